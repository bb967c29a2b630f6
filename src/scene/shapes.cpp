#include "scene/shapes.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <type_traits>

namespace bpm {
namespace {

struct DVec {
  double x, y, z;
};
DVec to_object(const Transform& world_from_object, Vec3 v, bool point) {
  const Matrix4& inv = world_from_object.inverse_matrix();
  DVec r{0, 0, 0};
  double* out[3] = {&r.x, &r.y, &r.z};
  for (int i = 0; i < 3; ++i)
    *out[i] = inv[i][0] * v.x + inv[i][1] * v.y + inv[i][2] * v.z + (point ? inv[i][3] : 0.0);
  return r;
}
double phi_of(double x, double y) {
  double phi = std::atan2(y, x);
  return phi < 0 ? phi + 2 * M_PI : phi;
}

}  // namespace

double intersect_sphere(const Sphere& s, Vec3 o_world, Vec3 d_world, double t_min, double t_max) {
  DVec o = to_object(s.world_from_object, o_world, true);
  DVec d = to_object(s.world_from_object, d_world, false);
  double a = d.x * d.x + d.y * d.y + d.z * d.z;
  double b = 2 * (d.x * o.x + d.y * o.y + d.z * o.z);
  double c = o.x * o.x + o.y * o.y + o.z * o.z - double(s.radius) * s.radius;
  // Numerically stable discriminant (Hearn and Baker's form, as pbrt-v4 uses).
  DVec f{o.x - b / (2 * a) * d.x, o.y - b / (2 * a) * d.y, o.z - b / (2 * a) * d.z};
  double fl2 = f.x * f.x + f.y * f.y + f.z * f.z;
  double disc = 4 * a * (double(s.radius) * s.radius - fl2);
  if (disc < 0) return -1;
  double root = std::sqrt(disc);
  double q = b < 0 ? -0.5 * (b - root) : -0.5 * (b + root);
  double t0 = q / a, t1 = c / q;
  if (t0 > t1) std::swap(t0, t1);
  for (double t : {t0, t1}) {
    if (!(t > t_min && t < t_max)) continue;
    if (!s.is_full()) {
      double px = o.x + t * d.x, py = o.y + t * d.y, pz = o.z + t * d.z;
      if (px == 0 && py == 0) px = 1e-5 * s.radius;
      if ((s.z_min > -s.radius && pz < s.z_min) || (s.z_max < s.radius && pz > s.z_max) ||
          phi_of(px, py) > s.phi_max)
        continue;
    }
    return t;
  }
  return -1;
}

double intersect_disk(const Disk& k, Vec3 o_world, Vec3 d_world, double t_min, double t_max) {
  DVec o = to_object(k.world_from_object, o_world, true);
  DVec d = to_object(k.world_from_object, d_world, false);
  if (d.z == 0) return -1;
  double t = (k.height - o.z) / d.z;
  if (!(t > t_min && t < t_max)) return -1;
  double px = o.x + t * d.x, py = o.y + t * d.y;
  double r2 = px * px + py * py;
  if (r2 > double(k.radius) * k.radius || r2 < double(k.inner_radius) * k.inner_radius) return -1;
  if (k.phi_max < 2 * kPi && phi_of(px, py) > k.phi_max) return -1;
  return t;
}

double intersect_cylinder(const Cylinder& c, Vec3 o_world, Vec3 d_world, double t_min,
                          double t_max) {
  DVec o = to_object(c.world_from_object, o_world, true);
  DVec d = to_object(c.world_from_object, d_world, false);
  double a = d.x * d.x + d.y * d.y;
  if (a == 0) return -1;  // parallel to the axis
  double b = 2 * (d.x * o.x + d.y * o.y);
  double r2 = double(c.radius) * c.radius;
  double cc = o.x * o.x + o.y * o.y - r2;
  // The same stable discriminant as the sphere's, in the xy plane.
  double fx = o.x - b / (2 * a) * d.x, fy = o.y - b / (2 * a) * d.y;
  double disc = 4 * a * (r2 - (fx * fx + fy * fy));
  if (disc < 0) return -1;
  double root = std::sqrt(disc);
  double q = b < 0 ? -0.5 * (b - root) : -0.5 * (b + root);
  if (q == 0) return -1;
  double t0 = q / a, t1 = cc / q;
  if (t0 > t1) std::swap(t0, t1);
  for (double t : {t0, t1}) {
    if (!(t > t_min && t < t_max)) continue;
    double pz = o.z + t * d.z;
    if (pz < c.z_min || pz > c.z_max) continue;
    if (c.phi_max < 2 * kPi && phi_of(o.x + t * d.x, o.y + t * d.y) > c.phi_max) continue;
    return t;
  }
  return -1;
}

double intersect_analytic(const Shape& shape, Vec3 o, Vec3 d, double t_min, double t_max) {
  if (auto* s = std::get_if<Sphere>(&shape)) return intersect_sphere(*s, o, d, t_min, t_max);
  if (auto* k = std::get_if<Disk>(&shape)) return intersect_disk(*k, o, d, t_min, t_max);
  return intersect_cylinder(std::get<Cylinder>(shape), o, d, t_min, t_max);
}

namespace {

// SurfacePoint::error per unit of coordinate magnitude: some 170 float ulps, room for the
// rounding of the intersection, the barycentric interpolation and the transforms.
constexpr float kPointErrorScale = 2e-5f;

Vec3 face_normal(Vec3 p0, Vec3 p1, Vec3 p2) {
  Vec3 ng = cross(p0 - p2, p1 - p2);
  float len = length(ng);
  return len > 0 ? ng / len : Vec3(0, 0, 1);
}

SurfacePoint mesh_point(const TriangleMesh& m, int prim, Vec2 b) {
  uint32_t i0 = m.indices[3 * prim], i1 = m.indices[3 * prim + 1], i2 = m.indices[3 * prim + 2];
  Vec3 p0 = m.positions[i0], p1 = m.positions[i1], p2 = m.positions[i2];
  float b0 = 1 - b.x - b.y;
  SurfacePoint sp;
  sp.p = p0 * b0 + p1 * b.x + p2 * b.y;
  sp.error = kPointErrorScale *
             std::max({max_abs_component(p0), max_abs_component(p1), max_abs_component(p2)});
  Vec3 ng = m.face_normals.empty() ? face_normal(p0, p1, p2) : m.face_normals[size_t(prim)];
  if (m.flip_normal) ng = -ng;
  sp.ng = sp.ns = ng;
  if (!m.normals.empty()) {
    Vec3 ns = m.normals[i0] * b0 + m.normals[i1] * b.x + m.normals[i2] * b.y;
    if (length_squared(ns) > 0) {
      sp.ns = normalize(ns);
      sp.ng = face_forward(ng, sp.ns);
    }
  }
  if (!m.uvs.empty()) {
    Vec2 a = m.uvs[i0], c = m.uvs[i1], d = m.uvs[i2];
    sp.uv = {a.x * b0 + c.x * b.x + d.x * b.y, a.y * b0 + c.y * b.x + d.y * b.y};
  } else {
    sp.uv = {b.x + b.y, b.y};  // pbrt-v4's default vertex uvs: (0,0), (1,0), (1,1)
  }
  return sp;
}

SurfacePoint analytic_point(const Shape& shape, Vec3 p_hit) {
  SurfacePoint sp;
  if (auto* s = std::get_if<Sphere>(&shape)) {
    Vec3 po = s->world_from_object.inverse().point(p_hit);
    float l = length(po);
    if (l > 0) po = po * (s->radius / l);  // re-project onto the surface
    sp.p = s->world_from_object.point(po);
    Vec3 n = normalize(s->world_from_object.normal(po));
    sp.ng = sp.ns = s->flip_normal ? -n : n;
    float phi = float(phi_of(po.x, po.y));
    // pbrt-v4: v runs from the z_min cap (0) to the z_max cap (1).
    float theta = std::acos(std::clamp(po.z / s->radius, -1.0f, 1.0f));
    // (acos(-1) and acos(1) for the poles of a sphere without caps.)
    float theta_min =
        s->z_min <= -s->radius ? kPi : std::acos(std::clamp(s->z_min / s->radius, -1.0f, 1.0f));
    float theta_max =
        s->z_max >= s->radius ? 0.0f : std::acos(std::clamp(s->z_max / s->radius, -1.0f, 1.0f));
    sp.uv = {phi / s->phi_max,
             theta_max != theta_min ? (theta - theta_min) / (theta_max - theta_min) : 0.0f};
    return sp;
  }
  if (auto* c = std::get_if<Cylinder>(&shape)) {
    Vec3 po = c->world_from_object.inverse().point(p_hit);
    float rxy = std::sqrt(po.x * po.x + po.y * po.y);
    if (rxy > 0) {
      po.x *= c->radius / rxy;  // re-project onto the surface
      po.y *= c->radius / rxy;
    }
    sp.p = c->world_from_object.point(po);
    Vec3 n = normalize(c->world_from_object.normal(Vec3(po.x, po.y, 0)));
    sp.ng = sp.ns = c->flip_normal ? -n : n;
    sp.uv = {float(phi_of(po.x, po.y)) / c->phi_max, (po.z - c->z_min) / (c->z_max - c->z_min)};
    return sp;
  }
  const Disk& k = std::get<Disk>(shape);
  Vec3 po = k.world_from_object.inverse().point(p_hit);
  po.z = k.height;
  sp.p = k.world_from_object.point(po);
  Vec3 n = normalize(k.world_from_object.normal(Vec3(0, 0, 1)));
  sp.ng = sp.ns = k.flip_normal ? -n : n;
  float r = std::sqrt(po.x * po.x + po.y * po.y);
  sp.uv = {float(phi_of(po.x, po.y)) / k.phi_max, (k.radius - r) / (k.radius - k.inner_radius)};
  return sp;
}

}  // namespace

void TriangleMesh::compute_face_normals() {
  face_normals.resize(size_t(triangle_count()));
  for (size_t t = 0; t < face_normals.size(); ++t)
    face_normals[t] = face_normal(positions[indices[3 * t]], positions[indices[3 * t + 1]],
                                  positions[indices[3 * t + 2]]);
}

void TriangleMesh::compute_open_edges() {
  // Vertices at the same position (their bits) are one corner, so that triangles that repeat
  // their corners' vertices (a seam of uvs or normals) still meet: each vertex's id is the first
  // vertex at its position.
  std::vector<uint32_t> by_position(positions.size()), id(positions.size());
  for (uint32_t v = 0; v < uint32_t(positions.size()); ++v) by_position[v] = v;
  auto bits = [&](uint32_t v) {
    std::array<uint32_t, 3> b;
    std::memcpy(b.data(), &positions[v], sizeof(b));
    return b;
  };
  tbb::parallel_sort(by_position.begin(), by_position.end(), [&](uint32_t a, uint32_t b) {
    return std::pair(bits(a), a) < std::pair(bits(b), b);
  });
  for (size_t i = 0; i < by_position.size(); ++i)
    id[by_position[i]] = i > 0 && bits(by_position[i]) == bits(by_position[i - 1])
                             ? id[by_position[i - 1]]
                             : by_position[i];
  // Every edge by its two corners' ids; sorted, the triangles of an edge lie together.
  struct EdgeRef {
    uint64_t key;
    uint32_t triangle;
    uint8_t edge;
  };
  const size_t n = size_t(triangle_count());
  std::vector<EdgeRef> edges(3 * n);
  tbb::parallel_for(size_t(0), n, [&](size_t t) {
    for (uint8_t e = 0; e < 3; ++e) {
      const uint32_t a = id[indices[3 * t + e]], b = id[indices[3 * t + (e + 1) % 3]];
      edges[3 * t + e] = {uint64_t(std::min(a, b)) << 32 | std::max(a, b), uint32_t(t), e};
    }
  });
  tbb::parallel_sort(edges.begin(), edges.end(), [](const EdgeRef& x, const EdgeRef& y) {
    return std::pair(x.key, x.triangle) < std::pair(y.key, y.triangle);
  });
  // An edge is inside the mesh when exactly two triangles have it and their third corners lie on
  // either side of it (each triangle's cross(b - a, c - a) against the other's points away): not
  // two faces of a double-sided sheet, nor a sheet folded back on itself.
  auto across = [&](const EdgeRef& r) {
    const uint32_t* v = &indices[3 * size_t(r.triangle)];
    uint32_t a = v[r.edge], b = v[(r.edge + 1) % 3];
    if (id[b] < id[a]) std::swap(a, b);  // the edge taken the same way for both triangles
    return cross(positions[b] - positions[a], positions[v[(r.edge + 2) % 3]] - positions[a]);
  };
  open_edges.assign(n, 0);
  for (size_t i = 0; i < edges.size();) {
    size_t j = i + 1;
    while (j < edges.size() && edges[j].key == edges[i].key) ++j;
    if (j - i != 2 || !(dot(across(edges[i]), across(edges[i + 1])) < 0)) {
      for (size_t k = i; k < j; ++k) open_edges[edges[k].triangle] |= uint8_t(1u << edges[k].edge);
    } else {
      // Two neighbours: each one's cross product, turned as the edge runs, is the other's negated
      // normal when the two lie in one plane.
      const Vec3 a = normalize(across(edges[i])), b = normalize(across(edges[i + 1]));
      if (!(-dot(a, b) >= 0.99999f)) {
        open_edges[edges[i].triangle] |= kBentBit;
        open_edges[edges[i + 1].triangle] |= kBentBit;
      }
    }
    i = j;
  }
}

SurfacePoint surface_point(const Shape& shape, int prim, Vec2 bary, Vec3 p_hit, Vec3 d) {
  if (auto* m = std::get_if<TriangleMesh>(&shape)) return mesh_point(*m, prim, bary);
  if (auto* c = std::get_if<Curves>(&shape)) return curve_point(*c, prim, bary.x, p_hit, d);
  SurfacePoint sp = analytic_point(shape, p_hit);
  // The point is re-projected in object space and transformed back: its error is relative to its
  // world coordinates and to its distance from the object's origin (the shape's size).
  const Vec3 origin = std::visit(
      [](const auto& s) {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, TriangleMesh> || std::is_same_v<T, Curves>)
          return Vec3(0, 0, 0);
        else
          return s.world_from_object.point(Vec3(0, 0, 0));
      },
      shape);
  sp.error = kPointErrorScale * (max_abs_component(sp.p) + max_abs_component(sp.p - origin));
  return sp;
}

Bounds3 world_bounds(const Shape& shape, int prim) {
  Bounds3 b;
  if (auto* m = std::get_if<TriangleMesh>(&shape)) {
    for (int j = 0; j < 3; ++j) b.expand(m->positions[m->indices[3 * prim + j]]);
    return b;
  }
  if (auto* c = std::get_if<Curves>(&shape)) {  // the control points' hull, grown by the width
    float r = 0;
    for (uint32_t i = c->first[size_t(prim)], k = 0; k < 4; ++k) {
      const float* q = &c->control[4 * size_t(i + k)];
      b.expand(Vec3(q[0], q[1], q[2]));
      r = std::fmax(r, q[3]);
    }
    b.lo = b.lo - Vec3(r, r, r);
    b.hi = b.hi + Vec3(r, r, r);
    return b;
  }
  const Transform* t;
  Vec3 lo, hi;
  if (auto* s = std::get_if<Sphere>(&shape)) {
    t = &s->world_from_object;
    lo = Vec3(-s->radius, -s->radius, std::fmax(s->z_min, -s->radius));
    hi = Vec3(s->radius, s->radius, std::fmin(s->z_max, s->radius));
  } else if (auto* c = std::get_if<Cylinder>(&shape)) {
    t = &c->world_from_object;
    lo = Vec3(-c->radius, -c->radius, c->z_min);
    hi = Vec3(c->radius, c->radius, c->z_max);
  } else {
    const Disk& k = std::get<Disk>(shape);
    t = &k.world_from_object;
    lo = Vec3(-k.radius, -k.radius, k.height);
    hi = Vec3(k.radius, k.radius, k.height);
  }
  for (int c = 0; c < 8; ++c)
    b.expand(t->point(Vec3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z)));
  // Pad so that analytic hits just on the box still count.
  Vec3 pad = b.diagonal() * 1e-4f + Vec3(1e-6f, 1e-6f, 1e-6f);
  b.lo = b.lo - pad;
  b.hi = b.hi + pad;
  return b;
}

int primitive_count(const Shape& shape) {
  if (auto* m = std::get_if<TriangleMesh>(&shape)) return m->triangle_count();
  if (auto* c = std::get_if<Curves>(&shape)) return c->segment_count();
  return 1;
}

}  // namespace bpm
