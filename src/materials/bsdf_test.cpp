// Tests of the BSDFs in bsdf.cpp: chi-square tests of sampled directions against bsdf_pdf,
// consistency of bsdf_sample with bsdf_f / bsdf_pdf, energy bounds and white-furnace identities,
// reciprocity (and the generalized reciprocity of refraction), Fresnel formulas, and the delta
// lobes of smooth and thin dielectrics.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "base/chi2_test_util.h"
#include "base/rng.h"
#include "base/sampling.h"
#include "materials/material.h"
#include "materials/microfacet.h"

namespace bpm {
namespace {

constexpr float kEta = 1.5f;
constexpr float kPhiO =
    0.6f;  // azimuth of wo: off the axes, so anisotropic lobes are not symmetric

Vec3 spherical(float cos_theta, float phi) {
  float s = std::sqrt(std::fmax(0.0f, 1 - cos_theta * cos_theta));
  return {s * std::cos(phi), s * std::sin(phi), cos_theta};
}

Vec3 random_direction(Rng& rng) { return sample_uniform_sphere({rng.uniform(), rng.uniform()}); }

// |a - b| <= rel * max(|a|, |b|) + abs_tol
bool near_rel(double a, double b, double rel, double abs_tol = 0) {
  return std::fabs(a - b) <= rel * std::fmax(std::fabs(a), std::fabs(b)) + abs_tol;
}

// A spectrum whose values differ per wavelength: a, b, c, d repeated over the channels.
Spectrum spec4(float a, float b, float c, float d) {
  const float v[4] = {a, b, c, d};
  Spectrum s;
  for (int i = 0; i < Spectrum::kChannels; ++i) s[i] = v[i % 4];
  return s;
}

Material diffuse() { return DiffuseMaterial{Spectrum(0.5f)}; }
Material rough_conductor(float ax, float ay) {
  ConductorMaterial c;
  c.eta = spec4(0.2f, 0.45f, 0.9f, 1.5f);  // roughly gold
  c.k = spec4(3.6f, 2.5f, 2.2f, 1.9f);
  c.roughness = Roughness{ax, ay};
  return c;
}
Material rough_dielectric(float alpha) {
  DielectricMaterial d;
  d.eta = kEta;
  d.roughness = Roughness{alpha, alpha};
  return d;
}
Material smooth_dielectric() {
  DielectricMaterial d;
  d.eta = kEta;
  return d;
}
Material diffuse_transmission() {
  DiffuseTransmissionMaterial m;
  m.reflectance = Spectrum(0.3f);
  m.transmittance = Spectrum(0.5f);
  return m;
}

Material phong() { return PhongMaterial{spec4(0.8f, 0.6f, 0.5f, 0.4f), 12}; }
bool is_phong(const Material& m) { return std::holds_alternative<PhongMaterial>(m); }
bool is_dielectric(const Material& m) { return std::holds_alternative<DielectricMaterial>(m); }

// For a rough dielectric: whether the microfacet normal of the pair (wo, wi), the generalized half
// vector eta_o wo + eta_i wi, is within |cos| < 0.05 of grazing to wo or to wi. There the
// Fresnel term, evaluated from one side, is ill-conditioned (near the critical angle when seen
// from inside: the transmittance goes like sqrt(cos - cos_critical)).
bool near_grazing_microfacet(Vec3 wo, Vec3 wi) {
  auto eta_of = [](Vec3 w) { return w.z > 0 ? 1.0f : kEta; };
  Vec3 h = normalize(wo * eta_of(wo) + wi * eta_of(wi));
  return std::fabs(dot(wo, h)) < 0.05f || std::fabs(dot(wi, h)) < 0.05f;
}

// One material and one outgoing direction.
struct BsdfCase {
  std::string name;
  Material material;
  float cos_theta_o = 1;
  uint64_t seed = 0;
  Vec3 wo() const { return spherical(cos_theta_o, kPhiO); }
};
void PrintTo(const BsdfCase& c, std::ostream* os) { *os << c.name; }

std::vector<BsdfCase> bsdf_cases() {
  std::vector<BsdfCase> v;
  auto add = [&](const std::string& name, const Material& m,
                 std::vector<std::pair<const char*, float>> wos) {
    for (auto& [label, c] : wos) v.push_back({name + "_" + label, m, c, 1000 + v.size()});
  };
  add("Diffuse", diffuse(),
      {{"Cos0p9", 0.9f}, {"Cos0p5", 0.5f}, {"Cos0p1", 0.1f}, {"CosMinus0p5", -0.5f}});
  add("ConductorIso0p3", rough_conductor(0.3f, 0.3f),
      {{"Cos0p9", 0.9f}, {"Cos0p5", 0.5f}, {"Cos0p1", 0.1f}});
  add("ConductorAniso0p1x0p4", rough_conductor(0.1f, 0.4f),
      {{"Cos0p9", 0.9f}, {"Cos0p5", 0.5f}, {"Cos0p1", 0.1f}});
  add("DielectricRough0p3", rough_dielectric(0.3f),
      {{"Cos0p9", 0.9f},
       {"Cos0p5", 0.5f},
       {"Cos0p1", 0.1f},
       {"CosMinus0p9", -0.9f},
       {"CosMinus0p6", -0.6f},
       {"CosMinus0p3", -0.3f}});
  add("DiffuseTransmission", diffuse_transmission(),
      {{"Cos0p9", 0.9f}, {"Cos0p5", 0.5f}, {"Cos0p1", 0.1f}, {"CosMinus0p6", -0.6f}});
  add("Phong12", phong(), {{"Cos0p9", 0.9f}, {"Cos0p3", 0.3f}, {"CosMinus0p7", -0.7f}});
  return v;
}

// The chi-square tests of this binary: one per case plus the two accepting self-tests of the
// harness below; the Sidak correction divides the family-wise 1% among them.
int chi2_test_count() { return int(bsdf_cases().size()) + 2; }

chi2::Options chi2_options() {
  chi2::Options o;
  o.n_tests = chi2_test_count();
  return o;
}

std::optional<Vec3> sample_direction(const Material& m, Vec3 wo, Rng& rng, TransportMode mode) {
  float uc = rng.uniform();
  Vec2 u{rng.uniform(), rng.uniform()};
  auto s = bsdf_sample(m, wo, uc, u, mode);
  if (!s) return std::nullopt;
  return s->wi;
}

// ---------------------------------------------------------------------------------------------
// The harness itself.

TEST(Chi2Harness, SurvivalFunctionMatchesClosedForms) {
  // dof = 2: Q(1, x/2) = exp(-x/2).
  for (double x : {0.1, 1.0, 5.0, 20.0, 60.0})
    EXPECT_NEAR(chi2::chi2_survival(x, 2), std::exp(-x / 2), 1e-12 + 1e-10 * std::exp(-x / 2)) << x;
  // dof = 1: erfc(sqrt(x/2)); 3.841458820694124 is the 95% quantile.
  for (double x : {0.5, 3.841458820694124, 10.0, 30.0})
    EXPECT_NEAR(chi2::chi2_survival(x, 1), std::erfc(std::sqrt(x / 2)),
                1e-9 * std::erfc(std::sqrt(x / 2)))
        << x;
  EXPECT_NEAR(chi2::chi2_survival(3.841458820694124, 1), 0.05, 1e-9);
  // Even dof = 2m: exp(-x/2) sum_{k<m} (x/2)^k / k!, here m = 100 (both the series and the
  // continued-fraction branches are exercised).
  for (double x : {150.0, 200.0, 260.0, 320.0}) {
    double s = 0;
    for (int k = 0; k < 100; ++k)
      s += std::exp(-x / 2 + k * std::log(x / 2) - std::lgamma(k + 1.0));
    EXPECT_NEAR(chi2::chi2_survival(x, 200), s, 1e-9 * s + 1e-300) << x;
  }
  EXPECT_EQ(chi2::chi2_survival(0, 5), 1.0);
  EXPECT_NEAR(chi2::sidak_alpha(0.01, 1), 0.01, 1e-15);
  EXPECT_LT(chi2::sidak_alpha(0.01, 20), 0.01 / 20 * 1.01);
  EXPECT_GT(chi2::sidak_alpha(0.01, 20), 0.01 / 20);
}

TEST(Chi2Harness, AcceptsCorrectSamplers) {
  // Uniform sphere.
  auto r = chi2::run([](Rng& rng) -> std::optional<Vec3> { return random_direction(rng); },
                     [](Vec3) { return double(kUniformSpherePdfSolidAngle); }, 11, chi2_options());
  EXPECT_TRUE(r.passed()) << r.report;
  // A sampler that fails 25% of the time, with a pdf that integrates to 0.75.
  auto r2 = chi2::run(
      [](Rng& rng) -> std::optional<Vec3> {
        if (rng.uniform() < 0.25f) return std::nullopt;
        return sample_cosine_hemisphere({rng.uniform(), rng.uniform()});
      },
      [](Vec3 w) { return w.z > 0 ? 0.75 * w.z * kInvPi : 0.0; }, 12, chi2_options());
  EXPECT_TRUE(r2.passed()) << r2.report;
}

TEST(Chi2Harness, RejectsWrongPdfs) {
  // Cosine-weighted samples against the uniform hemisphere density.
  auto r = chi2::run(
      [](Rng& rng) -> std::optional<Vec3> {
        return sample_cosine_hemisphere({rng.uniform(), rng.uniform()});
      },
      [](Vec3 w) { return w.z > 0 ? 1 / (2 * M_PI) : 0.0; }, 13, chi2_options());
  EXPECT_FALSE(r.passed()) << r.report;
  EXPECT_LT(r.p_value, 1e-12);
  // A GGX lobe of roughness 0.3 against the density of roughness 0.33.
  Material a = rough_conductor(0.3f, 0.3f), b = rough_conductor(0.33f, 0.33f);
  Vec3 wo = spherical(0.5f, kPhiO);
  auto r2 =
      chi2::run([&](Rng& rng) { return sample_direction(a, wo, rng, TransportMode::kRadiance); },
                [&](Vec3 wi) { return double(bsdf_pdf(b, wo, wi, TransportMode::kRadiance)); }, 14,
                chi2_options());
  EXPECT_FALSE(r2.passed()) << r2.report;
  // Failing samples that the pdf does not account for: a mass mismatch.
  auto r3 = chi2::run(
      [](Rng& rng) -> std::optional<Vec3> {
        if (rng.uniform() < 0.1f) return std::nullopt;
        return sample_cosine_hemisphere({rng.uniform(), rng.uniform()});
      },
      [](Vec3 w) { return w.z > 0 ? w.z * kInvPi : 0.0; }, 15, chi2_options());
  EXPECT_TRUE(r3.mass_mismatch) << r3.report;
  EXPECT_FALSE(r3.passed()) << r3.report;
}

// ---------------------------------------------------------------------------------------------
// Chi-square: bsdf_sample's directions follow bsdf_pdf.

class BsdfCaseTest : public ::testing::TestWithParam<BsdfCase> {};

TEST_P(BsdfCaseTest, Chi2SampledDirectionsFollowPdf) {
  const BsdfCase& c = GetParam();
  Vec3 wo = c.wo();
  auto r = chi2::run(
      [&](Rng& rng) { return sample_direction(c.material, wo, rng, TransportMode::kRadiance); },
      [&](Vec3 wi) { return double(bsdf_pdf(c.material, wo, wi, TransportMode::kRadiance)); },
      stream_key(c.seed, 1), chi2_options());
  EXPECT_TRUE(r.passed()) << c.name << ": " << r.report;
}

// bsdf_sample's f and pdf are bsdf_f and bsdf_pdf at the returned direction. The evaluation
// recomputes the microfacet normal from (wo, wi), which moves its cosine with wo by ~1e-7; where
// that cosine is within a few 1e-4 of the critical angle, the Fresnel transmittance (which goes
// like the square root of the distance) changes by more than 1e-3 relative. So dielectric pairs
// whose microfacet is nearly grazing to either direction are skipped (they are rare: fewer than
// 2% of the samples, which is asserted).
TEST_P(BsdfCaseTest, SampleAgreesWithEvaluation) {
  const BsdfCase& c = GetParam();
  Vec3 wo = c.wo();
  for (TransportMode mode : {TransportMode::kRadiance, TransportMode::kImportance}) {
    Rng rng(stream_key(c.seed, 2, int(mode)));
    int n_ok = 0, n_bad = 0, n_skipped = 0;
    std::string first_bad;
    for (int k = 0; k < 20000; ++k) {
      float uc = rng.uniform();
      Vec2 u{rng.uniform(), rng.uniform()};
      auto s = bsdf_sample(c.material, wo, uc, u, mode);
      if (!s) continue;
      ++n_ok;
      ASSERT_FALSE(s->is_specular());
      ASSERT_NEAR(length(s->wi), 1.0f, 1e-4f);
      ASSERT_EQ(s->is_transmission(), s->wi.z * wo.z < 0);
      if (is_dielectric(c.material) && near_grazing_microfacet(wo, s->wi)) {
        ++n_skipped;
        continue;
      }
      Spectrum f = bsdf_f(c.material, wo, s->wi, mode);
      float pdf = bsdf_pdf(c.material, wo, s->wi, mode);
      bool ok = near_rel(s->pdf_solid_angle, pdf, 1e-3);
      for (int ch = 0; ch < Spectrum::kChannels; ++ch) ok = ok && near_rel(s->f[ch], f[ch], 1e-3);
      if (!ok && n_bad++ == 0) {
        std::ostringstream os;
        os << "wi = (" << s->wi.x << ", " << s->wi.y << ", " << s->wi.z << "): sample f " << s->f[0]
           << " pdf " << s->pdf_solid_angle << ", evaluated f " << f[0] << " pdf " << pdf;
        first_bad = os.str();
      }
    }
    EXPECT_GT(n_ok, 10000) << c.name;
    EXPECT_LT(n_skipped, n_ok / 50) << c.name;
    EXPECT_EQ(n_bad, 0) << c.name << " mode " << int(mode) << ": " << first_bad;
  }
}

// Energy: the albedo E[f |cos| / pdf] does not exceed one. With visible-normal sampling every
// microfacet sample has weight F * G(wo, wi) / G1(wo) <= 1 (and 1/etap^2 times that for radiance
// transmission), diffuse samples have weight R (or R + T for diffuse transmission), so the bound
// holds per sample, not just on average. The exception is radiance transport leaving a denser
// medium (wo below a dielectric), whose transmitted weights carry eta^2 > 1 (Veach 1997, 5.2).
TEST_P(BsdfCaseTest, AlbedoAtMostOne) {
  const BsdfCase& c = GetParam();
  Vec3 wo = c.wo();
  for (TransportMode mode : {TransportMode::kRadiance, TransportMode::kImportance}) {
    float bound = 1;
    if (mode == TransportMode::kRadiance && is_dielectric(c.material) && wo.z < 0)
      bound = kEta * kEta;
    // The non-reciprocal lobe conserves energy in the direction light flows (importance); camera
    // paths carry |cos theta_i| / |cos theta_o|, which is not bounded by one.
    if (mode == TransportMode::kRadiance && is_phong(c.material)) continue;
    Rng rng(stream_key(c.seed, 3, int(mode)));
    MeanAccumulator albedo[Spectrum::kChannels];
    for (int k = 0; k < 100000; ++k) {
      float uc = rng.uniform();
      Vec2 u{rng.uniform(), rng.uniform()};
      auto s = bsdf_sample(c.material, wo, uc, u, mode);
      for (int ch = 0; ch < Spectrum::kChannels; ++ch)
        albedo[ch].add(s ? double(s->f[ch]) * std::fabs(s->wi.z) / s->pdf_solid_angle : 0.0);
    }
    for (int ch = 0; ch < Spectrum::kChannels; ++ch) {
      EXPECT_LE(albedo[ch].mean, bound + 3 * albedo[ch].standard_error())
          << c.name << " channel " << ch;
      EXPECT_LE(albedo[ch].max, bound * (1 + 1e-4))
          << c.name << " channel " << ch << " mode " << int(mode);
      EXPECT_GE(albedo[ch].min, 0.0) << c.name;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Materials, BsdfCaseTest, ::testing::ValuesIn(bsdf_cases()),
                         [](const ::testing::TestParamInfo<BsdfCase>& info) {
                           return info.param.name;
                         });

// ---------------------------------------------------------------------------------------------
// Exact albedos and white furnaces.

TEST(BsdfEnergy, DiffuseAlbedoIsReflectance) {
  // f cos / pdf = (R / pi) cos / (cos / pi) = R for every sample: a zero-variance estimator, so
  // the tolerance is float rounding.
  Material m = diffuse();
  for (float co : {0.9f, 0.3f, -0.7f}) {
    Rng rng(stream_key(21, int(co * 10)));
    MeanAccumulator a;
    for (int k = 0; k < 100000; ++k) {
      auto s = bsdf_sample(m, spherical(co, 1.0f), rng.uniform(), {rng.uniform(), rng.uniform()},
                           TransportMode::kRadiance);
      a.add(s ? s->f[0] * std::fabs(s->wi.z) / s->pdf_solid_angle : 0.0);
    }
    EXPECT_NEAR(a.mean, 0.5, kMeanTestSigmas * a.standard_error() + 1e-5) << co;
    EXPECT_NEAR(a.min, 0.5, 1e-5) << co;
    EXPECT_NEAR(a.max, 0.5, 1e-5) << co;
  }
}

TEST(BsdfEnergy, DiffuseTransmissionAlbedoIsReflectancePlusTransmittance) {
  // Reflection weight R (pr + pt) / pr, transmission weight T (pr + pt) / pt; both are
  // R + T = 0.8 here because the spectra are grey.
  Material m = diffuse_transmission();
  for (float co : {0.8f, -0.4f}) {
    Rng rng(stream_key(22, int(co * 10)));
    MeanAccumulator a;
    int n_refl = 0, n = 100000;
    for (int k = 0; k < n; ++k) {
      auto s = bsdf_sample(m, spherical(co, 2.0f), rng.uniform(), {rng.uniform(), rng.uniform()},
                           TransportMode::kRadiance);
      a.add(s ? s->f[0] * std::fabs(s->wi.z) / s->pdf_solid_angle : 0.0);
      if (s && !s->is_transmission()) ++n_refl;
    }
    EXPECT_NEAR(a.mean, 0.8, kMeanTestSigmas * a.standard_error() + 1e-5) << co;
    // The lobe is chosen with probability 0.3 / 0.8.
    double p = 0.3 / 0.8, sigma = std::sqrt(p * (1 - p) / n);
    EXPECT_NEAR(double(n_refl) / n, p, kMeanTestSigmas * sigma) << co;
  }
}

TEST(BsdfEnergy, SmoothDielectricWhiteFurnace) {
  // Importance transport: reflection weight (R / cos) cos / R = 1, transmission weight
  // (T / cos) cos / T = 1, so the weights average to exactly R + T = 1. Radiance transport divides
  // the transmitted weight by etap^2, so the average is R + T / etap^2.
  Material m = smooth_dielectric();
  for (float co : {0.9f, 0.5f, 0.1f, -0.9f, -0.8f, -0.5f}) {  // -0.5: total internal reflection
    Vec3 wo = spherical(co, 0.3f);
    float R = fresnel_dielectric(co, kEta), T = 1 - R;
    float etap = co > 0 ? kEta : 1 / kEta;
    for (TransportMode mode : {TransportMode::kImportance, TransportMode::kRadiance}) {
      Rng rng(stream_key(23, int(co * 10), int(mode)));
      MeanAccumulator a;
      for (int k = 0; k < 100000; ++k) {
        auto s = bsdf_sample(m, wo, rng.uniform(), {rng.uniform(), rng.uniform()}, mode);
        a.add(s ? s->f[0] * std::fabs(s->wi.z) / s->pdf_solid_angle : 0.0);
      }
      double expected = mode == TransportMode::kImportance ? 1.0 : R + T / (etap * etap);
      EXPECT_NEAR(a.mean, expected, kMeanTestSigmas * a.standard_error() + 1e-5)
          << "cos " << co << " mode " << int(mode);
    }
  }
}

TEST(BsdfEnergy, RoughPerfectConductorLosesLittleEnergyAtLowRoughness) {
  // eta = 1, k = 100: Fresnel reflectance > 0.999 at every angle. At normal incidence with
  // alpha = 0.1 the single-scattering microfacet model loses well under 1%: the weight is
  // F / (1 + Lambda(wi)), with Lambda tiny for the near-normal wi.
  ConductorMaterial c;
  c.eta = Spectrum(1.0f);
  c.k = Spectrum(100.0f);
  c.roughness = Roughness{0.1f, 0.1f};
  Material m = c;
  Rng rng(24);
  MeanAccumulator a;
  for (int k = 0; k < 100000; ++k) {
    auto s = bsdf_sample(m, Vec3(0, 0, 1), rng.uniform(), {rng.uniform(), rng.uniform()},
                         TransportMode::kRadiance);
    a.add(s ? s->f[0] * std::fabs(s->wi.z) / s->pdf_solid_angle : 0.0);
  }
  EXPECT_GT(a.mean, 0.95);
  EXPECT_LE(a.mean, 1 + 3 * a.standard_error());
}

// ---------------------------------------------------------------------------------------------
// Reciprocity.

// The phong lobe is the non-reciprocal case: its radiance and importance values differ, each is
// the other with the arguments swapped (the adjoint), and light-direction samples carry exactly
// the reflectance as weight (the lobe is normalised per incident direction).
TEST(BsdfReciprocity, PhongIsNotReciprocalButHasAnAdjoint) {
  Material m = phong();
  Rng rng(stream_key(37, 0));
  int n_asymmetric = 0, n_pairs = 0;
  for (int k = 0; k < 20000; ++k) {
    Vec3 wo = random_direction(rng), wi = random_direction(rng);
    wi.z = std::copysign(wi.z, wo.z);
    Spectrum rad = bsdf_f(m, wo, wi, TransportMode::kRadiance);
    Spectrum imp = bsdf_f(m, wi, wo, TransportMode::kImportance);
    for (int ch = 0; ch < Spectrum::kChannels; ++ch)
      ASSERT_TRUE(near_rel(rad[ch], imp[ch], 1e-5, 1e-9));
    if (rad.is_black()) continue;
    ++n_pairs;
    Spectrum swapped = bsdf_f(m, wi, wo, TransportMode::kRadiance);
    if (!near_rel(rad[0], swapped[0], 1e-2)) ++n_asymmetric;
  }
  EXPECT_GT(n_pairs, 500);
  EXPECT_GT(n_asymmetric, n_pairs / 2);
  for (float cos_o : {0.95f, 0.5f}) {
    Vec3 wo = spherical(cos_o, 0.3f);
    for (int k = 0; k < 2000; ++k) {
      auto s = bsdf_sample(m, wo, rng.uniform(), {rng.uniform(), rng.uniform()},
                           TransportMode::kImportance);
      if (!s) continue;
      Spectrum w = s->f * (std::fabs(s->wi.z) / s->pdf_solid_angle);
      for (int ch = 0; ch < Spectrum::kChannels; ++ch)
        ASSERT_TRUE(near_rel(w[ch], std::get<PhongMaterial>(m).reflectance[ch], 1e-4));
    }
  }
}

TEST(BsdfReciprocity, ReflectionIsSymmetric) {
  std::vector<std::pair<const char*, Material>> materials = {
      {"diffuse", diffuse()},
      {"conductor iso", rough_conductor(0.3f, 0.3f)},
      {"conductor aniso", rough_conductor(0.1f, 0.4f)},
      {"dielectric", rough_dielectric(0.3f)},
      {"diffuse transmission", diffuse_transmission()},
  };
  for (auto& [name, m] : materials) {
    Rng rng(stream_key(31, std::string(name).size()));
    int n_nonzero = 0;
    for (int k = 0; k < 20000; ++k) {
      Vec3 wo = random_direction(rng), wi = random_direction(rng);
      if (k % 2) wi.z = std::copysign(wi.z, wo.z);  // half of the pairs in the same hemisphere
      if (!same_hemisphere(wo, wi) && !std::holds_alternative<DiffuseTransmissionMaterial>(m))
        continue;
      for (TransportMode mode : {TransportMode::kRadiance, TransportMode::kImportance}) {
        Spectrum a = bsdf_f(m, wo, wi, mode), b = bsdf_f(m, wi, wo, mode);
        for (int ch = 0; ch < Spectrum::kChannels; ++ch)
          ASSERT_TRUE(near_rel(a[ch], b[ch], 1e-4, 1e-7))
              << name << ": f(wo, wi) = " << a[ch] << ", f(wi, wo) = " << b[ch];
        if (!a.is_black()) ++n_nonzero;
      }
    }
    EXPECT_GT(n_nonzero, 5000) << name;
  }
}

// Refraction through a rough dielectric, on pairs drawn by bsdf_sample. With eta(w) the index of
// the medium w lies in (1 above the surface, kEta below):
//  * adjoint: f_importance(wo, wi) == f_radiance(wi, wo) (Veach 1997, 3.7.6 and 5.2);
//  * generalized reciprocity of the radiance BSDF: f(wo, wi) eta(wi)^2 == f(wi, wo) eta(wo)^2,
//    i.e. Veach's f_s(wi -> wo) / eta_o^2 = f_s(wo -> wi) / eta_i^2 in pbrt's argument order.
// Pairs whose microfacet is nearly grazing to either direction (|cos| < 0.05) are skipped: there
// the Fresnel transmittance is computed from one side through an ill-conditioned square root.
TEST(BsdfReciprocity, RoughDielectricTransmission) {
  Material m = rough_dielectric(0.3f);
  auto eta_of = [](Vec3 w) { return w.z > 0 ? 1.0f : kEta; };
  Rng rng(32);
  int n_checked = 0;
  for (int k = 0; k < 40000; ++k) {
    Vec3 wo = random_direction(rng);
    auto s =
        bsdf_sample(m, wo, rng.uniform(), {rng.uniform(), rng.uniform()}, TransportMode::kRadiance);
    if (!s) continue;
    Vec3 wi = s->wi;
    if (near_grazing_microfacet(wo, wi)) continue;
    float f_rad = bsdf_f(m, wo, wi, TransportMode::kRadiance)[0];
    float f_rad_rev = bsdf_f(m, wi, wo, TransportMode::kRadiance)[0];
    float f_imp = bsdf_f(m, wo, wi, TransportMode::kImportance)[0];
    ASSERT_TRUE(near_rel(f_imp, f_rad_rev, 1e-3, 1e-6))
        << "adjoint: f_imp(wo, wi) = " << f_imp << ", f_rad(wi, wo) = " << f_rad_rev << ", wo.z "
        << wo.z;
    float eo = eta_of(wo), ei = eta_of(wi);
    ASSERT_TRUE(near_rel(f_rad * ei * ei, f_rad_rev * eo * eo, 1e-3, 1e-6))
        << "f(wo, wi) = " << f_rad << ", f(wi, wo) = " << f_rad_rev << ", eta_o " << eo
        << ", eta_i " << ei;
    if (s->is_transmission()) ++n_checked;
  }
  EXPECT_GT(n_checked, 5000);
}

// Same random numbers, two transport modes: identical directions and densities; transmitted
// values differ by etap^2, reflected ones not at all.
TEST(BsdfReciprocity, RadianceAndImportanceDifferByEtaSquaredOnTransmission) {
  Material m = rough_dielectric(0.3f);
  Rng rng(33);
  int n_trans = 0;
  for (int k = 0; k < 20000; ++k) {
    Vec3 wo = random_direction(rng);
    float uc = rng.uniform();
    Vec2 u{rng.uniform(), rng.uniform()};
    auto r = bsdf_sample(m, wo, uc, u, TransportMode::kRadiance);
    auto i = bsdf_sample(m, wo, uc, u, TransportMode::kImportance);
    ASSERT_EQ(bool(r), bool(i));
    if (!r) continue;
    ASSERT_EQ(r->wi.x, i->wi.x);
    ASSERT_EQ(r->wi.y, i->wi.y);
    ASSERT_EQ(r->wi.z, i->wi.z);
    ASSERT_EQ(r->pdf_solid_angle, i->pdf_solid_angle);
    ASSERT_EQ(r->flags, i->flags);
    if (r->is_transmission()) {
      ++n_trans;
      float etap = wo.z > 0 ? kEta : 1 / kEta;
      ASSERT_NEAR(r->eta, etap, 1e-6f);
      ASSERT_TRUE(near_rel(i->f[0], r->f[0] * etap * etap, 1e-5)) << i->f[0] << " vs " << r->f[0];
    } else {
      ASSERT_EQ(r->eta, 1.0f);
      ASSERT_EQ(i->f[0], r->f[0]);
    }
  }
  EXPECT_GT(n_trans, 2000);
}

// ---------------------------------------------------------------------------------------------
// Fresnel.

TEST(Fresnel, DielectricNormalIncidence) {
  EXPECT_NEAR(fresnel_dielectric(1, 1.5f), 0.04f, 1e-5f);
  EXPECT_NEAR(fresnel_dielectric(-1, 1.5f), 0.04f, 1e-5f);  // from inside: same at normal incidence
  EXPECT_NEAR(fresnel_dielectric(0.7f, 1.0f), 0.0f, 1e-7f);  // index-matched: no reflection
}

TEST(Fresnel, TotalInternalReflection) {
  // From inside (cos < 0) beyond the critical angle cos_c = sqrt(1 - 1/eta^2) = 0.745.
  EXPECT_EQ(fresnel_dielectric(-0.7f, 1.5f), 1.0f);
  EXPECT_EQ(fresnel_dielectric(-0.5f, 1.5f), 1.0f);
  EXPECT_EQ(fresnel_dielectric(-0.1f, 1.5f), 1.0f);
  EXPECT_LT(fresnel_dielectric(-0.8f, 1.5f), 1.0f);
  EXPECT_NEAR(fresnel_dielectric(0.0f, 1.5f), 1.0f, 1e-6f);  // grazing from outside
}

// Fresnel reflectance is the same for the two directions of a refraction pair. (From inside, the
// outside cosine is recomputed as sqrt(1 - eta^2 sin^2): for cos_o >= 0.1 float rounding moves it
// by < 2e-6, and R by < 1e-5.)
TEST(Fresnel, SameReflectanceFromBothSidesOfARefraction) {
  for (float co = 0.1f; co <= 1.0f; co += 0.05f) {
    float sin2_t = (1 - co * co) / (kEta * kEta), ct = std::sqrt(1 - sin2_t);
    EXPECT_NEAR(fresnel_dielectric(co, kEta), fresnel_dielectric(-ct, kEta), 5e-5f) << co;
  }
}

TEST(Fresnel, ComplexWithZeroAbsorptionIsDielectric) {
  for (float eta : {1.2f, 1.5f, 2.4f, 1 / 1.5f})
    for (float c = 0.05f; c <= 1.0001f; c += 0.05f) {
      float cc = std::fmin(c, 1.0f);
      Spectrum fc = fresnel_complex(cc, Spectrum(eta), Spectrum(0.0f));
      for (int ch = 0; ch < Spectrum::kChannels; ++ch)
        EXPECT_NEAR(fc[ch], fresnel_dielectric(cc, eta), 1e-5f) << "eta " << eta << " cos " << cc;
    }
}

TEST(Fresnel, ComplexNormalIncidence) {
  Spectrum eta = spec4(0.2f, 0.45f, 0.9f, 1.5f), k = spec4(3.6f, 2.5f, 2.2f, 1.9f);
  Spectrum f = fresnel_complex(1, eta, k);
  for (int ch = 0; ch < Spectrum::kChannels; ++ch) {
    double n = eta[ch], kk = k[ch];
    double expected = ((n - 1) * (n - 1) + kk * kk) / ((n + 1) * (n + 1) + kk * kk);
    EXPECT_NEAR(f[ch], expected, 1e-5) << ch;
  }
}

// ---------------------------------------------------------------------------------------------
// Delta lobes.

TEST(SmoothDielectric, RefractionObeysSnellsLaw) {
  Material m = smooth_dielectric();
  for (float co : {0.95f, 0.7f, 0.3f, 0.05f, -0.95f, -0.8f}) {
    Vec3 wo = spherical(co, 2.2f);
    float R = fresnel_dielectric(co, kEta), T = 1 - R;
    ASSERT_LT(R, 1.0f);
    auto s = bsdf_sample(m, wo, 1 - 1e-6f, {0.5f, 0.5f}, TransportMode::kRadiance);
    ASSERT_TRUE(s.has_value()) << co;
    ASSERT_TRUE(s->is_transmission()) << co;
    ASSERT_TRUE(s->is_specular());
    float eta_o = co > 0 ? 1 : kEta, eta_i = co > 0 ? kEta : 1;
    EXPECT_LT(s->wi.z * wo.z, 0) << co;
    EXPECT_NEAR(length(s->wi), 1.0f, 1e-5f);
    // eta_o sin(theta_o) = eta_i sin(theta_i), and wi lies in the plane of incidence, opposite wo.
    EXPECT_NEAR(s->wi.x * eta_i, -wo.x * eta_o, 1e-5f) << co;
    EXPECT_NEAR(s->wi.y * eta_i, -wo.y * eta_o, 1e-5f) << co;
    EXPECT_NEAR(s->eta, eta_i / eta_o, 1e-6f);
    EXPECT_NEAR(s->pdf_solid_angle, T, 1e-5f);
    float etap = eta_i / eta_o;
    EXPECT_NEAR(s->f[0], T / std::fabs(s->wi.z) / (etap * etap), 1e-4f * s->f[0]);
    // Delta lobes are invisible to evaluation.
    EXPECT_TRUE(bsdf_f(m, wo, s->wi, TransportMode::kRadiance).is_black());
    EXPECT_EQ(bsdf_pdf(m, wo, s->wi, TransportMode::kRadiance), 0.0f);

    auto r = bsdf_sample(m, wo, 0.0f, {0.5f, 0.5f}, TransportMode::kRadiance);
    ASSERT_TRUE(r.has_value());
    ASSERT_FALSE(r->is_transmission());
    EXPECT_NEAR(r->wi.x, -wo.x, 1e-6f);
    EXPECT_NEAR(r->wi.y, -wo.y, 1e-6f);
    EXPECT_NEAR(r->wi.z, wo.z, 1e-6f);
    EXPECT_NEAR(r->pdf_solid_angle, R, 1e-5f);
    EXPECT_NEAR(r->f[0], R / std::fabs(wo.z), 1e-4f * r->f[0]);
  }
  EXPECT_TRUE(bsdf_is_specular(m));
}

TEST(SmoothDielectric, TotalInternalReflectionAlwaysReflects) {
  Material m = smooth_dielectric();
  Vec3 wo = spherical(-0.5f, 0.4f);
  for (float uc : {0.0f, 0.5f, 1 - 1e-6f}) {
    auto s = bsdf_sample(m, wo, uc, {0.3f, 0.3f}, TransportMode::kRadiance);
    ASSERT_TRUE(s.has_value());
    EXPECT_FALSE(s->is_transmission());
    EXPECT_NEAR(s->pdf_solid_angle, 1.0f, 1e-6f);
  }
}

// The lobe is chosen with probabilities R and T: the observed reflection frequency is binomial.
TEST(SmoothDielectric, LobeProbabilitiesAreFresnel) {
  Material m = smooth_dielectric();
  for (float co : {0.9f, 0.2f, -0.9f, -0.76f}) {
    Vec3 wo = spherical(co, 1.3f);
    double R = fresnel_dielectric(co, kEta);
    Rng rng(stream_key(41, int(co * 100)));
    int n = 100000, n_refl = 0;
    for (int k = 0; k < n; ++k) {
      auto s = bsdf_sample(m, wo, rng.uniform(), {rng.uniform(), rng.uniform()},
                           TransportMode::kRadiance);
      ASSERT_TRUE(s.has_value());
      if (!s->is_transmission()) {
        ++n_refl;
        ASSERT_NEAR(s->pdf_solid_angle, R, 1e-5);
      } else {
        ASSERT_NEAR(s->pdf_solid_angle, 1 - R, 1e-5);
      }
    }
    double sigma = std::sqrt(R * (1 - R) / n);
    EXPECT_NEAR(double(n_refl) / n, R, kMeanTestSigmas * sigma + 1e-12) << co;
  }
}

TEST(SmoothConductor, MirrorReflection) {
  ConductorMaterial c;
  c.eta = spec4(0.2f, 0.45f, 0.9f, 1.5f);
  c.k = spec4(3.6f, 2.5f, 2.2f, 1.9f);
  Material m = c;
  EXPECT_TRUE(bsdf_is_specular(m));
  EXPECT_FALSE(bsdf_is_specular(rough_conductor(0.3f, 0.3f)));
  Vec3 wo = spherical(0.6f, 0.9f);
  auto s = bsdf_sample(m, wo, 0.5f, {0.5f, 0.5f}, TransportMode::kRadiance);
  ASSERT_TRUE(s.has_value());
  EXPECT_TRUE(s->is_specular());
  EXPECT_NEAR(s->wi.x, -wo.x, 1e-6f);
  EXPECT_NEAR(s->wi.y, -wo.y, 1e-6f);
  EXPECT_NEAR(s->wi.z, wo.z, 1e-6f);
  Spectrum F = fresnel_complex(0.6f, c.eta, c.k);
  for (int ch = 0; ch < Spectrum::kChannels; ++ch) EXPECT_NEAR(s->f[ch], F[ch] / 0.6f, 1e-4f);
}

TEST(ThinDielectric, TransmissionPassesStraightThrough) {
  ThinDielectricMaterial t;
  t.eta = kEta;
  Material m = t;
  EXPECT_TRUE(bsdf_is_specular(m));
  for (float co : {0.9f, 0.4f, -0.6f}) {
    Vec3 wo = spherical(co, 2.7f);
    // Slab reflectance with all inter-reflections: R + T^2 R / (1 - R^2) = 2R / (1 + R).
    float R1 = fresnel_dielectric(std::fabs(co), kEta);
    float R = 2 * R1 / (1 + R1), T = 1 - R;
    auto s = bsdf_sample(m, wo, 1 - 1e-6f, {0.2f, 0.7f}, TransportMode::kRadiance);
    ASSERT_TRUE(s.has_value());
    ASSERT_TRUE(s->is_transmission());
    EXPECT_TRUE(s->is_specular());
    EXPECT_EQ(s->wi.x, -wo.x);
    EXPECT_EQ(s->wi.y, -wo.y);
    EXPECT_EQ(s->wi.z, -wo.z);
    EXPECT_NEAR(s->pdf_solid_angle, T, 1e-5f);
    EXPECT_NEAR(s->f[0], T / std::fabs(wo.z), 1e-4f * s->f[0]);
    auto r = bsdf_sample(m, wo, 0.0f, {0.2f, 0.7f}, TransportMode::kRadiance);
    ASSERT_TRUE(r.has_value());
    ASSERT_FALSE(r->is_transmission());
    EXPECT_NEAR(r->wi.z, wo.z, 1e-6f);
    EXPECT_NEAR(r->pdf_solid_angle, R, 1e-5f);
  }
}

}  // namespace
}  // namespace bpm
