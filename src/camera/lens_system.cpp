#include "camera/lens_system.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "base/error.h"

namespace bpm {
namespace {

std::string number(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", double(v));
  return buf;
}

// Lens space is camera space mirrored in z (the scene toward -z), where interface i lies at
// z = -(thickness of i and of every interface behind it).
Vec3 mirror_z(Vec3 v) { return {v.x, v.y, -v.z}; }

float index_of(float eta) { return eta == 0 ? 1 : eta; }

// The ray's hit on the sphere of the given radius about (0, 0, z_centre): the nearer root where
// the ray meets the sphere's cap on its side of the centre, in double precision (an element's
// sag is small against its radius). n faces the ray's origin.
bool intersect_element(float radius, float z_centre, Vec3 o, Vec3 d, float* t, Vec3* n) {
  const double ox = o.x, oy = o.y, oz = double(o.z) - z_centre;
  const double a = double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z;
  const double b = 2 * (d.x * ox + d.y * oy + d.z * oz);
  const double c = ox * ox + oy * oy + oz * oz - double(radius) * radius;
  const double disc = b * b - 4 * a * c;
  if (disc < 0 || a == 0) return false;
  const double q = b < 0 ? -0.5 * (b - std::sqrt(disc)) : -0.5 * (b + std::sqrt(disc));
  double t0 = q / a, t1 = q != 0 ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  const bool closer = (d.z > 0) != (radius < 0);
  *t = float(closer ? t0 : t1);
  if (!(*t >= 0)) return false;
  const Vec3 p{float(ox + *t * d.x), float(oy + *t * d.y), float(oz + *t * d.z)};
  *n = face_forward(normalize(p), -d);
  return true;
}

// Snell's law for wi (pointing away from the interface, on n's side) into a medium eta times as
// dense; false on total internal reflection.
bool refract(Vec3 wi, Vec3 n, float eta, Vec3* wt) {
  float cos_i = dot(n, wi);
  if (cos_i < 0) eta = 1 / eta, cos_i = -cos_i, n = -n;
  const float sin2_t = std::max(0.0f, 1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return false;
  const float cos_t = std::sqrt(1 - sin2_t);
  *wt = -wi / eta + n * (cos_i / eta - cos_t);
  return true;
}

// pbrt-v4's cardinal points of a ray that entered parallel to the axis (r_in) and left (r_out):
// the principal plane (where the two meet) and the focal point (where r_out meets the axis).
void cardinal_points(const Ray& r_in, const Ray& r_out, float* pz, float* fz) {
  const float tf = -r_out.o.x / r_out.d.x;
  *fz = -(r_out.o.z + tf * r_out.d.z);
  const float tp = (r_in.o.x - r_out.o.x) / r_out.d.x;
  *pz = -(r_out.o.z + tp * r_out.d.z);
}

// Where the ray (lens space) meets interface e, which lies at z: the stop's plane or the element's
// sphere (n its normal, facing the ray's origin).
bool meet_interface(const LensInterface& e, float z, Vec3 o, Vec3 d, float* t, Vec3* n) {
  if (!e.is_stop())
    return intersect_element(e.curvature_radius, z + e.curvature_radius, o, d, t, n);
  *t = (z - o.z) / d.z;
  return *t >= 0;
}

}  // namespace

float ApertureMask::at(float u, float v) const {
  const float x = u * float(width) - 0.5f, y = v * float(height) - 0.5f;
  const int xi = int(std::floor(x)), yi = int(std::floor(y));
  const float dx = x - float(xi), dy = y - float(yi);
  auto texel = [&](int i, int j) {
    if (i < 0 || j < 0 || i >= width || j >= height) return 0.0f;
    return values[size_t(j) * size_t(width) + size_t(i)];
  };
  return (1 - dx) * (1 - dy) * texel(xi, yi) + dx * (1 - dy) * texel(xi + 1, yi) +
         (1 - dx) * dy * texel(xi, yi + 1) + dx * dy * texel(xi + 1, yi + 1);
}

LensSystem::LensSystem(LensSettings s, int full_width, int full_height)
    : interfaces_(std::move(s.interfaces)),
      aperture_(std::move(s.aperture)),
      film_diagonal_(s.film_diagonal) {
  BPM_CHECK(!interfaces_.empty() && full_width > 0 && full_height > 0);
  const float aspect = float(full_height) / float(full_width);
  extent_x_ = std::sqrt(film_diagonal_ * film_diagonal_ / (1 + aspect * aspect));
  extent_y_ = aspect * extent_x_;
  focus(s.focus_distance);
  // The exit pupil's bounds over 64 rings of the film, as pbrt-v4 (which traces 2^20 rays per
  // ring where this traces 2^16 + 2^14; bounds a little looser cost samples, not accuracy).
  const int rings = 64;
  pupil_.resize(rings);
  tbb::parallel_for(0, rings, [&](int i) {
    const float half = film_diagonal_ / 2;
    pupil_[size_t(i)] = bound_exit_pupil(half * float(i) / rings, half * float(i + 1) / rings);
  });
  if (pupil_[0].empty())
    throw Error("the lens passes no light to the film's centre (is its aperture stop closed?)");
  // A pixel's angle: the chief rays of film points a few pixels either side of the centre.
  const float pitch = extent_x_ / float(full_width), dx = 4 * pitch;
  Ray a, b;
  if (trace_from_film(Ray{{dx, 0, 0}, {-dx, 0, rear_z()}}, &a) > 0 &&
      trace_from_film(Ray{{-dx, 0, 0}, {dx, 0, rear_z()}}, &b) > 0)
    pixel_spread_ = length(cross(normalize(a.d), normalize(b.d))) / 8;
  else
    pixel_spread_ = pitch / focal_length_;
}

float LensSystem::front_z() const {
  float z = 0;
  for (const LensInterface& e : interfaces_) z += e.thickness;
  return z;
}

float LensSystem::trace_from_film(const Ray& r, Ray* out) const {
  Vec3 o = mirror_z(r.o), d = mirror_z(r.d);
  float z = 0, weight = 1;
  for (int i = int(interfaces_.size()) - 1; i >= 0; --i) {
    const LensInterface& e = interfaces_[size_t(i)];
    z -= e.thickness;
    float t;
    Vec3 n;
    if (!meet_interface(e, z, o, d, &t, &n)) return 0;
    const Vec3 p = o + d * t;
    if (e.is_stop() && !aperture_.empty()) {
      weight = aperture_.at((p.x / e.aperture_radius + 1) / 2, (p.y / e.aperture_radius + 1) / 2);
      if (!(weight > 0)) return 0;
    } else if (p.x * p.x + p.y * p.y > e.aperture_radius * e.aperture_radius) {
      return 0;
    }
    o = p;
    if (!e.is_stop()) {
      const float eta_i = index_of(e.eta);
      const float eta_t = i > 0 ? index_of(interfaces_[size_t(i) - 1].eta) : 1;
      if (!refract(normalize(-d), n, eta_t / eta_i, &d)) return 0;
    }
  }
  if (out) *out = Ray{mirror_z(o), mirror_z(d)};
  return weight;
}

float LensSystem::trace_from_scene(const Ray& r, Ray* out) const {
  Vec3 o = mirror_z(r.o), d = mirror_z(r.d);
  float z = -front_z();
  for (size_t i = 0; i < interfaces_.size(); ++i) {
    const LensInterface& e = interfaces_[i];
    float t;
    Vec3 n;
    if (!meet_interface(e, z, o, d, &t, &n)) return 0;
    const Vec3 p = o + d * t;
    if (p.x * p.x + p.y * p.y > e.aperture_radius * e.aperture_radius) return 0;
    o = p;
    if (!e.is_stop()) {
      const float eta_i = i > 0 ? index_of(interfaces_[i - 1].eta) : 1;
      if (!refract(normalize(-d), n, index_of(e.eta) / eta_i, &d)) return 0;
    }
    z += e.thickness;
  }
  if (out) *out = Ray{mirror_z(o), mirror_z(d)};
  return 1;
}

// pbrt-v4's FocusThickLens: the thick-lens approximation's cardinal points on both sides, from
// rays parallel to the axis at a thousandth of the film diagonal, and the move of the rear
// interface that images the plane at `distance` onto the film.
void LensSystem::focus(float distance) {
  const float x = 0.001f * film_diagonal_;
  float pz[2], fz[2];
  Ray scene_in{{x, 0, front_z() + 1}, {0, 0, -1}}, film_out;
  if (!trace_from_scene(scene_in, &film_out))
    throw Error(
        "no ray parallel to the lens's axis reaches the film (is its aperture stop closed?)");
  cardinal_points(scene_in, film_out, &pz[0], &fz[0]);
  Ray film_in{{x, 0, rear_z() - 1}, {0, 0, 1}}, scene_out;
  if (!trace_from_film(film_in, &scene_out))
    throw Error(
        "no ray parallel to the lens's axis leaves it toward the scene (is its aperture stop "
        "closed?)");
  cardinal_points(film_in, scene_out, &pz[1], &fz[1]);
  focal_length_ = fz[0] - pz[0];
  const float z = -distance;
  const float c = (pz[1] - z - pz[0]) * (pz[1] - z - 4 * focal_length_ - pz[0]);
  if (!(c > 0) || !(focal_length_ > 0))
    throw Error("the lens cannot focus at " + number(distance) +
                " m (too close for its focal length of " + number(focal_length_ * 1000) + " mm)");
  const float delta = (pz[1] - z + pz[0] - std::sqrt(c)) / 2;
  interfaces_.back().thickness += delta;
  if (!(interfaces_.back().thickness > 0))
    throw Error("focused at " + number(distance) + " m, the lens's rear would lie behind the film");
}

// The box on the rear interface's plane holding every point through which light from film
// points (x, 0) with x in [film_x0, film_x1] leaves the lens: the points of a lattice over the
// square `search` that pass, grown by two lattice spacings.
LensSystem::PupilBox LensSystem::bound_exit_pupil(float film_x0, float film_x1,
                                                  const PupilBox& search, int n) const {
  PupilBox box;
  bool found = false;
  for (int i = 0; i < n; ++i) {
    const float fx = film_x0 + (film_x1 - film_x0) * (float(i) + 0.5f) / float(n);
    // A rank-1 lattice (the plastic-number sequence).
    const double u = std::fmod(0.5 + i * 0.7548776662466927, 1.0),
                 v = std::fmod(0.5 + i * 0.5698402909980532, 1.0);
    const float px = float(search.x0 + (search.x1 - search.x0) * u),
                py = float(search.y0 + (search.y1 - search.y0) * v);
    const bool inside = found && px >= box.x0 && px <= box.x1 && py >= box.y0 && py <= box.y1;
    if (inside || !trace_from_film(Ray{{fx, 0, 0}, {px - fx, py, rear_z()}}, nullptr)) continue;
    if (!found) box = {px, py, px, py};
    found = true;
    box = {std::min(box.x0, px), std::min(box.y0, py), std::max(box.x1, px), std::max(box.y1, py)};
  }
  if (!found) return box;
  const float grow =
      2 * std::hypot(search.x1 - search.x0, search.y1 - search.y0) / std::sqrt(float(n));
  return {box.x0 - grow, box.y0 - grow, box.x1 + grow, box.y1 + grow};
}

// Over the rear interface's square first, then over the box found, to tighten it where the
// pupil is small against the rear interface (a stopped-down lens).
LensSystem::PupilBox LensSystem::bound_exit_pupil(float film_x0, float film_x1) const {
  const float r = 1.5f * interfaces_.back().aperture_radius;
  const PupilBox coarse = bound_exit_pupil(film_x0, film_x1, {-r, -r, r, r}, 1 << 16);
  if (coarse.empty()) return coarse;
  const PupilBox fine = bound_exit_pupil(film_x0, film_x1, coarse, 1 << 14);
  return fine.empty() ? coarse : fine;
}

CameraRay LensSystem::generate(Vec2 s, Vec2 u) const {
  const Vec3 film{-(-extent_x_ / 2 + s.x * extent_x_), -extent_y_ / 2 + s.y * extent_y_, 0};
  const Ray axis{{0, 0, front_z()}, {0, 0, 1}};
  const float r_film = std::sqrt(film.x * film.x + film.y * film.y);
  const int ring =
      std::min(int(pupil_.size()) - 1, int(r_film / (film_diagonal_ / 2) * float(pupil_.size())));
  const PupilBox& b = pupil_[size_t(ring)];
  if (b.empty()) return {axis, 0};
  const float lx = b.x0 + u.x * (b.x1 - b.x0), ly = b.y0 + u.y * (b.y1 - b.y0);
  const float area = (b.x1 - b.x0) * (b.y1 - b.y0);
  // The box holds the pupil of film points on +x: turn it to the film point's angle.
  const float sin_t = r_film != 0 ? film.y / r_film : 0, cos_t = r_film != 0 ? film.x / r_film : 1;
  const Vec3 pupil{cos_t * lx - sin_t * ly, sin_t * lx + cos_t * ly, rear_z()};
  const Ray from_film{film, pupil - film};
  Ray out;
  float weight = trace_from_film(from_film, &out);
  if (weight == 0) return {axis, 0};
  const float cos_theta = normalize(from_film.d).z;
  weight *= (cos_theta * cos_theta) * (cos_theta * cos_theta) * area / (rear_z() * rear_z());
  return {Ray{out.o, normalize(out.d)}, weight};
}

}  // namespace bpm
