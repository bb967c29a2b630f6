// Tests of the stochastic coated-diffuse BSDF. Its f and pdf are estimates, so the deterministic
// checks of bsdf_test.cpp do not apply; instead:
// - energy: a white base under a clear coating loses nothing, so every incident direction's albedo
//   is 1 (sampled weights) and so is the integral of f cos (evaluation);
// - sampling agrees with evaluation: the sampled weights binned by direction equal the integral
//   of f cos over each bin (the histogram test of a sampler whose density is not known);
// - reciprocity in expectation, and the two transport modes agree on reflection;
// - the coated diffuse's walk table (its f without the walk's noise) is the walk's expectation.
#include "materials/layered.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "base/chi2_test_util.h"
#include "base/rng.h"
#include "base/sampling.h"
#include "materials/dielectric.h"
#include "materials/material.h"

namespace bpm {
namespace {

CoatedDiffuseMaterial coated(float reflectance, float alpha, float thickness = 0.01f) {
  CoatedDiffuseMaterial m;
  m.reflectance = Spectrum(reflectance);
  m.layer.roughness = Roughness{alpha, alpha};
  m.layer.thickness = thickness;
  return m;
}

Vec3 direction(float cos_theta, float phi) {
  float s = std::sqrt(std::fmax(0.0f, 1 - cos_theta * cos_theta));
  return {s * std::cos(phi), s * std::sin(phi), cos_theta};
}

// Mean of f cos / pdf over bsdf_sample (the albedo), with its standard error.
MeanAccumulator sampled_albedo(const Material& m, Vec3 wo, int n, uint64_t seed) {
  MeanAccumulator a;
  Rng rng(seed);
  for (int i = 0; i < n; ++i) {
    auto s =
        bsdf_sample(m, wo, rng.uniform(), {rng.uniform(), rng.uniform()}, TransportMode::kRadiance);
    a.add(s ? double(s->f[0]) * std::fabs(s->wi.z) / s->pdf_solid_angle : 0.0);
  }
  return a;
}

// Integral of f cos over the sphere by uniform directions.
MeanAccumulator evaluated_albedo(const Material& m, Vec3 wo, int n, uint64_t seed) {
  MeanAccumulator a;
  Rng rng(seed);
  for (int i = 0; i < n; ++i) {
    Vec3 wi = sample_uniform_sphere({rng.uniform(), rng.uniform()});
    a.add(double(bsdf_f(m, wo, wi, TransportMode::kRadiance)[0]) * std::fabs(wi.z) /
          kUniformSpherePdfSolidAngle);
  }
  return a;
}

TEST(CoatedDiffuse, WhiteBaseUnderSmoothCoatingConservesEnergy) {
  // Thin layer (no attenuation), many bounces allowed, a smooth boundary (which loses nothing):
  // all light comes back out.
  CoatedDiffuseMaterial c = coated(1.0f, 0.0f, 1e-6f);
  c.layer.max_depth = 200;
  const auto table = make_coat_walk_table(c.layer);
  for (bool with_table : {false, true}) {
    c.walk_table = with_table ? table.get() : nullptr;
    Material m = c;
    for (float cos_o : {0.9f, 0.4f, -0.7f}) {
      MeanAccumulator s = sampled_albedo(m, direction(cos_o, 0.7f), 100000, 3);
      EXPECT_NEAR(s.mean, 1.0, kMeanTestSigmas * s.standard_error() + 2e-3)
          << "cos " << cos_o << (with_table ? " table" : "");
    }
  }
}

// A rough coating loses energy (single-scattering microfacets, many internal reflections), but the
// albedo from sampling equals the integral of the evaluated f: the two estimators agree. (pbrt-v4's
// f weighs one of its two connections with a density over the wrong variable and runs several per
// cent above its own sampling on rough coatings; bpm uses the competing strategy's density.)
TEST(CoatedDiffuse, RoughCoatingSampledAndEvaluatedAlbedosAgree) {
  CoatedDiffuseMaterial c = coated(1.0f, 0.3f, 1e-6f);
  c.layer.max_depth = 200;
  Material m = c;
  for (float cos_o : {0.9f, 0.4f, -0.7f}) {
    Vec3 wo = direction(cos_o, 0.7f);
    MeanAccumulator s = sampled_albedo(m, wo, 100000, 3), e = evaluated_albedo(m, wo, 100000, 4);
    double se = std::sqrt(s.standard_error() * s.standard_error() +
                          e.standard_error() * e.standard_error());
    EXPECT_NEAR(s.mean, e.mean, 4.5 * se) << "cos " << cos_o;
    EXPECT_LT(s.mean, 0.95);
    EXPECT_GT(s.mean, 0.5);
    // The walk table's sampling gives the stochastic walk's albedo (the table's error allowed).
    auto table = make_coat_walk_table(c.layer);
    CoatedDiffuseMaterial tabled = c;
    tabled.walk_table = table.get();
    MeanAccumulator t = sampled_albedo(tabled, wo, 100000, 5);
    double se_t = std::sqrt(s.standard_error() * s.standard_error() +
                            t.standard_error() * t.standard_error());
    EXPECT_NEAR(t.mean, s.mean, 4.5 * se_t + 2e-3 * s.mean) << "cos " << cos_o << " table";
  }
}

// A scattering layer (pbrt-v4's albedo and g): a white, non-absorbing medium over a white base
// under a smooth coat loses nothing, whatever the phase function; with a rough coat the albedo
// from sampling equals the integral of the evaluated f (the phase function's next-event and
// sampled exits weighed against each other); an absorbing medium reflects less than a clear layer.
TEST(CoatedDiffuse, ScatteringLayerConservesEnergyAndAgreesWithItsSampling) {
  for (float g : {0.0f, 0.6f, -0.5f}) {
    CoatedDiffuseMaterial c = coated(1.0f, 0.0f, 0.5f);
    c.layer.max_depth = 400;
    c.layer.albedo = Spectrum(1.0f);
    c.layer.g = g;
    MeanAccumulator s = sampled_albedo(c, direction(0.7f, 0.3f), 60000, 8);
    EXPECT_NEAR(s.mean, 1.0, kMeanTestSigmas * s.standard_error() + 3e-3) << "g " << g;
  }
  CoatedDiffuseMaterial c = coated(0.6f, 0.3f, 0.4f);
  c.layer.max_depth = 100;
  c.layer.albedo = Spectrum(0.8f);
  c.layer.g = 0.4f;
  for (float cos_o : {0.9f, 0.35f}) {
    const Vec3 wo = direction(cos_o, 0.7f);
    MeanAccumulator s = sampled_albedo(c, wo, 100000, 3), e = evaluated_albedo(c, wo, 100000, 4);
    const double se = std::sqrt(s.standard_error() * s.standard_error() +
                                e.standard_error() * e.standard_error());
    EXPECT_NEAR(s.mean, e.mean, 4.5 * se) << "cos " << cos_o;
    CoatedDiffuseMaterial dark = c;
    dark.layer.albedo = Spectrum(0.1f);
    MeanAccumulator d = sampled_albedo(dark, wo, 50000, 5);
    EXPECT_LT(d.mean, s.mean - 5 * (d.standard_error() + s.standard_error())) << "cos " << cos_o;
  }
}

TEST(CoatedDiffuse, AbsorbingBaseAndLayerReflectLess) {
  Vec3 wo = direction(0.8f, 0.2f);
  MeanAccumulator grey = sampled_albedo(coated(0.5f, 0.2f), wo, 50000, 5);
  MeanAccumulator white = sampled_albedo(coated(1.0f, 0.2f), wo, 50000, 5);
  MeanAccumulator thick = sampled_albedo(coated(1.0f, 0.2f, 0.5f), wo, 50000, 5);
  EXPECT_LT(grey.mean, white.mean - 5 * (grey.standard_error() + white.standard_error()));
  EXPECT_LT(thick.mean, white.mean - 5 * (thick.standard_error() + white.standard_error()));
  // The coating alone reflects its Fresnel share: at least that much always comes back.
  EXPECT_GT(grey.mean, fresnel_dielectric(0.8f, 1.5f));
}

// Direction bins over the sphere: kBinsCos in |cos theta| by kBinsPhi in azimuth, per hemisphere.
constexpr int kBinsCos = 6, kBinsPhi = 8, kBins = 2 * kBinsCos * kBinsPhi;
int direction_bin(Vec3 w) {
  int i = std::min(kBinsCos - 1, int(std::fabs(w.z) * kBinsCos));
  float phi = std::atan2(w.y, w.x) + kPi;
  int j = std::min(kBinsPhi - 1, int(phi / (2 * kPi) * kBinsPhi));
  return (w.z < 0 ? kBinsCos * kBinsPhi : 0) + i * kBinsPhi + j;
}

// The random walk that samples directions and the estimator of f describe the same BSDF: per
// direction bin, E[weight * 1(bin)] = integral over the bin of f cos.
void expect_sampling_matches_evaluation(const Material& m, Vec3 wo) {
  const int n = 300000;
  std::vector<MeanAccumulator> sampled(kBins), evaluated(kBins);
  Rng rng(9);
  for (int k = 0; k < n; ++k) {
    auto s =
        bsdf_sample(m, wo, rng.uniform(), {rng.uniform(), rng.uniform()}, TransportMode::kRadiance);
    // Delta lobes (a smooth coat's mirror reflection) are not in f: leave them out.
    int b = s && !s->is_specular() ? direction_bin(s->wi) : -1;
    for (int c = 0; c < int(sampled.size()); ++c)
      sampled[c].add(c == b ? double(s->f[0]) * std::fabs(s->wi.z) / s->pdf_solid_angle : 0.0);
    // Uniform over the sphere: z uniform, so the cos bins have equal measure.
    Vec3 wi = sample_uniform_sphere({rng.uniform(), rng.uniform()});
    double v = double(bsdf_f(m, wo, wi, TransportMode::kRadiance)[0]) * std::fabs(wi.z) /
               kUniformSpherePdfSolidAngle;
    int bw = direction_bin(wi);
    for (int c = 0; c < int(evaluated.size()); ++c) evaluated[c].add(c == bw ? v : 0.0);
  }
  // 96 bins at 4.5 sigma: a correct BSDF fails with probability about 1e-3.
  for (int c = 0; c < int(sampled.size()); ++c) {
    double se = std::sqrt(sampled[c].standard_error() * sampled[c].standard_error() +
                          evaluated[c].standard_error() * evaluated[c].standard_error());
    EXPECT_NEAR(sampled[c].mean, evaluated[c].mean, 4.5 * se + 1e-5) << "bin " << c;
  }
}

TEST(CoatedDiffuse, SampledWeightsMatchEvaluatedBsdfPerBin) {
  expect_sampling_matches_evaluation(coated(0.7f, 0.25f), direction(0.6f, 1.1f));
  // The same with the walk table: its mixture's weights against its f (the walks' share of the
  // draws, enter, and the coat's reflection drawn with the rest).
  CoatedDiffuseMaterial c = coated(0.7f, 0.25f);
  auto table = make_coat_walk_table(c.layer);
  ASSERT_TRUE(table);
  c.walk_table = table.get();
  expect_sampling_matches_evaluation(c, direction(0.6f, 1.1f));
}

// With the walk table the density is exact: per direction bin (96, at 4.5 sigma) and over the
// hemisphere, the share of samples that land there equals the integral of bsdf_pdf (both Monte
// Carlo), for the whole material and for each part.
TEST(CoatedDiffuse, WalkTablePdfIsTheSamplingDensity) {
  CoatedDiffuseMaterial c = coated(0.7f, 0.05f);
  auto table = make_coat_walk_table(c.layer);
  ASSERT_TRUE(table);
  c.walk_table = table.get();
  const Vec3 wo = direction(0.6f, 1.1f);
  const int n = 200000;
  for (BsdfPart part : {BsdfPart::kAll, BsdfPart::kGathered, BsdfPart::kTraced}) {
    std::vector<MeanAccumulator> sampled(kBins), integrated(kBins);
    MeanAccumulator sampled_all, integrated_all;  // all bins: the probability of a sample
    Rng rng(17);
    for (int k = 0; k < n; ++k) {
      auto s = bsdf_sample(c, wo, rng.uniform(), {rng.uniform(), rng.uniform()},
                           TransportMode::kRadiance, part);
      int b = s ? direction_bin(s->wi) : -1;
      // Cosine-distributed directions: the walks' lobe is then integrated with little noise.
      Vec3 wi = sample_cosine_hemisphere({rng.uniform(), rng.uniform()});
      double p = bsdf_pdf(c, wo, wi, TransportMode::kRadiance, part) /
                 cosine_hemisphere_pdf_solid_angle(wi.z);
      int bw = direction_bin(wi);
      for (int i = 0; i < int(sampled.size()); ++i) {
        sampled[i].add(i == b ? 1.0 : 0.0);
        integrated[i].add(i == bw ? p : 0.0);
      }
      sampled_all.add(b >= 0 ? 1.0 : 0.0);
      integrated_all.add(p);
    }
    EXPECT_NEAR(sampled_all.mean, integrated_all.mean,
                4.5 * std::hypot(sampled_all.standard_error(), integrated_all.standard_error()))
        << "part " << int(part);
    for (int i = 0; i < int(sampled.size()); ++i) {
      double se = std::sqrt(sampled[i].standard_error() * sampled[i].standard_error() +
                            integrated[i].standard_error() * integrated[i].standard_error());
      EXPECT_NEAR(sampled[i].mean, integrated[i].mean, 4.5 * se + 1e-5)
          << "part " << int(part) << " bin " << i;
    }
  }
}

// The walks' part of f (the coat's own reflection taken out), by the walk's estimator or the table.
Spectrum walks_f(const CoatedDiffuseMaterial& c, Vec3 wo, Vec3 wi, TransportMode mode) {
  const DielectricMaterial top{c.layer.eta, c.layer.roughness, nullptr, {}};
  return bsdf_f(c, wo, wi, mode) - dielectric_f(top, wo, wi, mode);
}

// The table is the expectation of the stochastic walk: per coat (smooth; alpha 0.01 as the shared
// staircase's tiles; 0.1; 0.3 with an odd maxdepth, whose visits to the base round up; thin and
// thick layers), direction pair (grazing on either side) and transport mode, the mean of 40000
// walks agrees within 4 sigma plus the table's own error: its integrals are within 5e-4 of 1e6-
// sample Monte Carlo and interpolation adds about as much; 2e-3 is allowed. Each walk is keyed by
// wi turned about the normal by another angle, which leaves the walks' part unchanged (it depends
// on the angles to the normal only), so the walks are independent.
TEST(CoatedDiffuse, WalkTableIsTheWalksExpectation) {
  struct Coat {
    float alpha, thickness;
    int max_depth;
  };
  for (Coat coat : {Coat{0.0f, 0.01f, 10}, Coat{0.01f, 0.5f, 10}, Coat{0.1f, 0.01f, 10},
                    Coat{0.3f, 0.01f, 5}}) {
    CoatedDiffuseMaterial stochastic = coated(0.7f, coat.alpha, coat.thickness);
    stochastic.layer.max_depth = coat.max_depth;
    stochastic.reflectance[1] = 0.2f;  // the visits' sum depends on the reflectance
    auto table = make_coat_walk_table(stochastic.layer);
    ASSERT_TRUE(table);
    CoatedDiffuseMaterial tabled = stochastic;
    tabled.walk_table = table.get();
    int pair = 0;
    for (auto [cos_o, cos_i] :
         {std::pair{0.9f, 0.8f}, {0.5f, 0.3f}, {0.06f, 0.7f}, {0.8f, 0.03f}}) {
      const TransportMode mode = pair++ % 2 ? TransportMode::kImportance : TransportMode::kRadiance;
      const Vec3 wo = direction(cos_o, 0.3f);
      const int n = 40000;
      MeanAccumulator walks[2];
      for (int k = 0; k < n; ++k) {
        Spectrum v = walks_f(stochastic, wo, direction(cos_i, 2 * kPi * float(k) / n), mode);
        for (int c = 0; c < 2; ++c) walks[c].add(v[c]);
      }
      const Spectrum expected = walks_f(tabled, wo, direction(cos_i, 2.0f), mode);
      for (int c = 0; c < 2; ++c)
        EXPECT_NEAR(expected[c], walks[c].mean,
                    kMeanTestSigmas * walks[c].standard_error() + 2e-3 * walks[c].mean)
            << "alpha " << coat.alpha << " thickness " << coat.thickness << " cos " << cos_o << " "
            << cos_i << " channel " << c;
    }
  }
}

TEST(CoatedDiffuse, WalkTableOnlyForIsotropicCoats) {
  CoatLayer anisotropic;
  anisotropic.roughness = Roughness{0.1f, 0.3f};
  EXPECT_FALSE(make_coat_walk_table(anisotropic));
  // A table made for another coat is not used: f is the walk's estimate again.
  CoatedDiffuseMaterial c = coated(0.6f, 0.3f);
  CoatLayer other = c.layer;
  other.thickness = 0.5f;
  auto table = make_coat_walk_table(other);
  ASSERT_TRUE(table);
  CoatedDiffuseMaterial with_other = c;
  with_other.walk_table = table.get();
  Vec3 a = direction(0.8f, 0.3f), b = direction(0.5f, 2.0f);
  EXPECT_EQ(bsdf_f(with_other, a, b, TransportMode::kRadiance)[0],
            bsdf_f(c, a, b, TransportMode::kRadiance)[0]);
}

CoatedConductorMaterial coated_gold(float coat_alpha, float base_alpha) {
  CoatedConductorMaterial m;
  m.layer.roughness = Roughness{coat_alpha, coat_alpha};
  m.conductor.eta = Spectrum(0.3f);
  m.conductor.eta[2] = 1.2f;
  m.conductor.k = Spectrum(2.8f);
  m.conductor.roughness = Roughness{base_alpha, base_alpha};
  return m;
}

TEST(CoatedConductor, SampledWeightsMatchEvaluatedBsdfPerBin) {
  expect_sampling_matches_evaluation(coated_gold(0.3f, 0.2f), direction(0.7f, 0.4f));
  expect_sampling_matches_evaluation(coated_gold(0.0f, 0.3f),
                                     direction(0.5f, 2.4f));  // smooth coat
  expect_sampling_matches_evaluation(coated_gold(0.3f, 0.0f),
                                     direction(0.8f, 5.0f));  // mirror base
}

TEST(CoatedConductor, SmoothCoatOverMirrorConservesEnergyAndIsSpecular) {
  CoatedConductorMaterial c = coated_gold(0.0f, 0.0f);
  c.conductor.eta = Spectrum(1.0f);
  c.conductor.k = Spectrum(1e4f);  // reflectance 1 at every angle
  c.layer.thickness = 1e-6f;
  c.layer.max_depth = 200;
  Material m = c;
  EXPECT_TRUE(bsdf_is_specular(m));
  for (float cos_o : {0.9f, 0.3f}) {
    MeanAccumulator s = sampled_albedo(m, direction(cos_o, 1.0f), 20000, 8);
    EXPECT_NEAR(s.mean, 1.0, kMeanTestSigmas * s.standard_error() + 2e-3) << "cos " << cos_o;
  }
  EXPECT_TRUE(
      bsdf_f(m, direction(0.9f, 1.0f), direction(0.9f, 1.0f + kPi), TransportMode::kRadiance)
          .is_black());
}

TEST(CoatedDiffuse, ReciprocalInExpectation) {
  CoatedDiffuseMaterial c = coated(0.6f, 0.3f);
  c.layer.samples =
      4000;  // many walks per value, so that one evaluation is close to the expectation
  Material m = c;
  for (auto [a, b] : {std::pair{direction(0.9f, 0.3f), direction(0.3f, 2.0f)},
                      {direction(0.5f, 1.0f), direction(0.7f, 4.0f)}}) {
    float fab = bsdf_f(m, a, b, TransportMode::kRadiance)[0],
          fba = bsdf_f(m, b, a, TransportMode::kRadiance)[0];
    EXPECT_NEAR(fab, fba, 0.03f * fab);
    // Reflection: radiance and importance transport see the same BSDF.
    float iab = bsdf_f(m, a, b, TransportMode::kImportance)[0];
    EXPECT_NEAR(fab, iab, 0.03f * fab);
  }
}

TEST(CoatedDiffuse, NoTransmissionTwoSidedAndDeterministic) {
  Material m = coated(0.6f, 0.3f);
  Vec3 a = direction(0.8f, 0.3f), b = direction(0.5f, 2.0f);
  EXPECT_TRUE(bsdf_f(m, a, -b, TransportMode::kRadiance).is_black());
  // Seen from below, the same material (the walk's random numbers are keyed by the directions).
  EXPECT_EQ(bsdf_f(m, a, b, TransportMode::kRadiance)[0],
            bsdf_f(m, -a, -b, TransportMode::kRadiance)[0]);
  EXPECT_EQ(bsdf_f(m, a, b, TransportMode::kRadiance)[0],
            bsdf_f(m, a, b, TransportMode::kRadiance)[0]);
  EXPECT_GT(bsdf_pdf(m, a, b, TransportMode::kRadiance), 0.0f);
  EXPECT_FALSE(bsdf_is_specular(m));
  auto s = bsdf_sample(m, a, 0.9f, {0.3f, 0.6f}, TransportMode::kRadiance);
  ASSERT_TRUE(s.has_value());
  EXPECT_GT(s->mis_pdf, 0.0f);
  EXPECT_GT(s->wi.z, 0.0f);
}

}  // namespace
}  // namespace bpm
