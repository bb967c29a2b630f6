// pbrt-v4's coateddiffuse and coatedconductor as stochastic layered BSDFs (Guo, Hasan and Zhao
// 2018; pbrt-v4, 4th ed., section 14.3): the coating is a dielectric boundary, the base a
// Lambertian reflector or a conductor, and light may bounce between them up to max_depth times. f
// and pdf are unbiased (f) or consistent (pdf, used only for MIS) Monte Carlo estimates over such
// random walks; their random numbers are keyed by the directions, so a value does not depend on the
// thread or the order of calls.
#pragma once
#include <optional>
#include <type_traits>

#include "materials/material.h"

namespace bpm {

// m holds a CoatedDiffuseMaterial or a CoatedConductorMaterial (is_layered). The traced part
// (BsdfPart) is the coating's own reflection when the coating is traced; the gathered part is the
// rest (the walks under it). Asked for a part the material does not split into, they answer for
// the whole material.
Spectrum layered_f(const Material& m, Vec3 wo, Vec3 wi, TransportMode mode, BsdfPart part);
float layered_pdf(const Material& m, Vec3 wo, Vec3 wi, TransportMode mode, BsdfPart part);
std::optional<BsdfSample> layered_sample(const Material& m, Vec3 wo, float uc, Vec2 u,
                                         TransportMode mode, BsdfPart part);

template <class T>
constexpr bool kLayered =
    std::is_same_v<T, CoatedDiffuseMaterial> || std::is_same_v<T, CoatedConductorMaterial>;

}  // namespace bpm
