// pbrt-v4's coateddiffuse as a stochastic layered BSDF (Guo, Hasan and Zhao 2018; pbrt-v4, 4th
// ed., section 14.3): the coating is a dielectric boundary, the base a Lambertian reflector, and
// light may bounce between them up to max_depth times. f and pdf are unbiased (f) or consistent
// (pdf, used only for MIS) Monte Carlo estimates over such random walks; their random numbers are
// keyed by the directions, so a value does not depend on the thread or the order of calls.
#pragma once
#include <optional>

#include "materials/material.h"

namespace bpm {

Spectrum coated_diffuse_f(const CoatedDiffuseMaterial& m, Vec3 wo, Vec3 wi, TransportMode mode);
float coated_diffuse_pdf(const CoatedDiffuseMaterial& m, Vec3 wo, Vec3 wi, TransportMode mode);
std::optional<BsdfSample> coated_diffuse_sample(const CoatedDiffuseMaterial& m, Vec3 wo, float uc, Vec2 u,
                                                TransportMode mode);

}  // namespace bpm
