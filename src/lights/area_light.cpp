// Diffuse area lights (pbrt-v4 DiffuseAreaLight) on one primitive of an object.
#include <cmath>

#include "base/sampling.h"
#include "lights/light_types.h"

namespace bpm {

Spectrum area_light_radiance(const AreaLight& l, Vec3 n, Vec2 uv, Vec3 w, const Wavelengths& wl,
                             const Spectrum* spectrum) {
  if (!l.two_sided && dot(n, w) <= 0) return {};
  if (!l.image) return spectrum ? *spectrum : l.radiance.sample(wl);
  return illuminant_texel(l.image->lookup({uv.x, 1 - uv.y}, TexFilter::kBilinear, TexWrap::kClamp),
                          l.image_scale, wl);
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
    return s->phi_max * r * (std::fmin(s->z_max, s->radius) - std::fmax(s->z_min, -s->radius)) *
           scale;
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
  float error;  // p's (SurfacePoint::error)
};

// Uniform point on the primitive (triangles; full spheres and disks, and cylinders, under
// similarity transforms, which flatten_shapes.cpp guarantees for emitters).
AreaSample sample_area(const AreaLight& l, const Shape& shape, Vec2 u) {
  if (std::holds_alternative<TriangleMesh>(shape)) {
    Vec2 b = sample_uniform_triangle(u);  // (b0, b1); surface_point takes (b1, b2)
    SurfacePoint sp = surface_point(shape, l.primitive, {b.y, 1 - b.x - b.y}, {});
    return {sp.p, sp.ng, 1 / l.area, sp.uv, sp.error};
  }
  if (auto* s = std::get_if<Sphere>(&shape)) {
    Vec3 po = sample_uniform_sphere(u) * s->radius;
    SurfacePoint sp = surface_point(shape, 0, {}, s->world_from_object.point(po));
    return {sp.p, sp.ng, 1 / l.area, sp.uv, sp.error};
  }
  if (auto* c = std::get_if<Cylinder>(&shape)) {
    float phi = u.y * c->phi_max;
    Vec3 po(c->radius * std::cos(phi), c->radius * std::sin(phi),
            c->z_min + u.x * (c->z_max - c->z_min));
    SurfacePoint sp = surface_point(shape, 0, {}, c->world_from_object.point(po));
    return {sp.p, sp.ng, 1 / l.area, sp.uv, sp.error};
  }
  const Disk& k = std::get<Disk>(shape);
  Vec2 d = sample_uniform_disk_concentric(u);
  Vec3 po(d.x * k.radius, d.y * k.radius, k.height);
  SurfacePoint sp = surface_point(shape, 0, {}, k.world_from_object.point(po));
  return {sp.p, sp.ng, 1 / l.area, sp.uv, sp.error};
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

std::optional<LightLiSample> sample_li_of(const AreaLight& l, const Shape* shape, Vec3 p_ref,
                                          Vec2 u, const SceneBoundsInfo&, const Wavelengths& wl,
                                          const Spectrum* spectrum) {
  LightLiSample ls;
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
      ls.p_light_error = sp.error;
      ls.radiance = area_light_radiance(l, sp.ng, sp.uv, -w, wl, spectrum);
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
  ls.p_light_error = as.error;
  ls.radiance = area_light_radiance(l, as.n, as.uv, -ls.wi, wl, spectrum);
  ls.pdf_solid_angle = as.pdf_area * d2 / cos_l;
  if (ls.radiance.is_black()) return std::nullopt;
  return ls;
}

LightPoint sample_point_of(const AreaLight& l, const Shape& shape, Vec2 u) {
  const AreaSample as = sample_area(l, shape, u);
  return {as.p, as.n, as.uv, as.error, as.pdf_area, false};
}

float pdf_li_of(const AreaLight& l, const Shape* shape, Vec3 p_ref, Vec3 wi, Vec3 p_light,
                Vec3 n_light) {
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

std::optional<LightLeSample> sample_le_of(const AreaLight& l, const Shape* shape, Vec2 u_pos,
                                          Vec2 u_dir, const SceneBoundsInfo&, const Wavelengths& wl,
                                          const Spectrum* spectrum) {
  LightLeSample s;
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
  s.origin_error = as.error;
  s.flux = area_light_radiance(l, as.n, as.uv, s.direction, wl, spectrum) *
           (w_local.z / (as.pdf_area * pdf_dir));
  return s;
}

Rgb power_of(const AreaLight& l, const SceneBoundsInfo&) {
  Rgb L = l.image ? l.image_mean * l.image_scale : l.radiance.rgb();
  return L * (kPi * (l.two_sided ? 2 : 1) * l.area);
}

}  // namespace bpm
