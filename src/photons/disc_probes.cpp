#include "photons/disc_probes.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace bpm {

namespace {

// Counts a probe ray, and shows it to the benchmarks' observer.
void count(PathCounters& rays, const Ray& ray) {
  ++rays.probe_rays;
  if (rays.observer) rays.observer->closest_hit(ray);
}

// Whether `is` holds for the material, or for either material of a mix (or there is no material
// to tell: then it may).
template <class Is>
bool some_material(const RenderScene& scene, int material, Is&& is, int depth = 0) {
  if (material < 0 || size_t(material) >= scene.materials.size()) return true;
  const MaterialDesc& m = scene.materials[size_t(material)];
  if (const auto* mix = std::get_if<MixDesc>(&m))
    return depth > 8 || some_material(scene, mix->materials[0], is, depth + 1) ||
           some_material(scene, mix->materials[1], is, depth + 1);
  return is(m);
}

// Whether light may pass through the object's surface (refraction, diffuse transmission, an
// interface).
bool lets_light_through(const RenderScene& scene, int object) {
  return some_material(scene, scene.objects[size_t(object)].material, [](const MaterialDesc& m) {
    return std::holds_alternative<DielectricMaterial>(m) ||
           std::holds_alternative<ThinDielectricMaterial>(m) ||
           std::holds_alternative<DiffuseTransmissionDesc>(m) ||
           std::holds_alternative<InterfaceMaterial>(m);
  });
}

// Whether photons are stored on the object (fpm's maps): some lobe of its material is gathered.
// Not on glass, interfaces or a smooth conductor; a textured roughness may be rough anywhere.
bool holds_photons(const RenderScene& scene, int object) {
  return some_material(scene, scene.objects[size_t(object)].material, [](const MaterialDesc& m) {
    if (const auto* c = std::get_if<ConductorDesc>(&m))
      return c->roughness_tex.any() || !c->roughness.traced();
    return !std::holds_alternative<DielectricMaterial>(m) &&
           !std::holds_alternative<ThinDielectricMaterial>(m) &&
           !std::holds_alternative<InterfaceMaterial>(m);
  });
}

// Whether the segment from a to b meets another object that light does not cross, or `object`
// where its normal disagrees with ng (a crease of one mesh).
bool blocked_along(const RenderScene& scene, Vec3 a, Vec3 b, int object, Vec3 ng, float normal_cos,
                   PathCounters& rays) {
  const Vec3 d = b - a;
  const float len = length(d);
  if (len == 0) return false;
  Ray ray{a, d / len, len};
  for (int crossing = 0; crossing < 8; ++crossing) {
    Hit h;
    count(rays, ray);
    if (!scene.intersect(ray, &h)) return false;
    const SurfacePoint at = scene.surface(ray, h);
    const bool passes = h.object == object ? std::fabs(dot(at.ng, ng)) >= normal_cos
                                           : lets_light_through(scene, h.object);
    if (!passes) return true;
    ray = Ray{offset_origin(at.p, at.ng, ray.d, at.error), ray.d, ray.t_max - h.t};
  }
  return false;
}

// The point of triangle abc nearest to p (by the region of the triangle's plane p projects to:
// a corner, an edge or the inside).
Vec3 nearest_on_triangle(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const float d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const Vec3 cp = p - c;
  const float d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const float denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

float distance_to_segment(Vec3 p, Vec3 a, Vec3 b) {
  const Vec3 ab = b - a;
  const float len2 = length_squared(ab);
  const float t = len2 > 0 ? std::clamp(dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return length(p - (a + ab * t));
}

}  // namespace

// Whether the disc is whole on plain sight of the geometry near it, so that probes would find no
// cut: everything within two radii of the point (the probes' origins and paths) is a triangle of
// its own mesh lying in its tangent plane (its normal within 0.26 degrees, or normal_cos if
// tighter, and its nearest point within twice the point's error bound), and no border of the mesh
// comes within the radius. Anything else (another object, a crease, a curved surface, a border, a
// mesh with alpha, an analytic disk, more than 64 triangles near it) leaves the question to the
// probes. One query of Embree's tree, where the probes cast nine rays or more; none when the
// point's own triangle (`primitive`, -1 when not known) has a neighbour off its plane. NaN from a
// degenerate triangle fails every test.
bool disc_plainly_whole(const RenderScene& scene, const SurfacePoint& sp, int object, int primitive,
                        float radius, float normal_cos) {
  const Object& obj = scene.objects[size_t(object)];
  const auto* mesh = std::get_if<TriangleMesh>(&obj.shape);
  if (!mesh || obj.has_alpha() || mesh->open_edges.empty() || mesh->face_normals.empty())
    return false;
  // Within reach: the probes' origins (up to sqrt 3 radii above the point, lifted off it), their
  // paths to the disc and the rays skimming it. A triangle 0.26 degrees off the plane rises
  // r / 200 at the disc's rim, where a probe's hit still counts as inside the sphere. Vertices of
  // one plane are off it by their rounding, far below the point's error bound.
  const float lift = std::fmax(sp.error, 1e-30f) * 4;  // as probe_disc lifts its rays
  const float flat_cos = std::fmax(0.99999f, normal_cos), reach = 2 * radius + 2 * lift,
              off_plane = 2 * sp.error;
  // On a curved or finely folded mesh the point's own triangle has a neighbour off its plane, and
  // when the triangle is no wider than the reach that neighbour lies within it: the query would
  // find it, at a cost; the probes decide at once.
  if (primitive >= 0 && (mesh->open_edges[size_t(primitive)] & TriangleMesh::kBentBit)) {
    const uint32_t* v = &mesh->indices[3 * size_t(primitive)];
    const Vec3 a = mesh->positions[v[0]], b = mesh->positions[v[1]], c = mesh->positions[v[2]];
    if (std::fmax(length_squared(b - a), std::fmax(length_squared(c - b), length_squared(a - c))) <=
        reach * reach)
      return false;
  }
  bool whole = true;
  int visits = 0;
  // Embree visits every primitive of a leaf its bounds reach: each is judged by the distance of
  // its bounds (never more than its own), and the point's own triangles by their nearest point.
  scene.for_each_near(sp.p, reach, [&](int o, int prim) {
    if (++visits > 64) return whole = false;
    const Bounds3 box = world_bounds(scene.objects[size_t(o)].shape, prim);
    const Vec3 nearest_in_box(std::clamp(sp.p.x, box.lo.x, box.hi.x),
                              std::clamp(sp.p.y, box.lo.y, box.hi.y),
                              std::clamp(sp.p.z, box.lo.z, box.hi.z));
    if (length_squared(nearest_in_box - sp.p) > reach * reach) return true;
    if (o != object) return whole = false;
    const uint32_t* v = &mesh->indices[3 * size_t(prim)];
    const Vec3 corner[3] = {mesh->positions[v[0]], mesh->positions[v[1]], mesh->positions[v[2]]};
    const Vec3 q = nearest_on_triangle(sp.p, corner[0], corner[1], corner[2]);
    if (!(std::fabs(dot(mesh->face_normals[size_t(prim)], sp.ng)) >= flat_cos) ||
        !(std::fabs(dot(q - sp.p, sp.ng)) <= off_plane))
      return whole = false;
    for (int e = 0; e < 3; ++e)
      if ((mesh->open_edges[size_t(prim)] >> e & 1) &&
          !(distance_to_segment(sp.p, corner[e], corner[(e + 1) % 3]) > radius * 1.001f))
        return whole = false;
    return true;
  });
  return whole;
}

namespace {

// Unit directions a common rotation apart, in a bit-reversed order of angles so that each nested
// set of probes (0-1, 0-3, all) spreads around the point.
constexpr float kC = 0.70710678f;
constexpr float kCos[kDiscProbes] = {1, -1, 0, 0, kC, -kC, -kC, kC};
constexpr float kSin[kDiscProbes] = {0, 0, 1, -1, kC, -kC, kC, -kC};
constexpr float kTan60 = 1.7320508f;

// The disc under test, and what its probes compare their hits with.
struct Disc {
  const RenderScene& scene;
  const SurfacePoint& sp;
  Vec3 n;  // the normal on wo's side
  int object;
  PhotonSurfaces where;
  float radius, normal_cos;
  float lift;  // keeps the origin off the surface
  float skim;  // the height of blocked_along's rays
  const TriangleMesh* mesh;

  // Another object whose photons count here too (kAnyObject: one map holds them all).
  bool counts(int o) const {
    return o != object && where == PhotonSurfaces::kAnyObject && holds_photons(scene, o);
  }
};

// What one probe says of the disc.
enum class ProbeSays { kNothing, kFound, kCut };

// The slope of the probes' origins over the disc. The origins must be in the open: under something
// lower than they would be (an overhang near where a sphere touches the floor, a shelf over the
// point), the probes start halfway up to it, at a lower angle.
inline float open_slope(const Disc& d, PathCounters& rays) {
  float slope = kTan60;
  const Ray up{d.sp.p + d.n * d.lift, d.n, d.radius * kTan60};
  Hit h;
  count(rays, up);
  if (d.scene.intersect(up, &h)) slope = 0.5f * h.t / d.radius;
  return slope;
}

// Aims probe i at a point of the disc stratified by area, from above the point at `slope`.
inline void aim_probes(const Disc& d, Vec3 u, Vec3 v, float slope, Rng& rng,
                       Ray (&probes)[kDiscProbes], float (&to_target)[kDiscProbes]) {
  for (int i = 0; i < kDiscProbes; ++i) {
    const float rho = d.radius * std::sqrt((float(i) + rng.uniform()) / kDiscProbes);
    const Vec3 target = d.sp.p + (u * kCos[i] + v * kSin[i]) * rho;
    const Vec3 origin = d.sp.p + d.n * (rho * slope + d.lift);
    const Vec3 to = target - origin;
    to_target[i] = length(to);
    // On past the target, to a surface that curves away below the tangent plane.
    probes[i] = Ray{origin, to / to_target[i], 3 * to_target[i] + d.lift};
  }
}

// Photons cross glass and interfaces: so does a probe (the rare case, one ray at a time). Moves
// the probe on to the first surface it stops at; returns the distance it travelled before.
inline float cross_to_surface(const Disc& d, Ray& ray, Hit& h, bool& found, PathCounters& rays) {
  float travelled = 0;
  for (int crossing = 0; found && h.object != d.object && crossing < 4; ++crossing) {
    if (!lets_light_through(d.scene, h.object) || d.counts(h.object)) break;
    const SurfacePoint at = d.scene.surface(ray, h);
    travelled += h.t;
    ray = Ray{offset_origin(at.p, at.ng, ray.d, at.error), ray.d, ray.t_max - h.t};
    count(rays, ray);
    found = d.scene.intersect(ray, &h);
  }
  return travelled;
}

// Another object before the target. Below the tangent plane, where only a surface that curves
// away (or ends) lets a probe go: the probe says nothing. Above it, a wall standing on the
// surface, or an overhang with surface under it (where a sphere rests on a floor), which photons
// reach: a ray along the surface, just above it, tells them apart.
inline ProbeSays judge_other_object(const Disc& d, const Ray& ray, const Hit& h, float travelled,
                                    float to_target, PathCounters& rays) {
  const float height = dot(ray.o + ray.d * h.t - d.sp.p, d.n);
  // In the disc's plane: a neighbouring surface (floor tiles, say), whose photons are not
  // gathered here (a map of their own, or a normal that disagrees).
  if (std::fabs(height) <= d.skim) return ProbeSays::kCut;
  if (height < 0) return ProbeSays::kNothing;
  const Vec3 target = ray.o + ray.d * (to_target - travelled);
  return blocked_along(d.scene, d.sp.p + d.n * d.skim, target + d.n * d.skim, d.object, d.sp.ng,
                       d.normal_cos, rays)
             ? ProbeSays::kCut
             : ProbeSays::kFound;
}

// The probe hit the disc's own object. Either side: a probe from the front reaches no back face of
// the object without crossing a front one first.
inline ProbeSays judge_own_surface(const Disc& d, const Ray& ray, const Hit& h, float travelled,
                                   float to_target) {
  const Vec3 ng = d.mesh && !d.mesh->face_normals.empty()
                      ? d.mesh->face_normals[size_t(h.primitive)]
                      : d.scene.surface(ray, h).ng;
  // A crease: photons there do not count.
  if (std::fabs(dot(ng, d.sp.ng)) < d.normal_cos) return ProbeSays::kCut;
  // (The slack keeps a probe aimed at the rim, whose hit rounds to just outside, from reading as a
  // cut.)
  if (length_squared(ray.o + ray.d * h.t - d.sp.p) <= d.radius * d.radius * (1 + 1e-4f))
    return ProbeSays::kFound;
  // The surface rises out of the sphere before the target.
  if (travelled + h.t < to_target) return ProbeSays::kCut;
  // Else the surface curves away below the target and meets the probe outside the sphere: the
  // probe says nothing of the disc (on a sphere, the part of the surface inside the gathering
  // sphere has area pi r^2 exactly, a whole disc's).
  return ProbeSays::kNothing;
}

// What the probe says, from the surface it stopped at after `travelled`.
inline ProbeSays judge_probe(const Disc& d, const Ray& ray, const Hit& h, bool found,
                             float travelled, float to_target, PathCounters& rays) {
  // Another object whose photons count as well, inside the sphere (a lower surface too: the
  // gather takes its photons), with a normal that agrees as the gather compares them (signs
  // included). Elsewhere it is any other object.
  if (found && d.counts(h.object)) {
    const Vec3 at = ray.o + ray.d * h.t;
    if (length_squared(at - d.sp.p) <= d.radius * d.radius &&
        dot(d.scene.surface(ray, h).ng, d.sp.ng) >= d.normal_cos)
      return ProbeSays::kFound;
  }
  // Nothing (past an edge), or another object after the target: no surface here.
  if (!found || (h.object != d.object && travelled + h.t >= to_target)) return ProbeSays::kCut;
  if (h.object != d.object) return judge_other_object(d, ray, h, travelled, to_target, rays);
  return judge_own_surface(d, ray, h, travelled, to_target);
}

}  // namespace

DiscProbes probe_disc(const RenderScene& scene, const SurfacePoint& sp, Vec3 wo, int object,
                      PhotonSurfaces where, float radius, float normal_cos, Rng& rng,
                      PathCounters& rays, int primitive) {
  if (disc_plainly_whole(scene, sp, object, primitive, radius, normal_cos))
    return {0xff, 0};  // as if every probe found it
  return cast_disc_probes(scene, sp, wo, object, where, radius, normal_cos, rng, rays);
}

DiscProbes cast_disc_probes(const RenderScene& scene, const SurfacePoint& sp, Vec3 wo, int object,
                            PhotonSurfaces where, float radius, float normal_cos, Rng& rng,
                            PathCounters& rays) {
  static_assert(kDiscProbes == RenderScene::kBundle);
  const Vec3 n = dot(sp.ng, wo) >= 0 ? sp.ng : -sp.ng;
  const Frame frame = Frame::from_z(n);
  const float rotation = 2 * kPi * rng.uniform();
  const Vec3 u = frame.s * std::cos(rotation) + frame.t * std::sin(rotation), v = cross(n, u);
  const float lift = std::fmax(sp.error, 1e-30f) * 4;
  const Disc disc{scene,
                  sp,
                  n,
                  object,
                  where,
                  radius,
                  normal_cos,
                  lift,
                  std::fmax(lift, 1e-4f * radius),
                  std::get_if<TriangleMesh>(&scene.objects[size_t(object)].shape)};
  const float slope = open_slope(disc, rays);
  Ray probes[kDiscProbes];
  float to_target[kDiscProbes];
  aim_probes(disc, u, v, slope, rng, probes, to_target);
  Hit hits[kDiscProbes];
  bool found[kDiscProbes];
  scene.intersect_bundle(probes, kDiscProbes, hits, found);
  for (const Ray& r : probes) count(rays, r);
  DiscProbes out;
  out.looked = true;
  for (int i = 0; i < kDiscProbes; ++i) {
    const float travelled = cross_to_surface(disc, probes[i], hits[i], found[i], rays);
    const ProbeSays says =
        judge_probe(disc, probes[i], hits[i], found[i], travelled, to_target[i], rays);
    const uint8_t bit = uint8_t(1u << i);
    if (says == ProbeSays::kFound) out.found |= bit;
    if (says == ProbeSays::kCut) out.cut |= bit;
  }
  return out;
}

bool photon_cut_off(const RenderScene& scene, Vec3 p, Vec3 n, Vec3 q, int object, float radius,
                    float normal_cos, PathCounters& rays) {
  const Vec3 lift = n * (1e-3f * radius);
  return blocked_along(scene, p + lift, q + lift, object, n, normal_cos, rays);
}

namespace {

// The surface seen through a pixel's centre (object -1: none); ng faces the camera.
struct FirstVertex {
  Vec3 p, ng;
  int object = -1;
};

FirstVertex first_surface(const RenderScene& scene, Ray ray) {
  for (int crossing = 0; crossing < 16; ++crossing) {
    Hit h;
    if (!scene.intersect(ray, &h)) return {};
    const SurfacePoint sp = scene.surface(ray, h);
    const int m = scene.objects[size_t(h.object)].material;
    const bool interface = m >= 0 && size_t(m) < scene.materials.size() &&
                           std::holds_alternative<InterfaceMaterial>(scene.materials[size_t(m)]);
    if (!interface) return {sp.p, dot(sp.ng, ray.d) > 0 ? -sp.ng : sp.ng, h.object};
    ray = spawn_ray(sp, ray.d);
  }
  return {};
}

// Whether two neighbouring pixels' surfaces may be one smooth piece of one surface: normals
// within 25 degrees, and b off a's tangent plane by at most a fifth of their distance (a sphere
// seen edge-on passes; a step between parallel faces does not).
bool continuous(const FirstVertex& a, const FirstVertex& b) {
  if (a.object < 0 || a.object != b.object || dot(a.ng, b.ng) < 0.9f) return false;
  const Vec3 d = b.p - a.p;
  return std::fabs(dot(d, a.ng)) <= 0.2f * length(d);
}

// out[i] = 1 where some in[j] with |j - i| <= r along a line of n values (stride apart) is set,
// or the window leaves the line.
void spread_line(const uint8_t* in, uint8_t* out, int n, size_t stride, int r) {
  int count = 0;  // set values in the window [i - r, i + r] inside the line
  for (int j = 0; j < std::min(n, r); ++j) count += in[size_t(j) * stride];
  for (int i = 0; i < n; ++i) {
    if (i + r < n) count += in[size_t(i + r) * stride];
    if (i - r - 1 >= 0) count -= in[size_t(i - r - 1) * stride];
    out[size_t(i) * stride] = (count > 0 || i - r < 0 || i + r >= n) ? 1 : 0;
  }
}

// Spreads the marks over a square of side 2r + 1 (rows, then columns).
std::vector<uint8_t> spread(const std::vector<uint8_t>& edge, int w, int h, int r) {
  std::vector<uint8_t> rows(edge.size()), out(edge.size());
  tbb::parallel_for(0, h, [&](int y) {
    spread_line(&edge[size_t(y) * size_t(w)], &rows[size_t(y) * size_t(w)], w, 1, r);
  });
  tbb::parallel_for(
      0, w, [&](int x) { spread_line(&rows[size_t(x)], &out[size_t(x)], h, size_t(w), r); });
  return out;
}

}  // namespace

std::vector<uint8_t> find_edges(const RenderScene& scene, const Camera& camera, int width,
                                int height) {
  const size_t w = size_t(width), h = size_t(height);
  std::vector<FirstVertex> first(w * h);
  tbb::parallel_for(size_t(0), h, [&](size_t y) {
    for (size_t x = 0; x < w; ++x)
      first[y * w + x] = first_surface(
          scene, camera.generate_ray({float(x) + 0.5f, float(y) + 0.5f}, {0.5f, 0.5f}).ray);
  });
  // Whether each pixel breaks with its right neighbour, and with the one below: their surfaces
  // are not one smooth piece, or something stands on it between the two points, too thin for a
  // pixel's centre to see (a shelf board seen from above, a fin): a ray skimming the surface from
  // one to the other, a thousandth of their distance above it, meets it.
  std::vector<uint8_t> right(first.size(), 1), down(first.size(), 1);
  auto breaks = [&](size_t p, size_t q) {
    const FirstVertex &a = first[p], &b = first[q];
    if (!continuous(a, b) || !continuous(b, a)) return true;
    PathCounters rays;  // before the render: not counted
    // As a photon at b would be cut off from a disc at a reaching it.
    return photon_cut_off(scene, a.p, a.ng, b.p, a.object, length(b.p - a.p), 0.9f, rays);
  };
  tbb::parallel_for(size_t(0), h, [&](size_t y) {
    for (size_t x = 0, p = y * w; x < w; ++x, ++p) {
      if (x + 1 < w) right[p] = breaks(p, p + 1);
      if (y + 1 < h) down[p] = breaks(p, p + w);
    }
  });
  std::vector<uint8_t> edge(first.size());
  tbb::parallel_for(size_t(0), h, [&](size_t y) {
    for (size_t x = 0, p = y * w; x < w; ++x, ++p)
      edge[p] = first[p].object < 0 || (x + 1 < w && right[p]) || (x > 0 && right[p - 1]) ||
                (y + 1 < h && down[p]) || (y > 0 && down[p - w]);
  });
  return edge;
}

void mark_near_edges(const std::vector<uint8_t>& edges, int width, int height, int radius_px0,
                     int radius_px1, std::vector<uint8_t>* near) {
  const std::vector<uint8_t> near1 = spread(edges, width, height, radius_px1),
                             near0 = spread(edges, width, height, radius_px0);
  near->resize(edges.size());
  for (size_t p = 0; p < edges.size(); ++p) (*near)[p] = uint8_t(near1[p] | (near0[p] << 1));
}

NearEdges::NearEdges(bool enabled, const RenderScene& scene, const Camera& camera, int width,
                     int height, Vec2 filter_radius)
    : width_(width),
      height_(height),
      reach_(std::fmax(0.5f, std::fmax(filter_radius.x, filter_radius.y))) {
  if (enabled) edges_ = find_edges(scene, camera, width, height);
}

void NearEdges::mark(float radius_px0, float radius_px1) {
  if (edges_.empty()) return;
  const int r0 = int(std::ceil(radius_px0 + reach_)), r1 = int(std::ceil(radius_px1 + reach_));
  if (r0 == radii_[0] && r1 == radii_[1]) return;
  mark_near_edges(edges_, width_, height_, r0, r1, &near_);
  radii_[0] = r0;
  radii_[1] = r1;
}

}  // namespace bpm
