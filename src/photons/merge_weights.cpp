#include "photons/merge_weights.h"

#include <cmath>
#include <variant>

namespace bpm {

bool combinable_vertex(const PathVertex& v) {
  return v.medium < 0 && !v.on_curve && v.material && !bsdf_all_traced(v.m()) &&
         !std::holds_alternative<PhongMaterial>(v.m());
}

bool combinable_light(const Light& l) {
  return std::holds_alternative<AreaLight>(l) ||
         (light_is_delta(l) && !std::holds_alternative<DistantLight>(l));
}

double emission_density(const RenderScene& scene, int light, Vec3 n, Vec3 w) {
  const Light& l = scene.lights[size_t(light)];
  const double pmf = double(scene.light_distribution.pmf(light));
  // A point-like light: its direction's density alone (its position's delta left out).
  if (const auto pdf = point_light_pdf_le(l, w)) return pmf * double(*pdf);
  const auto* area = std::get_if<AreaLight>(&l);
  if (!area || !(area->area > 0)) return 0;
  // Cosine-weighted about the normal (sample_le_of); a two-sided light picks its side first.
  const double side = area->two_sided ? 0.5 : 1.0;
  return pmf / double(area->area) * side * std::fabs(double(dot(n, w))) * kInvPi;
}

double light_sample_density(const RenderScene& scene, int light, Vec3 p, Vec3 y, Vec3 n) {
  const Light& l = scene.lights[size_t(light)];
  const double pmf = double(scene.light_distribution.pmf(light));
  if (!combinable_light(l)) return 0;
  // A point-like light: its delta left out, as emission_density leaves out its own.
  if (!std::holds_alternative<AreaLight>(l)) return pmf;
  const Vec3 d = y - p;
  const float len = length(d);
  if (!(len > 0)) return 0;
  return area_density(pmf * double(light_pdf_li(l, scene.light_shape(l), p, d / len, y, n)), p, y,
                      n);
}

void PhotonMis::start(const RenderScene& scene, int light, Vec3 y, Vec3 n, Vec3 w) {
  const double e = emission_density(scene, light, n, w);
  on_ = e > 0;
  if (!on_) return;
  r_ = 1 / e;
  light_ = light;
  y_ = prev_ = y;
  n_y_ = prev_n_ = n;
}

void PhotonMis::arrive(const RenderScene& scene, const PathVertex& v, int k) {
  if (!on_) return;
  const Vec3 d = v.sp.p - prev_;
  const double d2 = double(length_squared(d));
  if (!(d2 > 0)) {
    on_ = false;
    return;
  }
  const double len = std::sqrt(d2);
  // The area part of A_k, and the segment's cosine at its start for B_(k-1).
  r_ /= std::fabs(double(dot(v.sp.ng, d))) / (len * d2);
  seg_cos_ = std::fabs(double(dot(prev_n_, d))) / len;
  seg_d2_ = d2;
  k_ = k;
  arrival_ = k == 1 ? 0.0 : a_ * std::fabs(double(dot(v.sp.ng, d))) / (len * d2);
  if (k == 1) b0_ = light_sample_density(scene, light_, v.sp.p, y_, n_y_);
  if (!combinable_vertex(v) || !std::isfinite(r_)) on_ = false;
}

void PhotonMis::scatter(const PathVertex& v, Vec3 wi, bool traced, int k) {
  if (!on_) return;
  if (traced) {  // drawn through a traced lobe: the photon's alone
    on_ = false;
    return;
  }
  const Vec3 wi_local = v.frame.to_local(wi);
  // A_(k+1)'s solid-angle density: the adjoint BSDF's at v, from where the photon came, through
  // the gathered part (where a coat splits, its share of the density).
  const double g =
      bsdf_gathered_probability(v.m(), v.wo_local, wi_local, TransportMode::kImportance);
  const double a = g * bsdf_pdf(v.m(), v.wo_local, wi_local, TransportMode::kImportance);
  // B_(k-1): the eye's BSDF at v, arriving from wi, toward the vertex before (y0 when k = 1,
  // where next-event estimation's density joins it).
  double b =
      double(bsdf_pdf(v.m(), wi_local, v.wo_local, TransportMode::kRadiance)) * seg_cos_ / seg_d2_;
  if (k == 1) b += b0_;
  if (!(a > 0)) {
    on_ = false;
    return;
  }
  r_ *= b / a;
  a_ = a;
  prev_ = v.sp.p;
  prev_n_ = v.sp.ng;
}

}  // namespace bpm
