#include "lights/light.h"

#include <cmath>

#include "base/sampling.h"

namespace bpm {

bool light_is_delta(const Light& l) {
  return std::holds_alternative<PointLight>(l) || std::holds_alternative<SpotLight>(l) ||
         std::holds_alternative<GoniometricLight>(l) || std::holds_alternative<ProjectionLight>(l) ||
         std::holds_alternative<DistantLight>(l);
}
bool light_is_infinite(const Light& l) { return std::holds_alternative<DistantLight>(l) || light_is_environment(l); }
bool light_is_environment(const Light& l) {
  return std::holds_alternative<UniformInfiniteLight>(l) || std::holds_alternative<ImageInfiniteLight>(l);
}

// ---- image infinite lights ----

namespace {

constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

// An image light's texel (negative values clamped) as an illuminant spectrum times scale.
Spectrum illuminant_texel(Rgb rgb, float scale, const Wavelengths& wl) {
  rgb = rgb.clamped_zero();
  if (rgb.max_component() == 0) return {};
  return rgb_texel_spectrum(rgb, SpectrumKind::kIlluminant, wl) * scale;
}

Spectrum image_radiance(const ImageInfiniteLight& l, Vec2 uv, const Wavelengths& wl) {
  Rgb rgb;
  if (l.equal_area) {
    rgb = l.image->lookup(uv, TexFilter::kPoint, TexWrap::kOctahedralSphere);
  } else {
    rgb = l.image->lookup({uv.x, std::clamp(uv.y, 0.0f, kOneMinusEpsilon)}, TexFilter::kPoint, TexWrap::kRepeat);
  }
  return illuminant_texel(rgb, l.scale, wl);
}

// The solid angle of texel row y (all texels of a row cover the same one).
double texel_solid_angle(const ImageInfiniteLight& l, int y) {
  const TexImage& im = *l.image;
  if (l.equal_area) return 4 * M_PI / (double(im.width) * im.height);
  double t0 = M_PI * y / im.height, t1 = M_PI * (y + 1) / im.height;
  return 2 * M_PI / im.width * (std::cos(t0) - std::cos(t1));
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
  // row), so that the density is the texel's probability over its solid angle, bounded at the poles.
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
            double ct = c0 + (j + 0.5) / sub * (c1 - c0), st = std::sqrt(std::fmax(0.0, 1 - ct * ct));
            w = Vec3(float(st * std::cos(uv.x * 2 * M_PI)), float(st * std::sin(uv.x * 2 * M_PI)), float(ct));
          }
          cos_sum += std::fmax(0.0f, w.z);
        }
      e += lum * cos_sum / (sub * sub) * texel_solid_angle(l, y);
    }
  return e;
}

// ---- goniometric and projection lights ----

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

Spectrum environment_radiance(const Light& light, Vec3 w, const Wavelengths& wl) {
  if (auto* u = std::get_if<UniformInfiniteLight>(&light)) return u->radiance.sample(wl);
  if (auto* im = std::get_if<ImageInfiniteLight>(&light)) return image_radiance(*im, image_light_uv(*im, w), wl);
  return {};
}

Spectrum area_light_radiance(const AreaLight& l, Vec3 n, Vec2 uv, Vec3 w, const Wavelengths& wl) {
  if (!l.two_sided && dot(n, w) <= 0) return {};
  if (!l.image) return l.radiance.sample(wl);
  return illuminant_texel(l.image->lookup({uv.x, 1 - uv.y}, TexFilter::kBilinear, TexWrap::kClamp), l.image_scale, wl);
}

float spot_falloff(const SpotLight& l, Vec3 w) {
  float c = w.z;
  if (c >= l.cos_falloff_start) return 1;
  if (c <= l.cos_falloff_end) return 0;
  float t = (c - l.cos_falloff_end) / (l.cos_falloff_start - l.cos_falloff_end);
  return t * t * (3 - 2 * t);
}

float primitive_area(const Shape& shape, int prim) {
  if (auto* m = std::get_if<TriangleMesh>(&shape)) {
    Vec3 p0 = m->positions[m->indices[3 * prim]], p1 = m->positions[m->indices[3 * prim + 1]],
         p2 = m->positions[m->indices[3 * prim + 2]];
    return 0.5f * length(cross(p1 - p0, p2 - p0));
  }
  if (auto* s = std::get_if<Sphere>(&shape)) {
    float scale = 1;
    s->world_from_object.is_similarity(&scale);
    float r = s->radius * scale;
    return s->phi_max * r * (std::fmin(s->z_max, s->radius) - std::fmax(s->z_min, -s->radius)) * scale;
  }
  if (auto* c = std::get_if<Cylinder>(&shape)) {
    float scale = 1;
    c->world_from_object.is_similarity(&scale);
    return c->phi_max * c->radius * (c->z_max - c->z_min) * scale * scale;
  }
  const Disk& k = std::get<Disk>(shape);
  float scale = 1;
  k.world_from_object.is_similarity(&scale);
  return 0.5f * k.phi_max * (k.radius * k.radius - k.inner_radius * k.inner_radius) * scale * scale;
}

namespace {

struct AreaSample {
  Vec3 p, n;
  float pdf_area;
  Vec2 uv;
};

// Uniform point on the primitive (triangles; full spheres and disks, and cylinders, under
// similarity transforms, which flatten.cpp guarantees for emitters).
AreaSample sample_area(const AreaLight& l, const Shape& shape, Vec2 u) {
  if (std::holds_alternative<TriangleMesh>(shape)) {
    Vec2 b = sample_uniform_triangle(u);  // (b0, b1); surface_point takes (b1, b2)
    SurfacePoint sp = surface_point(shape, l.primitive, {b.y, 1 - b.x - b.y}, {});
    return {sp.p, sp.ng, 1 / l.area, sp.uv};
  }
  if (auto* s = std::get_if<Sphere>(&shape)) {
    Vec3 po = sample_uniform_sphere(u) * s->radius;
    SurfacePoint sp = surface_point(shape, 0, {}, s->world_from_object.point(po));
    return {sp.p, sp.ng, 1 / l.area, sp.uv};
  }
  if (auto* c = std::get_if<Cylinder>(&shape)) {
    float phi = u.y * c->phi_max;
    Vec3 po(c->radius * std::cos(phi), c->radius * std::sin(phi), c->z_min + u.x * (c->z_max - c->z_min));
    SurfacePoint sp = surface_point(shape, 0, {}, c->world_from_object.point(po));
    return {sp.p, sp.ng, 1 / l.area, sp.uv};
  }
  const Disk& k = std::get<Disk>(shape);
  Vec2 d = sample_uniform_disk_concentric(u);
  Vec3 po(d.x * k.radius, d.y * k.radius, k.height);
  SurfacePoint sp = surface_point(shape, 0, {}, k.world_from_object.point(po));
  return {sp.p, sp.ng, 1 / l.area, sp.uv};
}

struct SphereWorld {
  Vec3 center;
  float radius;
};
SphereWorld sphere_world(const Sphere& s) {
  float scale = 1;
  s.world_from_object.is_similarity(&scale);
  return {s.world_from_object.point(Vec3(0, 0, 0)), s.radius * scale};
}

}  // namespace

std::optional<LightLiSample> light_sample_li(const Light& light, const Shape* shape, Vec3 p_ref, Vec2 u,
                                             const SceneBoundsInfo& bounds, const Wavelengths& wl) {
  LightLiSample ls;
  if (auto* l = std::get_if<PointLight>(&light)) {
    Vec3 d = l->position - p_ref;
    float d2 = length_squared(d);
    if (d2 == 0) return std::nullopt;
    ls.wi = d / std::sqrt(d2);
    ls.radiance = l->intensity.sample(wl) / d2;
    ls.p_light = l->position;
    ls.pdf_solid_angle = 1;
    ls.is_delta = true;
    return ls;
  }
  if (auto* l = std::get_if<SpotLight>(&light)) {
    Vec3 d = l->position - p_ref;
    float d2 = length_squared(d);
    if (d2 == 0) return std::nullopt;
    ls.wi = d / std::sqrt(d2);
    float fall = spot_falloff(*l, l->frame.to_local(-ls.wi));
    if (fall == 0) return std::nullopt;
    ls.radiance = l->intensity.sample(wl) * (fall / d2);
    ls.p_light = l->position;
    ls.pdf_solid_angle = 1;
    ls.is_delta = true;
    return ls;
  }
  auto* gonio = std::get_if<GoniometricLight>(&light);
  auto* proj = std::get_if<ProjectionLight>(&light);
  if (gonio || proj) {
    Vec3 position = (gonio ? gonio->world_from_light : proj->world_from_light).point(Vec3(0, 0, 0));
    Vec3 d = position - p_ref;
    float d2 = length_squared(d);
    if (d2 == 0) return std::nullopt;
    ls.wi = d / std::sqrt(d2);
    Spectrum I = gonio ? light_intensity(*gonio, -ls.wi, wl) : light_intensity(*proj, -ls.wi, wl);
    if (I.is_black()) return std::nullopt;
    ls.radiance = I / d2;
    ls.p_light = position;
    ls.pdf_solid_angle = 1;
    ls.is_delta = true;
    return ls;
  }
  if (auto* l = std::get_if<DistantLight>(&light)) {
    ls.wi = l->direction_to_light;
    ls.radiance = l->radiance.sample(wl);
    ls.p_light = p_ref + ls.wi * (2 * bounds.radius);
    ls.pdf_solid_angle = 1;
    ls.is_delta = true;
    ls.is_infinite = true;
    return ls;
  }
  if (auto* l = std::get_if<UniformInfiniteLight>(&light)) {
    ls.wi = sample_uniform_sphere(u);
    ls.radiance = l->radiance.sample(wl);
    ls.p_light = p_ref + ls.wi * (2 * bounds.radius);
    ls.pdf_solid_angle = kUniformSpherePdfSolidAngle;
    ls.is_infinite = true;
    return ls;
  }
  if (auto* l = std::get_if<ImageInfiniteLight>(&light)) {
    float pdf = 0;
    Vec2 uv = image_light_sample(*l, u, &pdf);
    if (!(pdf > 0)) return std::nullopt;
    ls.wi = image_light_direction(*l, uv);
    ls.radiance = image_radiance(*l, uv, wl);
    ls.p_light = p_ref + ls.wi * (2 * bounds.radius);
    ls.pdf_solid_angle = pdf;
    ls.is_infinite = true;
    if (ls.radiance.is_black()) return std::nullopt;
    return ls;
  }
  const AreaLight& l = std::get<AreaLight>(light);
  if (auto* s = std::get_if<Sphere>(shape)) {
    SphereWorld sw = sphere_world(*s);
    Vec3 to_center = sw.center - p_ref;
    float dc2 = length_squared(to_center);
    if (dc2 > sw.radius * sw.radius * 1.0001f) {
      // Outside: sample the cone of directions the sphere subtends (pbrt-v4 Sphere::Sample).
      float dc = std::sqrt(dc2);
      float sin2_max = sw.radius * sw.radius / dc2;
      float cos_max = std::sqrt(std::fmax(0.0f, 1 - sin2_max));
      Frame f = Frame::from_z(to_center / dc);
      Vec3 w = f.to_world(sample_uniform_cone(u, cos_max));
      // Nearest intersection of the sampled direction with the sphere.
      float b = dot(w, to_center);
      float disc = std::fmax(0.0f, b * b - (dc2 - sw.radius * sw.radius));
      float t = b - std::sqrt(disc);
      Vec3 p = p_ref + w * t;
      SurfacePoint sp = surface_point(*shape, 0, {}, p);
      ls.wi = w;
      ls.p_light = sp.p;
      ls.n_light = sp.ng;
      ls.radiance = area_light_radiance(l, sp.ng, sp.uv, -w, wl);
      ls.pdf_solid_angle = uniform_cone_pdf_solid_angle(cos_max);
      if (ls.radiance.is_black()) return std::nullopt;
      return ls;
    }
  }
  AreaSample as = sample_area(l, *shape, u);
  Vec3 d = as.p - p_ref;
  float d2 = length_squared(d);
  if (d2 == 0) return std::nullopt;
  ls.wi = d / std::sqrt(d2);
  float cos_l = absdot(as.n, ls.wi);
  if (cos_l == 0) return std::nullopt;
  ls.p_light = as.p;
  ls.n_light = as.n;
  ls.radiance = area_light_radiance(l, as.n, as.uv, -ls.wi, wl);
  ls.pdf_solid_angle = as.pdf_area * d2 / cos_l;
  if (ls.radiance.is_black()) return std::nullopt;
  return ls;
}

float light_pdf_li(const Light& light, const Shape* shape, Vec3 p_ref, Vec3 wi, Vec3 p_light, Vec3 n_light) {
  if (light_is_delta(light)) return 0;
  if (std::holds_alternative<UniformInfiniteLight>(light)) return kUniformSpherePdfSolidAngle;
  if (auto* im = std::get_if<ImageInfiniteLight>(&light)) {
    return image_light_pdf(*im, image_light_uv(*im, wi));
  }
  const AreaLight& l = std::get<AreaLight>(light);
  if (auto* s = std::get_if<Sphere>(shape)) {
    SphereWorld sw = sphere_world(*s);
    float dc2 = length_squared(sw.center - p_ref);
    if (dc2 > sw.radius * sw.radius * 1.0001f) {
      float cos_max = std::sqrt(std::fmax(0.0f, 1 - sw.radius * sw.radius / dc2));
      return uniform_cone_pdf_solid_angle(cos_max);
    }
  }
  float d2 = length_squared(p_light - p_ref);
  float cos_l = absdot(n_light, wi);
  if (cos_l == 0) return 0;
  return d2 / (cos_l * l.area);
}

std::optional<LightLeSample> light_sample_le(const Light& light, const Shape* shape, Vec2 u_pos, Vec2 u_dir,
                                             const SceneBoundsInfo& bounds, const Wavelengths& wl) {
  LightLeSample s;
  if (auto* l = std::get_if<PointLight>(&light)) {
    s.origin = l->position;
    s.direction = sample_uniform_sphere(u_dir);
    s.flux = l->intensity.sample(wl) / kUniformSpherePdfSolidAngle;
    return s;
  }
  if (auto* l = std::get_if<SpotLight>(&light)) {
    Vec3 w = sample_uniform_cone(u_dir, l->cos_falloff_end);
    float fall = spot_falloff(*l, w);
    if (fall == 0) return std::nullopt;
    s.origin = l->position;
    s.direction = l->frame.to_world(w);
    s.flux = l->intensity.sample(wl) * (fall / uniform_cone_pdf_solid_angle(l->cos_falloff_end));
    return s;
  }
  if (auto* l = std::get_if<GoniometricLight>(&light)) {
    float pdf_uv = 0;
    Vec2 uv = l->distribution.sample(u_dir, &pdf_uv);
    if (!(pdf_uv > 0)) return std::nullopt;
    s.origin = l->world_from_light.point(Vec3(0, 0, 0));
    s.direction = normalize(l->world_from_light.vector(swap_yz(equal_area_square_to_sphere(uv))));
    s.flux = light_intensity(*l, s.direction, wl) * (4 * kPi / pdf_uv);
    if (s.flux.is_black()) return std::nullopt;
    return s;
  }
  if (auto* l = std::get_if<ProjectionLight>(&light)) {
    float pdf_uv = 0;
    Vec2 uv = l->distribution.sample(u_dir, &pdf_uv);
    if (!(pdf_uv > 0)) return std::nullopt;
    s.origin = l->world_from_light.point(Vec3(0, 0, 0));
    s.direction = normalize(l->world_from_light.vector(projection_direction_light(*l, uv)));
    s.flux = illuminant_texel(projection_texel(*l, uv), l->scale, wl) * (projection_solid_angle_per_area(*l, uv) / pdf_uv);
    if (s.flux.is_black()) return std::nullopt;
    return s;
  }
  // Infinite lights emit through a disk of the scene's bounding radius, facing the direction of
  // travel, placed outside the scene (pbrt-v4 DistantLight/UniformInfiniteLight::SampleLe).
  auto disk_origin = [&](Vec3 d) {
    Frame f = Frame::from_z(d);
    Vec2 q = sample_uniform_disk_concentric(u_pos);
    return bounds.center + f.to_world(Vec3(q.x, q.y, -1)) * bounds.radius;
  };
  float disk_area = kPi * bounds.radius * bounds.radius;
  if (auto* l = std::get_if<DistantLight>(&light)) {
    s.direction = -l->direction_to_light;
    s.origin = disk_origin(s.direction);
    s.flux = l->radiance.sample(wl) * disk_area;
    return s;
  }
  if (auto* l = std::get_if<UniformInfiniteLight>(&light)) {
    s.direction = sample_uniform_sphere(u_dir);
    s.origin = disk_origin(s.direction);
    s.flux = l->radiance.sample(wl) * (disk_area / kUniformSpherePdfSolidAngle);
    return s;
  }
  if (auto* l = std::get_if<ImageInfiniteLight>(&light)) {
    float pdf = 0;
    Vec2 uv = image_light_sample(*l, u_dir, &pdf);
    if (!(pdf > 0)) return std::nullopt;
    s.direction = -image_light_direction(*l, uv);
    s.origin = disk_origin(s.direction);
    s.flux = image_radiance(*l, uv, wl) * (disk_area / pdf);
    if (s.flux.is_black()) return std::nullopt;
    return s;
  }
  const AreaLight& l = std::get<AreaLight>(light);
  AreaSample as = sample_area(l, *shape, u_pos);
  // Cosine-weighted about the normal; a two-sided emitter picks its side with probability 1/2.
  float side = 1, side_pdf = 1;
  if (l.two_sided) {
    side_pdf = 0.5f;
    if (u_dir.x < 0.5f) {
      u_dir.x *= 2;
    } else {
      u_dir.x = 2 * u_dir.x - 1;
      side = -1;
    }
  }
  Vec3 w_local = sample_cosine_hemisphere(u_dir);
  float pdf_dir = side_pdf * cosine_hemisphere_pdf_solid_angle(w_local.z);
  if (pdf_dir == 0) return std::nullopt;
  Vec3 n = as.n * side;
  s.direction = Frame::from_z(n).to_world(w_local);
  s.origin = as.p;
  s.n_light = as.n;
  s.flux = area_light_radiance(l, as.n, as.uv, s.direction, wl) * (w_local.z / (as.pdf_area * pdf_dir));
  return s;
}

Rgb light_power(const Light& light, const SceneBoundsInfo& bounds) {
  if (auto* l = std::get_if<PointLight>(&light)) return l->intensity.rgb() * (4 * kPi);
  if (auto* l = std::get_if<SpotLight>(&light))
    return l->intensity.rgb() * (2 * kPi * ((1 - l->cos_falloff_start) + (l->cos_falloff_start - l->cos_falloff_end) / 2));
  if (auto* l = std::get_if<GoniometricLight>(&light)) return l->intensity.rgb() * (4 * kPi * l->mean_value);
  if (auto* l = std::get_if<ProjectionLight>(&light)) return l->power_rgb;
  if (auto* l = std::get_if<DistantLight>(&light)) return l->radiance.rgb() * (kPi * bounds.radius * bounds.radius);
  if (auto* l = std::get_if<UniformInfiniteLight>(&light))
    return l->radiance.rgb() * (4 * kPi * kPi * bounds.radius * bounds.radius);
  if (auto* l = std::get_if<ImageInfiniteLight>(&light))
    return l->mean_radiance * (4 * kPi * kPi * bounds.radius * bounds.radius);
  const AreaLight& l = std::get<AreaLight>(light);
  Rgb L = l.image ? l.image_mean * l.image_scale : l.radiance.rgb();
  return L * (kPi * (l.two_sided ? 2 : 1) * l.area);
}

}  // namespace bpm
