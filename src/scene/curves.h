// pbrt-v4's "curve" shape: cubic Bezier segments whose width varies linearly along each, for hair,
// fur and grass. Embree intersects them natively (accel.cpp): `flat` and `cylinder` curves are
// ribbons that face the ray meeting them (a cylinder's shading normal then turns across the
// width, as a tube's would, linearly in the offset as pbrt-v4 turns it); `ribbon` curves turn
// with normals given at the segment ends. Kept in world space: a transform's scale scales the
// width by the cube root of its determinant.
#pragma once
#include <cstdint>
#include <vector>

#include "base/vec.h"

namespace bpm {

struct SurfacePoint;

struct Curves {
  enum class Type { kFlat, kCylinder, kRibbon };
  Type type = Type::kFlat;
  // Four control points per segment: x, y, z and radius (half the width), as Embree reads them.
  std::vector<float> control;
  std::vector<uint32_t> first;  // each segment's first control point
  // kRibbon: each segment's normals at its ends, and per control point the normals Embree's
  // normal-oriented curves interpolate (the ends' slerp at u = 0, 1/3, 2/3, 1).
  std::vector<Vec3> end_normals, control_normals;
  bool flip_normal = false;  // ReverseOrientation and the transform's handedness, as pbrt-v4
  int segment_count() const { return int(first.size()); }
  // The segment's centre line at u: point, derivative and radius.
  Vec3 point(int seg, float u, Vec3* dpdu = nullptr, float* radius = nullptr) const;
  // The normal of a ribbon segment at u: the slerp of its end normals.
  Vec3 ribbon_normal(int seg, float u) const;
};

// The surface point where a ray of direction d met segment `seg` at curve parameter u (Embree's
// hit u) and point p. uv is (u, v) with v across the width from 0 to 1, as in pbrt-v4.
SurfacePoint curve_point(const Curves& c, int seg, float u, Vec3 p, Vec3 d);
// dp/du along the segment and dp/dv across it (the width), for bump mapping.
void curve_derivatives(const Curves& c, int seg, const SurfacePoint& sp, Vec3* dpdu, Vec3* dpdv);

// pbrt-v4's conversions to cubic Bezier control points: a quadratic Bezier segment raised to
// cubic; a uniform B-spline's segment from its 3 (quadratic) or 4 (cubic) control points.
void elevate_quadratic_bezier(const Vec3 in[3], Vec3 out[4]);
void quadratic_bspline_to_bezier(const Vec3 in[3], Vec3 out[4]);
void cubic_bspline_to_bezier(const Vec3 in[4], Vec3 out[4]);

}  // namespace bpm
