// Render-time shapes: triangle meshes in world space, analytic spheres, disks and cylinders kept
// in their object space (a tessellated sphere would bend caustics wrongly), and curves
// (scene/curves.h).
#pragma once
#include <cstdint>
#include <variant>
#include <vector>

#include "base/transform.h"
#include "base/vec.h"
#include "scene/curves.h"

namespace bpm {

struct TriangleMesh {
  std::vector<Vec3> positions;  // world space
  std::vector<Vec3> normals;    // world space, per vertex, or empty
  std::vector<Vec2> uvs;        // per vertex, or empty
  std::vector<uint32_t> indices;
  // pbrt-v4: the geometric normal is cross(p0 - p2, p1 - p2), negated when ReverseOrientation
  // and the transform's handedness say so, unless per-vertex normals decide its side.
  bool flip_normal = false;
  // Each triangle's unit cross(p0 - p2, p1 - p2) before flip_normal, so that a hit does not
  // compute it (RenderScene::commit fills it; surface_point computes it when it is empty).
  std::vector<Vec3> face_normals;
  // Per triangle, bit e (0-2): its edge from corner e to corner (e + 1) % 3 is open, a border of
  // the mesh (compute_open_edges says when); bit kBentBit: a neighbour across one of its edges
  // lies off its plane by more than 0.26 degrees (RenderScene::commit fills it).
  std::vector<uint8_t> open_edges;
  static constexpr uint8_t kBentBit = 8;
  int triangle_count() const { return int(indices.size() / 3); }
  void compute_face_normals();
  void compute_open_edges();
};

struct Sphere {
  Transform world_from_object;
  float radius = 1;
  float z_min = -1, z_max = 1;
  float phi_max = 2 * kPi;  // radians
  bool flip_normal = false;
  bool is_full() const { return z_min <= -radius && z_max >= radius && phi_max >= 2 * kPi; }
};

struct Disk {
  Transform world_from_object;
  float height = 0, radius = 1, inner_radius = 0;
  float phi_max = 2 * kPi;
  bool flip_normal = false;
  bool is_full() const { return inner_radius == 0 && phi_max >= 2 * kPi; }
};

// pbrt-v4 cylinder: x^2 + y^2 = radius^2 for z in [z_min, z_max], phi up to phi_max, open at
// both ends; the normal points away from the axis unless flipped.
struct Cylinder {
  Transform world_from_object;
  float radius = 1;
  float z_min = -1, z_max = 1;
  float phi_max = 2 * kPi;
  bool flip_normal = false;
};

using Shape = std::variant<TriangleMesh, Sphere, Disk, Cylinder, Curves>;

// A point on a surface as the integrators see it.
struct SurfacePoint {
  Vec3 p;
  Vec3 ng;  // geometric normal, on the side pbrt-v4's orientation rules give
  Vec3 ns;  // shading normal, in ng's hemisphere
  Vec2 uv;
  // A bound on p's floating-point error, in world units: a ray leaving the surface starts this
  // far off it (offset_origin). Relative to the primitive's coordinates, so that it holds at any
  // scene scale.
  float error = 0;
};

// Analytic ray intersection in object space (double precision). Returns the ray parameter of
// the nearest hit in (t_min, t_max) or a negative value.
double intersect_sphere(const Sphere& s, Vec3 o_world, Vec3 d_world, double t_min, double t_max);
double intersect_disk(const Disk& d, Vec3 o_world, Vec3 d_world, double t_min, double t_max);
double intersect_cylinder(const Cylinder& c, Vec3 o_world, Vec3 d_world, double t_min,
                          double t_max);
// The analytic shapes (spheres, disks, cylinders) in one call.
double intersect_analytic(const Shape& shape, Vec3 o_world, Vec3 d_world, double t_min,
                          double t_max);

// Surface point of a hit: for meshes from the primitive and Embree's barycentrics (b1, b2); for
// curves from the segment, Embree's u and the direction d of the ray (a flat curve faces it).
SurfacePoint surface_point(const Shape& shape, int prim, Vec2 barycentric, Vec3 p_hit, Vec3 d = {});
Bounds3 world_bounds(const Shape& shape, int prim);
int primitive_count(const Shape& shape);

}  // namespace bpm
