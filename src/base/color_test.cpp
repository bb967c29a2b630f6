// Tests of spectral upsampling, wavelength sampling and the film's colour conversion.
#include "base/color.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "base/chi2_test_util.h"
#include "base/rng.h"

namespace bpm {
namespace {

// The Monte Carlo colour of a curve: the film's conversion averaged over sampled wavelengths, with
// its standard error per channel.
struct ColourEstimate {
  MeanAccumulator c[3];
};
ColourEstimate estimate_colour(const SpectrumCurve& s, const SpectrumCurve* lit_by, int n,
                               uint64_t seed) {
  ColourEstimate e;
  Rng rng(seed);
  for (int i = 0; i < n; ++i) {
    Wavelengths wl = sample_wavelengths(rng.uniform());
    Spectrum v = s.sample(wl);
    if (lit_by) v *= lit_by->sample(wl);
    Rgb rgb = spectrum_to_rgb(v, wl);
    for (int k = 0; k < 3; ++k) e.c[k].add(rgb[k]);
  }
  return e;
}

TEST(Color, D65IsWhiteAtUnitLuminance) {
  SpectrumCurve d65 = SpectrumCurve::from_rgb(Rgb(1.0f), SpectrumKind::kIlluminant);
  EXPECT_NEAR(d65.luminance(), 1.0f, 1e-5f);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(d65.rgb()[k], 1.0f, 1e-5f);
  // The table: 100 at 560 nm before scaling, so the ratio to 560 nm is the CIE table's.
  EXPECT_NEAR(d65_unit(460) / d65_unit(560), 1.17812f, 1e-5f);
  EXPECT_NEAR(d65_unit(555) / d65_unit(560), 0.5f * (1.04046f + 1.0f), 1e-5f);
}

TEST(Color, SigmoidFitReproducesReflectances) {
  // A grid over the unit cube, including saturated colours near its faces.
  const float values[] = {0.02f, 0.05f, 0.2f, 0.5f, 0.8f, 0.95f};
  for (float r : values)
    for (float g : values)
      for (float b : values) {
        std::array<float, 3> coeff;
        float residual = fit_sigmoid(Rgb(r, g, b), &coeff);
        EXPECT_LT(residual, 2e-4f) << r << " " << g << " " << b;
        SpectrumCurve s = SpectrumCurve::from_rgb(Rgb(r, g, b), SpectrumKind::kAlbedo);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(s.rgb()[k], Rgb(r, g, b)[k], 2e-4f);
        // A reflectance stays within [0, 1] at every wavelength.
        EXPECT_GE(s.min_value(), 0.0f);
        EXPECT_LE(s.max_value(), 1.0f);
      }
}

// The colour of the sigmoid spectrum with coefficients c under D65, integrated at 1 nm.
Rgb sigmoid_colour(const std::array<float, 3>& c) {
  std::vector<float> values(size_t(kLambdaMax - kLambdaMin) + 1);
  for (size_t i = 0; i < values.size(); ++i) values[i] = sigmoid_spectrum(c, kLambdaMin + float(i));
  return SpectrumCurve::from_table(values, SpectrumKind::kAlbedo).rgb();
}

// The interpolated table that texels use reproduces colours all over the cube, between its nodes
// too: measured worst 0.0017 and mean 0.0006 per channel over these colours (an 8-bit step is
// 0.004).
TEST(Color, SigmoidTableReproducesColoursBetweenNodes) {
  Rng rng(7);
  double worst = 0, sum = 0;
  const int n = 600;
  for (int i = 0; i < n; ++i) {
    Rgb c(rng.uniform(), rng.uniform(), rng.uniform());
    if (i % 3 == 0) c[i % 9 / 3] *= 0.05f;  // saturated colours too
    Rgb got = sigmoid_colour(sigmoid_coefficients_lookup(c));
    double err = 0;
    for (int k = 0; k < 3; ++k) err = std::max(err, double(std::fabs(got[k] - c[k])));
    worst = std::max(worst, err);
    sum += err;
  }
  EXPECT_LT(worst, 3e-3) << "mean " << sum / n;
  EXPECT_LT(sum / n, 1e-3);
  // Grey and black.
  EXPECT_NEAR(sigmoid_colour(sigmoid_coefficients_lookup(Rgb(0.5f)))[1], 0.5f, 1e-3f);
  Wavelengths wl = sample_wavelengths(0.3f);
  EXPECT_TRUE(rgb_texel_spectrum(Rgb(0.0f), SpectrumKind::kAlbedo, wl).is_black());
  // An albedo texel above 1 is clamped; an unbounded one keeps its size.
  Spectrum a = rgb_texel_spectrum(Rgb(2.0f, 2.0f, 2.0f), SpectrumKind::kAlbedo, wl);
  for (int i = 0; i < Spectrum::kChannels; ++i) EXPECT_NEAR(a[i], 1.0f, 2e-3f);
  Spectrum u = rgb_texel_spectrum(Rgb(3.0f, 3.0f, 3.0f), SpectrumKind::kUnbounded, wl);
  for (int i = 0; i < Spectrum::kChannels; ++i) EXPECT_NEAR(u[i], 3.0f, 1e-2f);
}

TEST(Color, GreyStaysConstantAndBlackIsZero) {
  SpectrumCurve g = SpectrumCurve::from_rgb(Rgb(0.3f), SpectrumKind::kAlbedo);
  EXPECT_TRUE(g.is_constant());
  EXPECT_FLOAT_EQ(g.value(400), 0.3f);
  EXPECT_FLOAT_EQ(g.value(700), 0.3f);
  EXPECT_TRUE(SpectrumCurve::from_rgb(Rgb(0.0f), SpectrumKind::kAlbedo).is_black());
}

TEST(Color, UnboundedAndIlluminantColoursRoundTrip) {
  for (Rgb c : {Rgb(17, 12, 4), Rgb(0.2f, 0.9f, 3.0f), Rgb(1.0f, 0.0f, 0.5f)}) {
    SpectrumCurve u = SpectrumCurve::from_rgb(c, SpectrumKind::kUnbounded);
    SpectrumCurve l = SpectrumCurve::from_rgb(c, SpectrumKind::kIlluminant);
    float tol = 2e-3f * c.max_component();  // a zero channel cannot be met exactly by a sigmoid
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(u.rgb()[k], c[k], tol) << k;
      EXPECT_NEAR(l.rgb()[k], c[k], tol) << k;
    }
  }
}

// The film's conversion is unbiased: averaged over sampled wavelengths it gives the curve's colour,
// for a light seen directly and for a reflectance lit by D65.
TEST(Color, SampledConversionIsUnbiased) {
  SpectrumCurve light = SpectrumCurve::from_rgb(Rgb(17, 12, 4), SpectrumKind::kIlluminant);
  SpectrumCurve d65 = SpectrumCurve::from_rgb(Rgb(1.0f), SpectrumKind::kIlluminant);
  SpectrumCurve red = SpectrumCurve::from_rgb(Rgb(0.63f, 0.065f, 0.05f), SpectrumKind::kAlbedo);
  SpectrumCurve bb = SpectrumCurve::blackbody(3000);
  struct Case {
    const char* name;
    const SpectrumCurve& s;
    const SpectrumCurve* lit;
    Rgb expected;
  } cases[] = {{"light", light, nullptr, light.rgb()},
               {"red wall under D65", red, &d65, red.rgb()},
               {"blackbody", bb, nullptr, bb.rgb()}};
  for (const Case& c : cases) {
    ColourEstimate e = estimate_colour(c.s, c.lit, 200000, 11);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(e.c[k].mean, c.expected[k],
                  kMeanTestSigmas * e.c[k].standard_error() + 1e-4 * c.expected.max_component())
          << c.name << " channel " << k;
  }
}

TEST(Color, WavelengthSamplesFollowTheirDensity) {
  // The density integrates to one over the range, and the first of the four stratified
  // wavelengths (u itself) is distributed by it: a histogram against the integrated pdf.
  double integral = 0;
  for (float l = kLambdaMin; l < kLambdaMax; l += 0.5f) integral += 0.5 * wavelength_pdf(l + 0.25f);
  EXPECT_NEAR(integral, 1.0, 1e-4);
  const int bins = 47, n = 200000;
  std::vector<double> observed(bins, 0), expected(bins, 0);
  Rng rng(5);
  for (int i = 0; i < n; ++i) {
    Wavelengths wl = sample_wavelengths(rng.uniform());
    for (int j = 0; j < Spectrum::kChannels; ++j) {
      ASSERT_GE(wl.lambda[j], kLambdaMin);
      ASSERT_LE(wl.lambda[j], kLambdaMax);
      ASSERT_NEAR(wl.pdf[j], wavelength_pdf(wl.lambda[j]), 1e-6f);
    }
    int b = std::min(bins - 1, int((wl.lambda[0] - kLambdaMin) / (kLambdaMax - kLambdaMin) * bins));
    observed[b] += 1;
  }
  double width = (kLambdaMax - kLambdaMin) / bins;
  for (int b = 0; b < bins; ++b)
    for (int s = 0; s < 50; ++s)
      expected[b] += n * width / 50 * wavelength_pdf(kLambdaMin + width * (b + (s + 0.5f) / 50));
  double stat = 0;
  for (int b = 0; b < bins; ++b)
    stat += (observed[b] - expected[b]) * (observed[b] - expected[b]) / expected[b];
  EXPECT_GT(chi2::chi2_survival(stat, bins - 1), 0.01) << "statistic " << stat;
}

TEST(Color, BlackbodyPeaksAtOneAndReddensWhenCooler) {
  SpectrumCurve hot = SpectrumCurve::blackbody(6500), cool = SpectrumCurve::blackbody(2000);
  EXPECT_LE(hot.max_value(), 1.0f + 1e-4f);
  EXPECT_GT(hot.max_value(), 0.99f);  // the 6500 K peak (446 nm) is inside the range
  Rgb c = cool.scaled(1 / cool.luminance()).rgb();
  EXPECT_GT(c[0], c[1]);
  EXPECT_GT(c[1], c[2]);
}

// Why transport is spectral: the colour of light after two bounces off the same coloured wall is
// not the product of RGB colours. The spectral answer is the reference pbrt-v4 computes.
TEST(Color, TwoBouncesDifferFromTheRgbProduct) {
  Rgb wall(0.14f, 0.45f, 0.091f);
  SpectrumCurve s = SpectrumCurve::from_rgb(wall, SpectrumKind::kAlbedo);
  std::vector<float> squared;  // at 1 nm steps, as from_table takes them
  for (float l = kLambdaMin; l <= kLambdaMax; l += 1) squared.push_back(s.value(l) * s.value(l));
  Rgb spectral = SpectrumCurve::from_table(squared, SpectrumKind::kAlbedo).rgb();
  Rgb product = wall * wall;
  EXPECT_GT(std::fabs(spectral[2] / product[2] - 1), 0.05f)
      << "blue " << spectral[2] << " vs " << product[2];
}

}  // namespace
}  // namespace bpm
