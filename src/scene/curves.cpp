#include "scene/curves.h"

#include <algorithm>
#include <cmath>

#include "scene/shapes.h"

namespace bpm {
namespace {

Vec3 control_point(const Curves& c, uint32_t i) {
  return {c.control[4 * size_t(i)], c.control[4 * size_t(i) + 1], c.control[4 * size_t(i) + 2]};
}

// Any unit vector perpendicular to a (a unit).
Vec3 perpendicular(Vec3 a) {
  const Vec3 b = std::fabs(a.x) < 0.9f ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  return normalize(cross(a, b));
}

}  // namespace

Vec3 Curves::point(int seg, float u, Vec3* dpdu, float* radius) const {
  const uint32_t i = first[size_t(seg)];
  const Vec3 p0 = control_point(*this, i), p1 = control_point(*this, i + 1),
             p2 = control_point(*this, i + 2), p3 = control_point(*this, i + 3);
  const float s = 1 - u;
  if (dpdu) *dpdu = ((p1 - p0) * (s * s) + (p2 - p1) * (2 * s * u) + (p3 - p2) * (u * u)) * 3;
  if (radius) {
    const float* r = &control[4 * size_t(i) + 3];
    *radius = r[0] * s * s * s + r[4] * 3 * s * s * u + r[8] * 3 * s * u * u + r[12] * u * u * u;
  }
  return p0 * (s * s * s) + p1 * (3 * s * s * u) + p2 * (3 * s * u * u) + p3 * (u * u * u);
}

Vec3 Curves::ribbon_normal(int seg, float u) const {
  const Vec3 n0 = end_normals[2 * size_t(seg)], n1 = end_normals[2 * size_t(seg) + 1];
  const float angle = std::acos(std::clamp(dot(n0, n1), -1.0f, 1.0f));
  if (angle < 1e-4f) return n0;
  const float inv_sin = 1 / std::sin(angle);
  return normalize(n0 * (std::sin((1 - u) * angle) * inv_sin) +
                   n1 * (std::sin(u * angle) * inv_sin));
}

// pbrt-v4's frame at a curve hit: dp/dv spans the width (across the ribbon's normal, or for the
// ray-facing curves across both the ray and the tangent), the normal is dp/du x dp/dv; a
// `cylinder` turns dp/dv about the tangent by an angle running linearly from -90 to 90 degrees
// across the width.
SurfacePoint curve_point(const Curves& c, int seg, float u, Vec3 p, Vec3 d) {
  Vec3 dpdu;
  float radius;
  const Vec3 centre = c.point(seg, u, &dpdu, &radius);
  const float width = 2 * radius;
  if (!(length_squared(dpdu) > 0))
    dpdu = perpendicular(normalize(d.x || d.y || d.z ? d : Vec3(0, 0, 1)));
  const Vec3 t = normalize(dpdu);
  Vec3 across = c.type == Curves::Type::kRibbon ? cross(c.ribbon_normal(seg, u), t) : cross(d, t);
  across = length_squared(across) > 0 ? normalize(across) : perpendicular(t);
  const float offset = width > 0 ? dot(p - centre, across) / width : 0;
  const float v = std::clamp(0.5f + offset, 0.0f, 1.0f);
  Vec3 dpdv = across;
  if (c.type == Curves::Type::kCylinder) {
    const float theta = kPi * (v - 0.5f);  // pbrt-v4 rotates dp/dv by -theta about dp/du
    dpdv = across * std::cos(theta) - cross(t, across) * std::sin(theta);
  }
  Vec3 n = normalize(cross(t, dpdv));
  if (c.flip_normal) n = -n;
  SurfacePoint sp;
  sp.p = p;
  sp.ng = sp.ns = n;
  sp.uv = {u, v};
  // pbrt-v4 bounds the point's error by the width on each axis, and so lifts rays off the curve
  // by the width times |n.x| + |n.y| + |n.z|: far enough that a ray leaving it does not meet the
  // ribbon the curve turns toward that ray.
  sp.error = std::fmax(width * (std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z)),
                       2e-5f * max_abs_component(p));
  return sp;
}

void curve_derivatives(const Curves& c, int seg, const SurfacePoint& sp, Vec3* dpdu, Vec3* dpdv) {
  float radius;
  c.point(seg, sp.uv.x, dpdu, &radius);
  *dpdv = normalize(cross(sp.ng, *dpdu)) * (2 * radius);
}

void elevate_quadratic_bezier(const Vec3 in[3], Vec3 out[4]) {
  out[0] = in[0];
  out[1] = in[0] + (in[1] - in[0]) * (2.0f / 3);
  out[2] = in[2] + (in[1] - in[2]) * (2.0f / 3);
  out[3] = in[2];
}

void quadratic_bspline_to_bezier(const Vec3 in[3], Vec3 out[4]) {
  const Vec3 bezier[3] = {(in[0] + in[1]) * 0.5f, in[1], (in[1] + in[2]) * 0.5f};
  elevate_quadratic_bezier(bezier, out);
}

void cubic_bspline_to_bezier(const Vec3 in[4], Vec3 out[4]) {
  out[0] = (in[0] + in[1] * 4 + in[2]) / 6;
  out[1] = (in[1] * 2 + in[2]) / 3;
  out[2] = (in[1] + in[2] * 2) / 3;
  out[3] = (in[1] + in[2] * 4 + in[3]) / 6;
}

}  // namespace bpm
