// The dielectric boundary's lobes, one at a time: what a layered material needs from its coating
// (pbrt-v4's DielectricBxDF with BxDFReflTransFlags). `lobes` is kReflection, kTransmission or
// both.
#pragma once
#include <optional>

#include "materials/material.h"

namespace bpm {

Spectrum dielectric_f(const DielectricMaterial& m, Vec3 wo, Vec3 wi, TransportMode mode);
float dielectric_pdf(const DielectricMaterial& m, Vec3 wo, Vec3 wi, unsigned lobes);
std::optional<BsdfSample> dielectric_sample(const DielectricMaterial& m, Vec3 wo, float uc, Vec2 u,
                                            TransportMode mode, unsigned lobes);

}  // namespace bpm
