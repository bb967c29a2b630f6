// Lights at infinity: distant, uniform and image infinite lights (pbrt-v4 DistantLight,
// UniformInfiniteLight, ImageInfiniteLight).
#include <algorithm>
#include <cmath>
#include <vector>

#include "base/sampling.h"
#include "lights/light_types.h"

namespace bpm {

namespace {
// Infinite lights emit through a disk of the scene's bounding radius, facing the direction of
// travel, placed outside the scene (pbrt-v4 DistantLight/UniformInfiniteLight::SampleLe).
Vec3 disk_origin(Vec3 d, Vec2 u_pos, const SceneBoundsInfo& bounds) {
  Frame f = Frame::from_z(d);
  Vec2 q = sample_uniform_disk_concentric(u_pos);
  return bounds.center + f.to_world(Vec3(q.x, q.y, -1)) * bounds.radius;
}
float disk_area(const SceneBoundsInfo& bounds) { return kPi * bounds.radius * bounds.radius; }
}  // namespace

// ---- distant ----

std::optional<LightLiSample> sample_li_of(const DistantLight& l, const Shape*, Vec3 p_ref, Vec2,
                                          const SceneBoundsInfo& bounds, const Wavelengths& wl) {
  LightLiSample ls;
  ls.wi = l.direction_to_light;
  ls.radiance = l.radiance.sample(wl);
  ls.p_light = p_ref + ls.wi * (2 * bounds.radius);
  ls.pdf_solid_angle = 1;
  ls.is_delta = true;
  ls.is_infinite = true;
  return ls;
}

std::optional<LightLeSample> sample_le_of(const DistantLight& l, const Shape*, Vec2 u_pos, Vec2,
                                          const SceneBoundsInfo& bounds, const Wavelengths& wl) {
  LightLeSample s;
  s.direction = -l.direction_to_light;
  s.origin = disk_origin(s.direction, u_pos, bounds);
  s.flux = l.radiance.sample(wl) * disk_area(bounds);
  return s;
}

Rgb power_of(const DistantLight& l, const SceneBoundsInfo& bounds) {
  return l.radiance.rgb() * (kPi * bounds.radius * bounds.radius);
}

// ---- uniform infinite ----

std::optional<LightLiSample> sample_li_of(const UniformInfiniteLight& l, const Shape*, Vec3 p_ref,
                                          Vec2 u, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl) {
  LightLiSample ls;
  ls.wi = sample_uniform_sphere(u);
  ls.radiance = l.radiance.sample(wl);
  ls.p_light = p_ref + ls.wi * (2 * bounds.radius);
  ls.pdf_solid_angle = kUniformSpherePdfSolidAngle;
  ls.is_infinite = true;
  return ls;
}

float pdf_li_of(const UniformInfiniteLight&, const Shape*, Vec3, Vec3, Vec3, Vec3) {
  return kUniformSpherePdfSolidAngle;
}

std::optional<LightLeSample> sample_le_of(const UniformInfiniteLight& l, const Shape*, Vec2 u_pos,
                                          Vec2 u_dir, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl) {
  LightLeSample s;
  s.direction = sample_uniform_sphere(u_dir);
  s.origin = disk_origin(s.direction, u_pos, bounds);
  s.flux = l.radiance.sample(wl) * (disk_area(bounds) / kUniformSpherePdfSolidAngle);
  return s;
}

Spectrum environment_radiance_of(const UniformInfiniteLight& l, Vec3, const Wavelengths& wl) {
  return l.radiance.sample(wl);
}

Rgb power_of(const UniformInfiniteLight& l, const SceneBoundsInfo& bounds) {
  return l.radiance.rgb() * (4 * kPi * kPi * bounds.radius * bounds.radius);
}

// ---- image infinite ----

namespace {

constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

Spectrum image_radiance(const ImageInfiniteLight& l, Vec2 uv, const Wavelengths& wl) {
  Rgb rgb;
  if (l.equal_area) {
    rgb = l.image->lookup(uv, TexFilter::kPoint, TexWrap::kOctahedralSphere);
  } else {
    rgb = l.image->lookup({uv.x, std::clamp(uv.y, 0.0f, kOneMinusEpsilon)}, TexFilter::kPoint,
                          TexWrap::kRepeat);
  }
  return illuminant_texel(rgb, l.scale, wl);
}

// Whether the light reaches the scene along w (toward the light): always without a portal.
bool through_portal(const ImageInfiniteLight& l, Vec3 w) {
  return !l.portal_normal || dot(w, *l.portal_normal) > 0;
}

// The solid angle of texel row y (all texels of a row cover the same one).
double texel_solid_angle(const ImageInfiniteLight& l, int y) {
  const TexImage& im = *l.image;
  if (l.equal_area) return 4 * M_PI / (double(im.width) * im.height);
  return latlong_cell_solid_angle(y, im.width, im.height);
}

}  // namespace

Vec3 image_light_direction(const ImageInfiniteLight& l, Vec2 uv) {
  Vec3 w;
  if (l.equal_area) {
    w = equal_area_square_to_sphere(uv);
  } else {
    float theta = uv.y * kPi, phi = uv.x * 2 * kPi;
    w = Vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  }
  return normalize(l.world_from_light.vector(w));
}

Vec2 image_light_uv(const ImageInfiniteLight& l, Vec3 w_world) {
  Vec3 w = normalize(l.world_from_light.inverse().vector(w_world));
  if (l.equal_area) return equal_area_sphere_to_square(w);
  float phi = std::atan2(w.y, w.x);
  if (phi < 0) phi += 2 * kPi;
  // atan2 keeps theta accurate near the poles, where acos(z) loses it (and the density, through
  // sin theta, with it).
  return {phi / (2 * kPi), std::atan2(std::sqrt(w.x * w.x + w.y * w.y), w.z) / kPi};
}

Vec2 image_light_sample(const ImageInfiniteLight& l, Vec2 u, float* pdf_solid_angle) {
  float pdf_uv = 0;
  Vec2 uv = l.distribution.sample(u, &pdf_uv);
  const TexImage& im = *l.image;
  if (l.equal_area) {
    *pdf_solid_angle = pdf_uv / (4 * kPi);  // d omega = 4 pi du dv
    return uv;
  }
  // Latitude-longitude: uniform in solid angle within the texel (uniform in cos theta across its
  // row), so that the density is the texel's probability over its solid angle, bounded at the
  // poles.
  int y = std::clamp(int(uv.y * float(im.height)), 0, im.height - 1);
  float frac = uv.y * float(im.height) - float(y);
  double c0 = std::cos(M_PI * y / im.height), c1 = std::cos(M_PI * (y + 1) / im.height);
  double cos_theta = c0 + double(frac) * (c1 - c0);
  uv.y = float(std::acos(std::clamp(cos_theta, -1.0, 1.0)) / M_PI);
  *pdf_solid_angle = float(pdf_uv / (double(im.width) * im.height) / texel_solid_angle(l, y));
  return uv;
}

float image_light_pdf(const ImageInfiniteLight& l, Vec2 uv) {
  float pdf_uv = l.distribution.pdf(uv);
  if (l.equal_area) return pdf_uv / (4 * kPi);
  const TexImage& im = *l.image;
  int y = std::clamp(int(uv.y * float(im.height)), 0, im.height - 1);
  return float(pdf_uv / (double(im.width) * im.height) / texel_solid_angle(l, y));
}

void prepare_image_light(ImageInfiniteLight* l) {
  const TexImage& im = *l->image;
  std::vector<float> weights(size_t(im.width) * size_t(im.height));
  Rgb sum(0.0f);
  double omega_total = 0;
  for (int y = 0; y < im.height; ++y) {
    double omega = texel_solid_angle(*l, y);
    omega_total += omega * im.width;
    for (int x = 0; x < im.width; ++x) {
      Rgb rgb = im.texel(x, y, TexWrap::kClamp).clamped_zero();
      // Behind a portal (its corners, edge middles and centre all are): never drawn.
      if (l->portal_normal) {
        bool seen = false;
        for (int j = 0; j <= 2 && !seen; ++j)
          for (int i = 0; i <= 2 && !seen; ++i)
            seen = through_portal(
                *l, image_light_direction(*l, {(float(x) + 0.5f * float(i)) / float(im.width),
                                               (float(y) + 0.5f * float(j)) / float(im.height)}));
        if (!seen) rgb = Rgb(0.0f);
      }
      weights[size_t(y) * im.width + x] = float(rgb.average() * omega);
      for (int c = 0; c < 3; ++c) sum[c] += float(rgb[c] * omega);
    }
  }
  l->distribution = Distribution2D(weights, im.width, im.height);
  l->mean_radiance = sum * float(l->scale / omega_total);
}

double image_light_illuminance(const ImageInfiniteLight& l) {
  // Each texel's luminance times the integral of max(0, cos theta) over its solid angle, by
  // sub-texel points of equal solid angle: exact in the limit even for texels the horizon crosses.
  const TexImage& im = *l.image;
  int sub = std::clamp(256 / im.height, 1, 16);
  double e = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      double lum = im.texel(x, y, TexWrap::kClamp).clamped_zero().luminance();
      if (lum == 0) continue;
      double cos_sum = 0;
      for (int j = 0; j < sub; ++j)
        for (int i = 0; i < sub; ++i) {
          Vec2 uv((x + (i + 0.5f) / sub) / im.width, (y + (j + 0.5f) / sub) / im.height);
          Vec3 w;
          if (l.equal_area) {
            w = equal_area_square_to_sphere(uv);
          } else {  // rows of equal solid angle: uniform steps in cos theta
            double c0 = std::cos(M_PI * y / im.height), c1 = std::cos(M_PI * (y + 1) / im.height);
            double ct = c0 + (j + 0.5) / sub * (c1 - c0),
                   st = std::sqrt(std::fmax(0.0, 1 - ct * ct));
            w = Vec3(float(st * std::cos(uv.x * 2 * M_PI)), float(st * std::sin(uv.x * 2 * M_PI)),
                     float(ct));
          }
          cos_sum += std::fmax(0.0f, w.z);
        }
      e += lum * cos_sum / (sub * sub) * texel_solid_angle(l, y);
    }
  return e;
}

Spectrum environment_radiance_of(const ImageInfiniteLight& l, Vec3 w, const Wavelengths& wl) {
  if (!through_portal(l, w)) return {};
  return image_radiance(l, image_light_uv(l, w), wl);
}

std::optional<LightLiSample> sample_li_of(const ImageInfiniteLight& l, const Shape*, Vec3 p_ref,
                                          Vec2 u, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl) {
  LightLiSample ls;
  float pdf = 0;
  Vec2 uv = image_light_sample(l, u, &pdf);
  if (!(pdf > 0)) return std::nullopt;
  ls.wi = image_light_direction(l, uv);
  if (!through_portal(l, ls.wi)) return std::nullopt;
  ls.radiance = image_radiance(l, uv, wl);
  ls.p_light = p_ref + ls.wi * (2 * bounds.radius);
  ls.pdf_solid_angle = pdf;
  ls.is_infinite = true;
  if (ls.radiance.is_black()) return std::nullopt;
  return ls;
}

float pdf_li_of(const ImageInfiniteLight& l, const Shape*, Vec3, Vec3 wi, Vec3, Vec3) {
  return image_light_pdf(l, image_light_uv(l, wi));
}

std::optional<LightLeSample> sample_le_of(const ImageInfiniteLight& l, const Shape*, Vec2 u_pos,
                                          Vec2 u_dir, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl) {
  LightLeSample s;
  float pdf = 0;
  Vec2 uv = image_light_sample(l, u_dir, &pdf);
  if (!(pdf > 0)) return std::nullopt;
  s.direction = -image_light_direction(l, uv);
  if (!through_portal(l, -s.direction)) return std::nullopt;
  s.origin = disk_origin(s.direction, u_pos, bounds);
  s.flux = image_radiance(l, uv, wl) * (disk_area(bounds) / pdf);
  if (s.flux.is_black()) return std::nullopt;
  return s;
}

Rgb power_of(const ImageInfiniteLight& l, const SceneBoundsInfo& bounds) {
  return l.mean_radiance * (4 * kPi * kPi * bounds.radius * bounds.radius);
}

}  // namespace bpm
