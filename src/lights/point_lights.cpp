// Point-like lights: point, spot (pbrt-v4 PointLight, SpotLight), and the image-modulated
// goniometric and projection lights (pbrt-v4 GoniometricLight, ProjectionLight).
#include <cmath>
#include <variant>
#include <vector>

#include "base/sampling.h"
#include "lights/light_types.h"

namespace bpm {

// ---- point ----

std::optional<LightLiSample> sample_li_of(const PointLight& l, const Shape*, Vec3 p_ref, Vec2,
                                          const SceneBoundsInfo&, const Wavelengths& wl) {
  LightLiSample ls;
  Vec3 d = l.position - p_ref;
  float d2 = length_squared(d);
  if (d2 == 0) return std::nullopt;
  ls.wi = d / std::sqrt(d2);
  ls.radiance = l.intensity.sample(wl) / d2;
  ls.p_light = l.position;
  ls.pdf_solid_angle = 1;
  ls.is_delta = true;
  return ls;
}

std::optional<LightLeSample> sample_le_of(const PointLight& l, const Shape*, Vec2, Vec2 u_dir,
                                          const SceneBoundsInfo&, const Wavelengths& wl) {
  LightLeSample s;
  s.origin = l.position;
  s.direction = sample_uniform_sphere(u_dir);
  s.flux = l.intensity.sample(wl) / kUniformSpherePdfSolidAngle;
  return s;
}

Rgb power_of(const PointLight& l, const SceneBoundsInfo&) { return l.intensity.rgb() * (4 * kPi); }

// ---- spot ----

float spot_falloff(const SpotLight& l, Vec3 w) {
  float c = w.z;
  if (c >= l.cos_falloff_start) return 1;
  if (c <= l.cos_falloff_end) return 0;
  float t = (c - l.cos_falloff_end) / (l.cos_falloff_start - l.cos_falloff_end);
  return t * t * (3 - 2 * t);
}

std::optional<LightLiSample> sample_li_of(const SpotLight& l, const Shape*, Vec3 p_ref, Vec2,
                                          const SceneBoundsInfo&, const Wavelengths& wl) {
  LightLiSample ls;
  Vec3 d = l.position - p_ref;
  float d2 = length_squared(d);
  if (d2 == 0) return std::nullopt;
  ls.wi = d / std::sqrt(d2);
  float fall = spot_falloff(l, l.frame.to_local(-ls.wi));
  if (fall == 0) return std::nullopt;
  ls.radiance = l.intensity.sample(wl) * (fall / d2);
  ls.p_light = l.position;
  ls.pdf_solid_angle = 1;
  ls.is_delta = true;
  return ls;
}

std::optional<LightLeSample> sample_le_of(const SpotLight& l, const Shape*, Vec2, Vec2 u_dir,
                                          const SceneBoundsInfo&, const Wavelengths& wl) {
  LightLeSample s;
  Vec3 w = sample_uniform_cone(u_dir, l.cos_falloff_end);
  float fall = spot_falloff(l, w);
  if (fall == 0) return std::nullopt;
  s.origin = l.position;
  s.direction = l.frame.to_world(w);
  s.flux = l.intensity.sample(wl) * (fall / uniform_cone_pdf_solid_angle(l.cos_falloff_end));
  return s;
}

Rgb power_of(const SpotLight& l, const SceneBoundsInfo&) {
  return l.intensity.rgb() *
         (2 * kPi * ((1 - l.cos_falloff_start) + (l.cos_falloff_start - l.cos_falloff_end) / 2));
}

// Goniometric and projection lights are points whose intensity depends on the direction.

namespace {
// L is a GoniometricLight or a ProjectionLight (light_intensity of either).
template <class L>
std::optional<LightLiSample> sample_li_directional_point(const L& l, Vec3 p_ref,
                                                         const Wavelengths& wl) {
  LightLiSample ls;
  Vec3 position = l.world_from_light.point(Vec3(0, 0, 0));
  Vec3 d = position - p_ref;
  float d2 = length_squared(d);
  if (d2 == 0) return std::nullopt;
  ls.wi = d / std::sqrt(d2);
  Spectrum I = light_intensity(l, -ls.wi, wl);
  if (I.is_black()) return std::nullopt;
  ls.radiance = I / d2;
  ls.p_light = position;
  ls.pdf_solid_angle = 1;
  ls.is_delta = true;
  return ls;
}
}  // namespace

// ---- goniometric ----

void prepare_goniometric_light(GoniometricLight* l) {
  const TexImage& im = *l->image;
  std::vector<float> weights(size_t(im.width) * size_t(im.height));
  double sum = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      float v = std::fmax(0.0f, im.texel(x, y, TexWrap::kClamp).average());
      weights[size_t(y) * im.width + x] = v;
      sum += v;
    }
  l->distribution = Distribution2D(weights, im.width, im.height);
  l->mean_value = float(sum / weights.size());
}

namespace {
// pbrt-v4 swaps y and z between the light's frame and the image's sphere.
Vec3 swap_yz(Vec3 v) { return {v.x, v.z, v.y}; }
}  // namespace

float goniometric_value(const GoniometricLight& l, Vec3 w) {
  Vec3 wl = swap_yz(normalize(l.world_from_light.inverse().vector(w)));
  Rgb texel = l.image->lookup(equal_area_sphere_to_square(wl), TexFilter::kPoint, TexWrap::kClamp);
  return std::fmax(0.0f, texel.average());
}

Spectrum light_intensity(const GoniometricLight& l, Vec3 w, const Wavelengths& wl) {
  float v = goniometric_value(l, w);
  if (v == 0) return {};
  return l.intensity.sample(wl) * v;
}

// Photon emission of a point light whose image says where its light goes (goniometric,
// projection): image coordinates drawn by the light's distribution, direction_light(uv) their
// direction in the light's frame, flux(uv, direction, pdf_uv) the photon's flux.
template <class L, class Direction, class Flux>
std::optional<LightLeSample> sample_le_image_point(const L& l, Vec2 u_dir,
                                                   Direction&& direction_light, Flux&& flux) {
  LightLeSample s;
  float pdf_uv = 0;
  Vec2 uv = l.distribution.sample(u_dir, &pdf_uv);
  if (!(pdf_uv > 0)) return std::nullopt;
  s.origin = l.world_from_light.point(Vec3(0, 0, 0));
  s.direction = normalize(l.world_from_light.vector(direction_light(uv)));
  s.flux = flux(uv, s.direction, pdf_uv);
  if (s.flux.is_black()) return std::nullopt;
  return s;
}

std::optional<LightLiSample> sample_li_of(const GoniometricLight& l, const Shape*, Vec3 p_ref, Vec2,
                                          const SceneBoundsInfo&, const Wavelengths& wl) {
  return sample_li_directional_point(l, p_ref, wl);
}

std::optional<LightLeSample> sample_le_of(const GoniometricLight& l, const Shape*, Vec2, Vec2 u_dir,
                                          const SceneBoundsInfo&, const Wavelengths& wl) {
  return sample_le_image_point(
      l, u_dir, [&](Vec2 uv) { return swap_yz(equal_area_square_to_sphere(uv)); },
      [&](Vec2, Vec3 direction, float pdf_uv) {
        return light_intensity(l, direction, wl) * (4 * kPi / pdf_uv);
      });
}

Rgb power_of(const GoniometricLight& l, const SceneBoundsInfo&) {
  return l.intensity.rgb() * (4 * kPi * l.mean_value);
}

// ---- projection ----

Vec3 projection_direction_light(const ProjectionLight& l, Vec2 uv) {
  // Screen coordinates in [-half_width, half_width] x [-half_height, half_height], y down the
  // image; at unit distance along +z they lie tan_half_fov times further out, y flipped.
  float sx = (2 * uv.x - 1) * l.half_width, sy = (2 * uv.y - 1) * l.half_height;
  return normalize(Vec3(sx * l.tan_half_fov, -sy * l.tan_half_fov, 1));
}

float projection_solid_angle_per_area(const ProjectionLight& l, Vec2 uv) {
  // The frame covers 4 hw hh tan^2 of the plane z = 1, where d omega = cos^3 dA.
  float c = projection_direction_light(l, uv).z;
  return 4 * l.half_width * l.half_height * l.tan_half_fov * l.tan_half_fov * c * c * c;
}

std::optional<Vec2> projection_uv(const ProjectionLight& l, Vec3 w) {
  Vec3 d = l.world_from_light.inverse().vector(w);
  if (!(d.z > 1e-3f * length(d))) return std::nullopt;  // behind the light (pbrt-v4's hither)
  float sx = d.x / (d.z * l.tan_half_fov), sy = -d.y / (d.z * l.tan_half_fov);
  if (std::fabs(sx) > l.half_width || std::fabs(sy) > l.half_height) return std::nullopt;
  return Vec2((sx / l.half_width + 1) / 2, (sy / l.half_height + 1) / 2);
}

namespace {
Rgb projection_texel(const ProjectionLight& l, Vec2 uv) {
  return l.image->lookup(uv, TexFilter::kPoint, TexWrap::kClamp).clamped_zero();
}
}  // namespace

Spectrum light_intensity(const ProjectionLight& l, Vec3 w, const Wavelengths& wl) {
  auto uv = projection_uv(l, w);
  if (!uv) return {};
  return illuminant_texel(projection_texel(l, *uv), l.scale, wl);
}

void prepare_projection_light(ProjectionLight* l) {
  const TexImage& im = *l->image;
  float aspect = float(im.width) / float(im.height);
  l->half_width = aspect > 1 ? aspect : 1;
  l->half_height = aspect > 1 ? 1 : 1 / aspect;
  // Texels weighted by their solid angle (cos^3 at the centre; sub-texel points would matter only
  // for fields of view near 180 degrees).
  std::vector<float> weights(size_t(im.width) * size_t(im.height));
  Rgb power(0.0f);
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      Vec2 uv((x + 0.5f) / im.width, (y + 0.5f) / im.height);
      float omega = projection_solid_angle_per_area(*l, uv) / float(im.width * im.height);
      Rgb rgb = projection_texel(*l, uv);
      weights[size_t(y) * im.width + x] = rgb.average() * omega;
      power += rgb * (omega * l->scale);
    }
  l->distribution = Distribution2D(weights, im.width, im.height);
  l->power_rgb = power;
}

std::optional<LightLiSample> sample_li_of(const ProjectionLight& l, const Shape*, Vec3 p_ref, Vec2,
                                          const SceneBoundsInfo&, const Wavelengths& wl) {
  return sample_li_directional_point(l, p_ref, wl);
}

std::optional<LightLeSample> sample_le_of(const ProjectionLight& l, const Shape*, Vec2, Vec2 u_dir,
                                          const SceneBoundsInfo&, const Wavelengths& wl) {
  return sample_le_image_point(
      l, u_dir, [&](Vec2 uv) { return projection_direction_light(l, uv); },
      [&](Vec2 uv, Vec3, float pdf_uv) {
        return illuminant_texel(projection_texel(l, uv), l.scale, wl) *
               (projection_solid_angle_per_area(l, uv) / pdf_uv);
      });
}

Rgb power_of(const ProjectionLight& l, const SceneBoundsInfo&) { return l.power_rgb; }

// The densities of the sample_le_of above: uniform over the sphere (point) or the cone out to
// cos_falloff_end (spot); the image's distribution over the equal-area square, whose area is
// 4 pi steradians (goniometric), or over the projected frame (projection).
std::optional<float> point_light_pdf_le(const Light& light, Vec3 w) {
  if (std::holds_alternative<PointLight>(light)) return kUniformSpherePdfSolidAngle;
  if (const auto* l = std::get_if<SpotLight>(&light))
    return spot_falloff(*l, l->frame.to_local(w)) > 0
               ? uniform_cone_pdf_solid_angle(l->cos_falloff_end)
               : 0.0f;
  if (const auto* l = std::get_if<GoniometricLight>(&light)) {
    const Vec3 wl = swap_yz(normalize(l->world_from_light.inverse().vector(w)));
    return l->distribution.pdf(equal_area_sphere_to_square(wl)) / (4 * kPi);
  }
  if (const auto* l = std::get_if<ProjectionLight>(&light)) {
    const auto uv = projection_uv(*l, w);
    return uv ? l->distribution.pdf(*uv) / projection_solid_angle_per_area(*l, *uv) : 0.0f;
  }
  return std::nullopt;
}

}  // namespace bpm
