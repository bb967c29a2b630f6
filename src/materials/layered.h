// pbrt-v4's coateddiffuse and coatedconductor as stochastic layered BSDFs (Guo, Hasan and Zhao
// 2018; pbrt-v4, 4th ed., section 14.3): the coating is a dielectric boundary, the base a
// Lambertian reflector or a conductor, and light may bounce between them up to max_depth times. f
// and pdf are unbiased (f) or consistent (pdf, used only for MIS) Monte Carlo estimates over such
// random walks; their random numbers are keyed by the directions, so a value does not depend on the
// thread or the order of calls.
#pragma once
#include <array>
#include <memory>
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
// bsdf_gathered_probability of a layered material.
float layered_gathered_probability(const Material& m, Vec3 wo, Vec3 wi, TransportMode mode);
std::optional<BsdfSample> layered_sample(const Material& m, Vec3 wo, float uc, Vec2 u,
                                         TransportMode mode, BsdfPart part);

// The walks under an isotropic coat over a Lambertian base, in expectation. Light that reaches a
// Lambertian base leaves it in directions that do not depend on where it came from, so the walks'
// f factors (with R the base's reflectance, per channel):
//   f_walks(wo, wi) = A(cos wo) R B(cos wi) (1 + R rho + ... + (R rho)^(N-1)),
// A: the share of light from wo that crosses the coat and the layer to the base; B: the same toward
// wi, counted as the stochastic walk counts it (next-event estimation through the coat and exits
// by base sampling, weighted by MIS); rho: the share of light leaving the base that the coat
// reflects back to it; N = (max_depth + 1) / 2 visits to the base within max_depth bounces. A, B
// and rho are integrals over the coat's own sampling, computed once per coat on a grid (about 0.2 s
// of CPU for a rough coat), so f is the stochastic walk's expectation (within about 1e-3) without
// its noise or its cost. The material is then a plain BSDF of two lobes, the coat's reflection and
// the walks' table, sampled as a mixture: the walks with probability enter(cos wo) (their share of
// the coat's own draws), cosine-distributed, else the coat's reflection; layered_pdf is that
// mixture's density, exactly.
struct CoatWalkTable {
  static constexpr int kNodes = 64;  // node j at cos = (j / (kNodes - 1))^2: dense near grazing
  CoatLayer layer;                   // the coat it was made for
  std::array<float, kNodes> a, b;   // radiance transport's (reflection: importance's f is the same)
  std::array<float, kNodes> enter;  // the probability that the coat's draw goes into the layer
  float rho = 0;
  int visits = 0;
  bool made_for(const CoatLayer& l) const {
    return l.eta == layer.eta && l.thickness == layer.thickness && l.max_depth == layer.max_depth &&
           l.roughness.alpha_x == layer.roughness.alpha_x &&
           l.roughness.alpha_y == layer.roughness.alpha_y;
  }
  Spectrum f(const Spectrum& reflectance, float cos_o, float cos_i) const;
};
// Null for an anisotropic coat (its walks depend on the azimuths too).
std::shared_ptr<const CoatWalkTable> make_coat_walk_table(const CoatLayer& layer);

template <class T>
constexpr bool kLayered =
    std::is_same_v<T, CoatedDiffuseMaterial> || std::is_same_v<T, CoatedConductorMaterial>;

}  // namespace bpm
