#include "photons/density.h"

#include <gtest/gtest.h>

#include "base/rng.h"
#include "base/sampling.h"

namespace bpm {
namespace {

// The general form of photon_contribution, through the BSDF in the shading frame.
Spectrum through_frame(const Material& m, Vec3 ng, Vec3 ns, Vec3 wo, Vec3 wi,
                       const Spectrum& flux) {
  Frame frame = Frame::from_z(ns);
  Spectrum f = bsdf_f(m, frame.to_local(wo), frame.to_local(wi), TransportMode::kRadiance);
  float cos_g = std::fabs(dot(wi, ng));
  if (f.is_black() || cos_g == 0) return {};
  return flux * f * (std::fabs(dot(wi, ns)) / cos_g);
}

// The Lambertian shortcut gives what the BSDF gives, for shading normals tilted from the geometric
// one and directions on both sides (zero where wo and wi are on opposite sides of ns).
TEST(PhotonContribution, LambertianShortcutEqualsTheBsdf) {
  DiffuseMaterial d;
  for (int c = 0; c < Spectrum::kChannels; ++c) d.reflectance[c] = 0.1f + 0.1f * float(c);
  const Material m = d;
  Rng rng(5);
  Spectrum flux(2.5f);
  int nonzero = 0;
  for (int k = 0; k < 2000; ++k) {
    Vec3 ng = sample_uniform_sphere({rng.uniform(), rng.uniform()});
    Vec3 ns = normalize(ng + 0.4f * sample_uniform_sphere({rng.uniform(), rng.uniform()}));
    Vec3 wo = sample_uniform_sphere({rng.uniform(), rng.uniform()});
    Vec3 wi = sample_uniform_sphere({rng.uniform(), rng.uniform()});
    Spectrum a = photon_contribution(m, ng, ns, wo, wi, flux),
             b = through_frame(m, ng, ns, wo, wi, flux);
    for (int c = 0; c < Spectrum::kChannels; ++c)
      ASSERT_NEAR(a[c], b[c], 1e-4f * std::fabs(b[c]) + 1e-6f) << "sample " << k;
    nonzero += !a.is_black();
  }
  EXPECT_GT(nonzero, 500);
}

}  // namespace
}  // namespace bpm
