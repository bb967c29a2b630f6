#include "bpm/camera_connections.h"

#include <algorithm>
#include <cmath>

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

// p_e(y) pi r^2 of the pixel about pixel centre `centre` for a point at u on the image, without
// the filter's density: (du/domega) |cos_y| pi r^2 / d^2, r the pixel's caustic radius.
double merge_area_density(const CameraConnections& cc, uint32_t pixel, float pixels_per_solid_angle,
                          float cos_y, float d2) {
  const double r = cc.caustic_radius[pixel];
  const double r2 = cc.world ? r * r / double(d2) : r * r;
  return double(pixels_per_solid_angle) * double(cos_y) * kPi * r2;
}

}  // namespace

void connect_to_camera(const RenderScene& scene, const CameraConnections& cc, const Material& m,
                       const SurfacePoint& sp, Vec3 wi, const Spectrum& flux, bool hero_only,
                       bool odd, const Wavelengths& wl, uint64_t* rays,
                       std::vector<CameraHit>& out) {
  const Vec2 radius = cc.filter->settings().radius;
  const auto proj = cc.camera->project(sp.p, std::max(radius.x, radius.y));
  if (!proj) return;
  const Vec3 to_camera = proj->pinhole - sp.p;
  const float d2 = length_squared(to_camera);
  if (!(d2 > 0)) return;
  const Vec3 wo = to_camera / std::sqrt(d2);
  const float cos_y = std::fabs(dot(sp.ng, wo));
  if (cos_y == 0) return;
  // A dispersive material holds the hero wavelength's index for every channel (materials/
  // material.cpp): there the path goes on at the hero alone, scaled once (hero_join_factor).
  Spectrum value = photon_contribution(m, sp.ng, sp.ns, wo, wi, flux);
  if (!hero_only && material_is_dispersive(m)) value = hero_wavelength_only(value);
  if (value.is_black()) return;
  ++*rays;
  const Vec3 origin = offset_origin(sp.p, sp.ng, wo, sp.error);
  const Spectrum seen = shadow_transmittance(scene, origin, proj->pinhole, -1, false, wl);
  if (seen.is_black()) return;
  // The importance of the point to the image, per square pixel of the filter's offsets.
  const float importance = proj->pixels_per_solid_angle * cos_y / d2;
  // Without the pixel's radius: spread_to_pixels multiplies by r^2 (per unit of distance) or by
  // r^2 / d^2 (world units).
  const float chance =
      cc.mode == CameraConnectionMode::kOn ? gather_chance(cc, m, sp.ns, wo) : 0.0f;
  const float merge =
      float(chance * kPi * proj->pixels_per_solid_angle * cos_y / (cc.world ? double(d2) : 1.0));
  out.push_back({proj->raster, merge, seen * value * importance, odd});
}

std::pair<int, int> rows_reached(const CameraConnections& cc, const CameraHit& hit) {
  const float r = cc.filter->settings().radius.y, y = hit.raster.y;
  return {std::max(0, int(std::ceil(y - 0.5f - r))),
          std::min(cc.height - 1, int(std::floor(y - 0.5f + r)))};
}

void spread_to_pixels(const CameraConnections& cc, const CameraHit& hit, int row0, int row1,
                      Spectrum* sums, Spectrum* odd_sums) {
  const Vec2 radius = cc.filter->settings().radius, u = hit.raster;
  const int x0 = std::max(0, int(std::ceil(u.x - 0.5f - radius.x))),
            x1 = std::min(cc.width - 1, int(std::floor(u.x - 0.5f + radius.x))),
            y0 = std::max(row0, rows_reached(cc, hit).first),
            y1 = std::min(row1 - 1, rows_reached(cc, hit).second);
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const Vec2 offset{u.x - (float(x) + 0.5f), u.y - (float(y) + 0.5f)};
      const float share = cc.filter->normalized(offset);
      if (share == 0) continue;
      const size_t pixel = size_t(y) * size_t(cc.width) + size_t(x);
      const double r = cc.caustic_radius[pixel];
      // The merge's density against the connection's 1 (0 where the eye path never gathers here).
      const double merge = double(hit.merge) * cc.filter->sample_density(offset) * r * r;
      const Spectrum v = hit.value * float(share / (1 + merge));
      sums[pixel] += v;
      if (hit.odd) odd_sums[pixel] += v;
    }
}

float merge_weight_against_camera(const CameraConnections& cc, const BackwardPhoton& bp,
                                  const Material& m) {
  if (cc.mode == CameraConnectionMode::kAlone) return 0;
  const Vec2 radius = cc.filter->settings().radius;
  const auto proj = cc.camera->project(bp.p, std::max(radius.x, radius.y) + 1);
  if (!proj) return 1;  // not seen through the pinhole (numerical accident): no connection made it
  const Vec3 to_camera = proj->pinhole - bp.p;
  const float d2 = length_squared(to_camera);
  if (!(d2 > 0)) return 1;
  const float cos_y = std::fabs(dot(bp.ng, to_camera)) / std::sqrt(d2);
  const uint32_t w = uint32_t(cc.width);
  // The eye sample's offset from its pixel's centre, inside the filter (rounding may put a point
  // on its edge a hair outside).
  const Vec2 offset{std::clamp(proj->raster.x - (float(bp.pixel % w) + 0.5f), -radius.x, radius.x),
                    std::clamp(proj->raster.y - (float(bp.pixel / w) + 0.5f), -radius.y, radius.y)};
  const double merge = double(gather_chance(cc, m, bp.ns, bp.wo)) *
                       double(cc.filter->sample_density(offset)) *
                       merge_area_density(cc, bp.pixel, proj->pixels_per_solid_angle, cos_y, d2);
  return float(merge / (merge + 1));
}

}  // namespace bpm
