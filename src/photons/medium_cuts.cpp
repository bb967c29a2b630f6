#include "photons/medium_cuts.h"

#include <algorithm>
#include <cmath>
#include <variant>

namespace bpm {

namespace {

// Whether light can pass through a surface of `material` (a mix: through either of its two).
bool lets_light_through(const RenderScene& scene, int material, int depth = 0) {
  const MaterialDesc& m = scene.materials[size_t(material)];
  if (const auto* mix = std::get_if<MixDesc>(&m))
    return depth > 8 || lets_light_through(scene, mix->materials[0], depth + 1) ||
           lets_light_through(scene, mix->materials[1], depth + 1);
  return std::holds_alternative<DielectricMaterial>(m) ||
         std::holds_alternative<ThinDielectricMaterial>(m) ||
         std::holds_alternative<DiffuseTransmissionDesc>(m) ||
         std::holds_alternative<InterfaceMaterial>(m);
}

// Whether the medium's beams end at a surface of `object`: it leads into another medium, or no
// light passes through it. Not a curve (thinner than any disc), nor a surface with the same medium
// on both sides that light crosses (glass in fog, a cut-out): beams lie beyond those too.
bool ends_beams(const RenderScene& scene, int object) {
  const Object& o = scene.objects[size_t(object)];
  if (std::holds_alternative<Curves>(o.shape)) return false;
  if (o.medium_inside != o.medium_outside) return true;
  return !o.has_alpha() && !lets_light_through(scene, o.material);
}

// The offset from the plane of the surface that the probe from p along dir meets within `reach`:
// the surface's normal there, turned toward p, and p's foot along it, found by a second probe
// within `radius` (a surface that curves away before the foot cuts nothing). Zero where either
// probe meets nothing.
Vec3 cut_along(const RenderScene& scene, Vec3 p, Vec3 dir, float reach, float radius,
               PathCounters& rays) {
  const Ray probe{p, dir, reach};
  Hit hit;
  ++rays.probe_rays;
  if (!scene.intersect(probe, &hit) || !ends_beams(scene, hit.object)) return {};
  const Vec3 toward = face_forward(scene.surface(probe, hit).ng, -dir);
  const Ray foot{p, -toward, radius};
  Hit at;
  ++rays.probe_rays;
  if (!scene.intersect(foot, &at) || !ends_beams(scene, at.object)) return {};
  const SurfacePoint sp = scene.surface(foot, at);
  const Vec3 n = face_forward(sp.ng, toward);
  const float h = dot(p - sp.p, n);
  return h > 0 && h < radius ? n * h : Vec3{};
}

}  // namespace

Vec3 medium_cut(const RenderScene& scene, Vec3 p, Vec3 d, float to_end, float from_start,
                float radius, PathCounters& rays) {
  Vec3 cut;
  float nearest = radius;
  const float reach = kCutReach * radius;
  for (const auto& [dir, along] : {std::pair{d, to_end}, std::pair{-d, from_start}}) {
    if (!(along < reach)) continue;
    // A little past the piece's end, so that the surface it ended at is met.
    const Vec3 c = cut_along(scene, p, dir, along + 0.01f * radius, radius, rays);
    const float h = length(c);
    if (h > 0 && h < nearest) {
      nearest = h;
      cut = c;
    }
  }
  return cut;
}

float cut_line_distance(Vec3 cut, Vec3 d) {
  const float h2 = length_squared(cut);
  if (h2 == 0) return kInf;
  const float sin2 = 1 - dot(cut, d) * dot(cut, d) / h2;
  return sin2 > 0 ? std::sqrt(h2 / sin2) : kInf;
}

float disc_share_before(float line, float radius) {
  if (!(line < radius)) return 1;
  const float u = line / radius;
  // The circular segment beyond the line, over the disc's area.
  return 1 - (std::acos(u) - u * std::sqrt(1 - u * u)) / kPi;
}

}  // namespace bpm
