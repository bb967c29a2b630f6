// One photon's share of the radiance reflected at a gathering point (eq. 2 before the division by
// pi r^2 and by the number of photons): f(wo, wi) evaluated in the point's shading frame, in
// radiance mode, times the photon's flux, times |wi.ns| / |wi.ng_photon|: the photon's flux is per
// area of the surface it hit, so it stands for incident radiance times |wi.ng_photon|, while the
// BSDF wants it times the shading cosine |wi.ns|. ng_photon is the geometric normal where the
// photon hit, not the gathering point's: the photons of a disc on a curved or faceted surface lie
// on other facets, and a photon that grazes the point's own plane but not its facet (|wi.ng_point|
// near 0) would otherwise weigh without bound. Photons arrive in proportion to |wi.ng_photon|, so
// the factor's mean is finite. Only the gathered lobes count (BsdfPart): the eye paths go on
// through the traced ones.
#pragma once
#include <cmath>

#include "materials/material.h"
#include "photons/settings.h"

namespace bpm {

// One gathering's photon contributions summed over three nested discs: radius r, r / sqrt 2 (half
// its area) and r / 2 (a quarter).
struct NestedSums {
  Spectrum all, half, quarter;
  void add(const Spectrum& value, float d2, float r2) {
    all += value;
    if (2 * d2 < r2) half += value;
    if (4 * d2 < r2) quarter += value;
  }
};

// The bias of L(r) = all * norm from the estimates at the three radii (norm = 1 / (pi r^2 N)).
// With s = 1 / sqrt 2, D1 = L(r) - L(s r) and D2 = L(s r) - L(s^2 r): for a bias a r^2, D1 is half
// of it; for a r^2 + b r, solving the two differences gives -sqrt 2 D1 + (4 + 2 sqrt 2) D2 (2 D1
// when D2 = D1 / 2, as r^2 alone gives; (2 + sqrt 2) D1 when D2 = s D1, as r alone gives). A linear
// combination of unbiased estimates, so its mean over passes is as well.
inline Spectrum radius_bias(const NestedSums& s, float norm, BiasModel model) {
  const Spectrum L = s.all * norm, L_half = s.half * (2 * norm);
  if (model == BiasModel::kSquare) return (L - L_half) * 2.0f;
  const Spectrum L_quarter = s.quarter * (4 * norm);
  constexpr float kSqrt2 = 1.41421356f;
  return (L - L_half) * -kSqrt2 + (L_half - L_quarter) * (4 + 2 * kSqrt2);
}

inline Spectrum photon_contribution(const Material& m, Vec3 ng_photon, Vec3 ns, Vec3 wo, Vec3 wi,
                                    const Spectrum& flux) {
  // The common case without a frame or a call: Lambertian, f = R / pi with wo and wi on the same
  // side of the shading surface (the frame's z is ns, so these are its local z components).
  if (const auto* d = std::get_if<DiffuseMaterial>(&m)) {
    const float cos_o = dot(wo, ns), cos_i = dot(wi, ns), cos_g = std::fabs(dot(wi, ng_photon));
    if (!(cos_o * cos_i > 0) || cos_g == 0) return {};
    return flux * d->reflectance * (kInvPi * std::fabs(cos_i) / cos_g);
  }
  Frame frame = Frame::from_z(ns);
  Vec3 wo_local = frame.to_local(wo), wi_local = frame.to_local(wi);
  Spectrum f = bsdf_f(m, wo_local, wi_local, TransportMode::kRadiance, BsdfPart::kGathered);
  if (f.is_black()) return {};
  float cos_g = std::fabs(dot(wi, ng_photon));
  if (cos_g == 0) return {};
  return flux * f * (std::fabs(wi_local.z) / cos_g);
}

}  // namespace bpm
