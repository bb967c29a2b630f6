#include "bpm/camera_connections.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "base/color.h"
#include "integrator/direct_light.h"
#include "photons/density.h"

namespace bpm {
namespace {

// The chance that an eye path gathered at a vertex of material m seen from direction wo (world),
// with shading normal ns (integrator/path_vertex.h, choose_eye_vertex).
float gather_chance(const CameraConnections& cc, const Material& m, Vec3 ns, Vec3 wo) {
  if (!cc.gather_by_chance) return 1;
  return 1 - bsdf_traced_part_probability(m, Frame::from_z(ns).to_local(wo));
}

// Where the camera sees point p (geometric normal ng): its place on the image, its squared
// distance from the pinhole and |cos| of the way there at ng. Nothing where it is off the image by
// more than `margin` pixels or behind the camera.
struct CameraView {
  Camera::ProjectedPoint proj;
  float d2, cos_y;
};
std::optional<CameraView> view_from_camera(const CameraConnections& cc, Vec3 p, Vec3 ng,
                                           float margin) {
  const auto proj = cc.camera->project(p, margin);
  if (!proj) return std::nullopt;
  const Vec3 to_camera = proj->pinhole - p;
  const float d2 = length_squared(to_camera);
  if (!(d2 > 0)) return std::nullopt;
  return CameraView{*proj, d2, std::fabs(dot(ng, to_camera)) / std::sqrt(d2)};
}

// The merge's density against the connection's 1 at a point seen so, but for the pixel's filter
// density and squared radius: c pi (du/domega) |cos_y|, over d^2 for radii in world units (else
// the radius is per unit of distance, and d cancels).
float merge_factor(const CameraConnections& cc, float chance, const CameraView& v) {
  return float(chance * kPi * v.proj.pixels_per_solid_angle * v.cos_y /
               (cc.world ? double(v.d2) : 1.0));
}

// The way from the point p (geometric normal ng, error bound `error`) to the pinhole: its
// transmittance through the media (none where something blocks it), and in *pass the probability
// that the camera's ray got across them (shadow_transmittance). The medium at p is found toward
// the camera, alike for the photon and for the backward photon; the pieces the camera's rays
// cross for certain (CameraConnections::certain_pieces) are the last ones on the way.
Spectrum toward_camera(const RenderScene& scene, const CameraConnections& cc, Vec3 p, Vec3 ng,
                       float error, Vec3 pinhole, const Wavelengths& wl, float* pass) {
  const Vec3 w = normalize(pinhole - p);
  const Vec3 origin = offset_origin(p, ng, w, error);
  const int medium = scene.media.empty() ? -1 : medium_at(scene, origin, w, cc.camera_medium);
  return shadow_transmittance(scene, origin, pinhole, medium, false, wl, pass, cc.certain_pieces);
}

// The merge's density at `pixel` for the filter offset `offset`: the factor times the filter's
// sampling density there and the pixel's squared radius. Both sides use it, so the weights of a
// path sum to one.
double merge_density(const CameraConnections& cc, float factor, size_t pixel, Vec2 offset) {
  const double r = cc.caustic_radius[pixel];
  return double(factor) * cc.filter->sample_density(offset) * r * r;
}

}  // namespace

void connect_to_camera(const RenderScene& scene, const CameraConnections& cc, const Material& m,
                       const SurfacePoint& sp, Vec3 wi, const Spectrum& flux, bool hero_only,
                       bool odd, const Wavelengths& wl, uint64_t* rays,
                       std::vector<CameraHit>& out) {
  const Vec2 radius = cc.filter->settings().radius;
  const auto view = view_from_camera(cc, sp.p, sp.ng, std::max(radius.x, radius.y));
  if (!view || view->cos_y == 0) return;
  const Vec3 wo = normalize(view->proj.pinhole - sp.p);
  // A dispersive material holds the hero wavelength's index for every channel (materials/
  // material.cpp): there the path goes on at the hero alone, scaled once (hero_join_factor).
  Spectrum value = photon_contribution(m, sp.ng, sp.ns, wo, wi, flux);
  if (!hero_only && material_is_dispersive(m)) value = hero_wavelength_only(value);
  if (value.is_black()) return;
  ++*rays;
  float pass = 1;
  const Spectrum seen =
      toward_camera(scene, cc, sp.p, sp.ng, sp.error, view->proj.pinhole, wl, &pass);
  if (seen.is_black()) return;
  // The importance of the point to the image, per square pixel of the filter's offsets.
  const float importance = view->proj.pixels_per_solid_angle * view->cos_y / view->d2;
  const float chance = cc.mode == ConnectionMode::kOn ? gather_chance(cc, m, sp.ns, wo) : 0.0f;
  out.push_back(
      {view->proj.raster, merge_factor(cc, chance, *view) * pass, seen * value * importance, odd});
}

std::pair<int, int> rows_reached(const CameraConnections& cc, const CameraHit& hit) {
  const float r = cc.filter->settings().radius.y, y = hit.raster.y;
  return {std::max(0, int(std::ceil(y - 0.5f - r))),
          std::min(cc.height - 1, int(std::floor(y - 0.5f + r)))};
}

void spread_to_pixels(const CameraConnections& cc, const CameraHit& hit, int row0, int row1,
                      Spectrum* sums, Spectrum* odd_sums) {
  const Vec2 radius = cc.filter->settings().radius, u = hit.raster;
  const std::pair<int, int> rows = rows_reached(cc, hit);
  const int x0 = std::max(0, int(std::ceil(u.x - 0.5f - radius.x))),
            x1 = std::min(cc.width - 1, int(std::floor(u.x - 0.5f + radius.x))),
            y0 = std::max(row0, rows.first), y1 = std::min(row1 - 1, rows.second);
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const Vec2 offset{u.x - (float(x) + 0.5f), u.y - (float(y) + 0.5f)};
      const float share = cc.filter->normalized(offset);
      if (share == 0) continue;
      const size_t pixel = size_t(y) * size_t(cc.width) + size_t(x);
      // The merge's density against the connection's 1 (0 where the eye path never gathers here).
      const double merge = merge_density(cc, hit.merge, pixel, offset);
      const Spectrum v = hit.value * float(share / (1 + merge));
      sums[pixel] += v;
      if (hit.odd) odd_sums[pixel] += v;
    }
}

float merge_weight_against_camera(const RenderScene& scene, const CameraConnections& cc,
                                  const BackwardPhoton& bp, const Material& m,
                                  const Wavelengths& wl) {
  if (cc.mode == ConnectionMode::kAlone) return 0;
  const Vec2 radius = cc.filter->settings().radius;
  const auto view = view_from_camera(cc, bp.p, bp.ng, std::max(radius.x, radius.y) + 1);
  if (!view) return 1;  // not seen through the pinhole (numerical accident): no connection made it
  const uint32_t w = uint32_t(cc.width);
  // The eye sample's offset from its pixel's centre, inside the filter (rounding may put a point
  // on its edge a hair outside).
  const Vec2 u = view->proj.raster;
  const Vec2 offset{std::clamp(u.x - (float(bp.pixel % w) + 0.5f), -radius.x, radius.x),
                    std::clamp(u.y - (float(bp.pixel / w) + 0.5f), -radius.y, radius.y)};
  float pass = 1;
  if (!scene.media.empty())
    toward_camera(scene, cc, bp.p, bp.ng, bp.error(), view->proj.pinhole, wl, &pass);
  const double merge = merge_density(
      cc, merge_factor(cc, gather_chance(cc, m, bp.ns, bp.wo), *view) * pass, bp.pixel, offset);
  return float(merge / (merge + 1));
}

}  // namespace bpm
