// One photon's share of the radiance reflected at a gathering point (eq. 2 before the division by
// pi r^2 and by the number of photons): f(wo, wi) evaluated in the point's shading frame, in
// radiance mode, times the photon's flux, times |wi.ns| / |wi.ng| because the density estimate
// gives irradiance on the geometric surface while the BSDF wants it on the shading one. Only the
// gathered lobes count (BsdfPart): the eye paths go on through the traced ones.
#pragma once
#include <cmath>

#include "materials/material.h"

namespace bpm {

inline Spectrum photon_contribution(const Material& m, Vec3 ng, Vec3 ns, Vec3 wo, Vec3 wi,
                                    const Spectrum& flux) {
  // The common case without a frame or a call: Lambertian, f = R / pi with wo and wi on the same
  // side of the shading surface (the frame's z is ns, so these are its local z components).
  if (const auto* d = std::get_if<DiffuseMaterial>(&m)) {
    const float cos_o = dot(wo, ns), cos_i = dot(wi, ns), cos_g = std::fabs(dot(wi, ng));
    if (!(cos_o * cos_i > 0) || cos_g == 0) return {};
    return flux * d->reflectance * (kInvPi * std::fabs(cos_i) / cos_g);
  }
  Frame frame = Frame::from_z(ns);
  Vec3 wo_local = frame.to_local(wo), wi_local = frame.to_local(wi);
  Spectrum f = bsdf_f(m, wo_local, wi_local, TransportMode::kRadiance, BsdfPart::kGathered);
  if (f.is_black()) return {};
  float cos_g = std::fabs(dot(wi, ng));
  if (cos_g == 0) return {};
  return flux * f * (std::fabs(wi_local.z) / cos_g);
}

}  // namespace bpm
