#include "photons/merge_weights.h"

#include <cmath>
#include <variant>

namespace bpm {

bool combinable_vertex(const PathVertex& v) {
  if (v.medium >= 0) return true;
  if (v.on_curve || !v.material) return false;
  const Material& m = v.m();
  if (bsdf_all_traced(m))
    return std::holds_alternative<ConductorMaterial>(m) ||
           std::holds_alternative<DielectricMaterial>(m) ||
           std::holds_alternative<ThinDielectricMaterial>(m);
  return !std::holds_alternative<PhongMaterial>(m);
}

double combined_density(const PathVertex& v, Vec3 from, Vec3 to, TransportMode mode,
                        float delta_probability) {
  if (delta_probability > 0) return delta_probability;
  const Material& m = v.m();
  const double g = bsdf_all_traced(m) ? 1.0 : double(bsdf_gathered_probability(m, from, to, mode));
  if (!(g > 0)) return 0;
  return g * double(bsdf_pdf(m, from, to, mode));
}

namespace {
// The area of the disc through which photons from a light at infinity enter (infinite_lights.cpp).
double entry_disc_area(const RenderScene& scene) {
  const double r = double(scene.bounds_info.radius);
  return kPi * r * r;
}
}  // namespace

double emission_density(const RenderScene& scene, int light, Vec3 y, Vec3 n, Vec3 w,
                        const DensityEnd& at) {
  const Light& l = scene.lights[size_t(light)];
  const double pmf = double(scene.light_distribution.pmf(light));
  if (light_is_infinite(l)) {
    // A point of the entry disc (uniform, perpendicular to w) and w itself: the disc's area density
    // is |cos| (or sigma in a medium) there over its area; w's density is a delta for a distant
    // light (left out, as in light_sample_density), the environment's own sampling's otherwise.
    const double dir =
        light_is_delta(l) ? 1.0 : double(light_pdf_li(l, nullptr, at.p, -w, y, Vec3()));
    return pmf * dir * at.factor(w, 1) / entry_disc_area(scene);
  }
  double a = 0;  // A0 times A1's solid-angle density at y
  if (const auto pdf = point_light_pdf_le(l, w)) {
    // A point-like light: its direction's density alone (its position's delta left out).
    a = pmf * double(*pdf);
  } else if (const auto* area = std::get_if<AreaLight>(&l); area && area->area > 0) {
    // Cosine-weighted about the normal (sample_le_of); a two-sided light picks its side first.
    const double side = area->two_sided ? 0.5 : 1.0;
    a = pmf / double(area->area) * side * std::fabs(double(dot(n, w))) * kInvPi;
  }
  return area_density(a, y, at);
}

double light_end_density(const Light& l, double pdf_solid_angle, Vec3 p, Vec3 y, Vec3 n) {
  if (light_is_delta(l)) return 0;
  if (light_is_infinite(l)) return pdf_solid_angle;
  return area_density(pdf_solid_angle, p, DensityEnd{y, n});
}

double light_sample_density(const RenderScene& scene, int light, Vec3 p, Vec3 y, Vec3 n) {
  const Light& l = scene.lights[size_t(light)];
  const double pmf = double(scene.light_distribution.pmf(light));
  // A point-like or distant light: its delta left out, as emission_density leaves out its own.
  if (light_is_delta(l)) return pmf;
  const Vec3 d = y - p;
  const float len = length(d);
  if (!(len > 0)) return 0;
  return light_end_density(l, pmf * double(light_pdf_li(l, scene.light_shape(l), p, d / len, y, n)),
                           p, y, n);
}

void PhotonMis::start(const RenderScene& scene, int light, Vec3 y, Vec3 n, Vec3 w) {
  const Light& l = scene.lights[size_t(light)];
  on_ = true;
  light_ = light;
  y_ = y;
  n_y_ = n;
  prev_ = {y, n};
  w_ = w;
  at_infinity_ = light_is_infinite(l);
  delta_ = light_is_delta(l);
}

void PhotonMis::arrive(const RenderScene& scene, const PathVertex& v, int k, float pass,
                       const Wavelengths& wl) {
  if (!on_) return;
  here_ = density_end(scene, v, wl);
  const Vec3 d = v.sp.p - prev_.p;
  const double d2 = double(length_squared(d));
  if (!(d2 > 0)) {
    on_ = false;
    return;
  }
  const double len = std::sqrt(d2);
  const double to_area = here_.factor(d, len) / d2;
  k_ = k;
  if (k == 1) {
    // A0 A1 as an area density here; B0 from here.
    r_ = 1 / emission_density(scene, light_, y_, n_y_, w_, here_);
    // No next-event estimation at a vertex whose lobes are all traced. Its shadow ray gets
    // across the media for certain (its transmittance is a weight), where the photon and the
    // BSDF sample get across with the probability `pass`, which both count (and which the
    // products leave out, as every later segment's, where it would cancel).
    b0_ = v.material && bsdf_all_traced(v.m())
              ? 0.0
              : light_sample_density(scene, light_, v.sp.p, y_, n_y_) / double(pass);
    arrival_ = 0;
  } else {
    // The area part of A_k; no vertex connection joins a traced vertex to this one.
    r_ /= to_area;
    // It counts the way's pass probability, which the connection's shadow ray does not share.
    arrival_ = last_traced_ || prev_.sigma > 0 ? 0.0 : a_ * to_area * double(pass);
  }
  // The segment's factor for B_(k-1): the eye's solid-angle density at v toward the vertex before,
  // turned into that vertex's measure (a light at infinity: the direction itself; none for a
  // delta light, which no BSDF sample finds).
  if (k == 1 && at_infinity_) {
    seg_cos_ = delta_ ? 0.0 : 1.0;
    seg_d2_ = 1;
  } else {
    seg_cos_ = prev_.factor(d, len);
    seg_d2_ = d2;
  }
  if (!combinable_vertex(v) || !std::isfinite(r_) || !std::isfinite(b0_)) on_ = false;
}

void PhotonMis::scatter(const PathVertex& v, const BsdfSample& bs, Vec3 wi, int k) {
  if (!on_) return;
  const bool all_traced = bsdf_all_traced(v.m());
  if (bs.is_traced() && !all_traced) {  // through a split coat's traced part: the photon's alone
    on_ = false;
    return;
  }
  const Vec3 wi_local = v.frame.to_local(wi);
  const float delta = delta_choice_probability(bs);
  // A_(k+1)'s solid-angle density: the adjoint BSDF's at v, from where the photon came, through
  // the gathered part (where a coat splits, its share of the density).
  const double a = combined_density(v, v.wo_local, wi_local, TransportMode::kImportance, delta);
  // B_(k-1): the eye's BSDF at v, arriving from wi, toward the vertex before (y0 when k = 1,
  // where next-event estimation's density joins it).
  double b = (delta > 0 ? delta : bsdf_pdf(v.m(), wi_local, v.wo_local, TransportMode::kRadiance)) *
             seg_cos_ / seg_d2_;
  if (k == 1) b += b0_;
  last_traced_ = all_traced;
  gathered_ = gathered_ || !all_traced;
  if (!(a > 0)) {
    on_ = false;
    return;
  }
  r_ *= b / a;
  a_ = a;
  prev_ = here_;
}

void PhotonMis::scatter_in_medium(float phase, int k) {
  if (!on_) return;
  // A_(k+1) is the phase function's density; B_(k-1) the same (Henyey-Greenstein depends on the
  // angle alone), toward the vertex before, joined by next-event estimation's where k = 1.
  double b = double(phase) * seg_cos_ / seg_d2_;
  if (k == 1) b += b0_;
  last_traced_ = false;
  gathered_ = true;
  if (!(phase > 0)) {
    on_ = false;
    return;
  }
  r_ *= b / double(phase);
  a_ = phase;
  prev_ = here_;
}

}  // namespace bpm
