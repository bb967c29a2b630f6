// Tests of the pixel filters' importance sampling: a sample's weight times a test function, summed
// and divided by the sum of weights (what the film does), converges to the filter-weighted average
// of the test function, integral(f g) / integral(f).
#include "film/filter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <ostream>
#include <string>
#include <vector>

#include "base/chi2_test_util.h"
#include "base/rng.h"

namespace bpm {
namespace {

struct FilterCase {
  std::string name;
  FilterSettings settings;
  bool analytic;  // sampled exactly (box, triangle) rather than from a tabulated |f|
};
void PrintTo(const FilterCase& c, std::ostream* os) { *os << c.name; }

FilterSettings settings(FilterType type, Vec2 radius) {
  FilterSettings s;
  s.type = type;
  s.radius = radius;
  return s;
}

// Different radii in x and y catch mixed-up axes; all radii are multiples of 1/64, so that the
// tabulated cells (32 per pixel) have power-of-two widths and the bounds are exact in float.
std::vector<FilterCase> filter_cases() {
  return {
      {"Box", settings(FilterType::kBox, {0.5f, 0.75f}), true},
      {"Triangle", settings(FilterType::kTriangle, {1.5f, 1.0f}), true},
      {"Gaussian", settings(FilterType::kGaussian, {1.5f, 1.25f}), false},
      {"Mitchell", settings(FilterType::kMitchell, {2.0f, 1.5f}), false},
      {"Lanczos", settings(FilterType::kLanczos, {1.5f, 1.5f}), false},
  };
}

// A test function with odd and even moments in both axes and a mixed term.
double g(double x, double y) { return 1 + x + x * x + 0.5 * y * y + x * y * y; }

class FilterTest : public ::testing::TestWithParam<FilterCase> {};

TEST_P(FilterTest, WeightedSamplesAverageTheTestFunction) {
  const FilterCase& fc = GetParam();
  Filter filter(fc.settings);
  const double rx = fc.settings.radius.x, ry = fc.settings.radius.y;

  // Reference integrals by the midpoint rule on a fine grid: k x k points in each cell of the
  // grid that filter.cpp tabulates (int(32 * 2 * radius) cells per axis). The same sums with f
  // replaced by its value at the cell centre give the error of that piecewise-constant
  // approximation, which the tabulated sampler carries by design; it is added to the tolerance.
  const int nx = std::max(1, int(32 * rx * 2)), ny = std::max(1, int(32 * ry * 2)), k = 8;
  const double cw = 2 * rx / nx, ch = 2 * ry / ny, da = (cw / k) * (ch / k);
  double i_f = 0, i_abs_f = 0, i_fg = 0, d_f = 0, d_fg = 0;  // d_: f minus its cell-centre value
  for (int cy = 0; cy < ny; ++cy)
    for (int cx = 0; cx < nx; ++cx) {
      double f_center =
          filter.evaluate({float(-rx + (cx + 0.5) * cw), float(-ry + (cy + 0.5) * ch)});
      for (int sy = 0; sy < k; ++sy)
        for (int sx = 0; sx < k; ++sx) {
          double x = -rx + cx * cw + (sx + 0.5) * cw / k, y = -ry + cy * ch + (sy + 0.5) * ch / k;
          double f = filter.evaluate({float(x), float(y)});
          i_f += f * da;
          i_abs_f += std::fabs(f) * da;
          i_fg += f * g(x, y) * da;
          d_f += (f - f_center) * da;
          d_fg += (f - f_center) * g(x, y) * da;
        }
    }
  ASSERT_GT(i_f, 0);
  const double mu = i_fg / i_f;
  // Errors of the piecewise-constant approximation in E[w] and in E[w (g - mu)].
  const double bias_w = fc.analytic ? 0.0 : d_f, bias_g = fc.analytic ? 0.0 : d_fg - mu * d_f;

  Rng rng(stream_key(77, uint64_t(fc.settings.radius.x * 64), uint64_t(fc.settings.type)));
  MeanAccumulator weighted_g, weight;
  const int n = 200000;
  for (int q = 0; q < n; ++q) {
    FilterSample s = filter.sample({rng.uniform(), rng.uniform()});
    ASSERT_LE(std::fabs(s.offset.x), fc.settings.radius.x) << fc.name;
    ASSERT_LE(std::fabs(s.offset.y), fc.settings.radius.y) << fc.name;
    ASSERT_TRUE(std::isfinite(s.weight));
    if (fc.analytic) {
      ASSERT_EQ(s.weight, 1.0f) << fc.name;
    }
    weighted_g.add(double(s.weight) * (g(s.offset.x, s.offset.y) - mu));
    weight.add(s.weight);
  }
  // E[w (g - mu)] = integral f (g - mu) = 0.
  EXPECT_NEAR(weighted_g.mean, 0.0,
              kMeanTestSigmas * weighted_g.standard_error() + std::fabs(bias_g) + 1e-6 * i_abs_f)
      << fc.name << ": self-normalised estimate " << mu + weighted_g.mean / weight.mean << " vs "
      << mu;
  // E[w] = integral f (1 for the analytic samplers, whose densities are f / integral f).
  if (!fc.analytic) {
    EXPECT_NEAR(weight.mean, i_f,
                kMeanTestSigmas * weight.standard_error() + std::fabs(bias_w) + 1e-5 * i_abs_f)
        << fc.name;
  }
}

// sample_density is the density sample() draws from, and normalized what a weighted sample
// averages with: both integrate to 1 over the filter's square, and each sample's weight is
// normalized / sample_density times one constant (1 for the analytic samplers, the tabulated
// integral for the others).
TEST_P(FilterTest, DensitiesIntegrateToOneAndMatchTheSamplesWeights) {
  const FilterCase& fc = GetParam();
  Filter filter(fc.settings);
  const double rx = fc.settings.radius.x, ry = fc.settings.radius.y;
  const int k = 512;
  double density = 0, normalized = 0;
  for (int y = 0; y < k; ++y)
    for (int x = 0; x < k; ++x) {
      const Vec2 o{float(-rx + (x + 0.5) * 2 * rx / k), float(-ry + (y + 0.5) * 2 * ry / k)};
      density += filter.sample_density(o) * (4 * rx * ry) / (k * k);
      normalized += filter.normalized(o) * (4 * rx * ry) / (k * k);
    }
  EXPECT_NEAR(density, 1.0, 2e-3) << fc.name;
  EXPECT_NEAR(normalized, 1.0, 2e-3) << fc.name;
  EXPECT_EQ(filter.sample_density({float(rx) * 1.01f, 0}), 0.0f);
  Rng rng(stream_key(79, uint64_t(fc.settings.type), 0));
  double constant = 0;
  for (int q = 0; q < 20000; ++q) {
    const FilterSample s = filter.sample({rng.uniform(), rng.uniform()});
    const float n = filter.normalized(s.offset), d = filter.sample_density(s.offset);
    ASSERT_GT(d, 0) << fc.name;
    if (n == 0) continue;
    const double c = double(s.weight) * d / n;
    if (constant == 0) constant = c;
    ASSERT_NEAR(c, constant, 1e-4 * constant) << fc.name;
  }
  if (fc.analytic) {
    EXPECT_NEAR(constant, 1.0, 1e-4) << fc.name;
  }
}

// The analytic samplers draw offsets with density exactly f / integral(f): the mean and second
// moment of the offset along each axis are those of the 1D factor.
TEST(FilterSampling, TriangleMoments) {
  Filter filter(settings(FilterType::kTriangle, {1.5f, 1.0f}));
  Rng rng(78);
  MeanAccumulator x2, y2, x;
  for (int q = 0; q < 200000; ++q) {
    FilterSample s = filter.sample({rng.uniform(), rng.uniform()});
    x.add(s.offset.x);
    x2.add(double(s.offset.x) * s.offset.x);
    y2.add(double(s.offset.y) * s.offset.y);
  }
  // A tent of radius r has variance r^2 / 6.
  EXPECT_NEAR(x.mean, 0.0, kMeanTestSigmas * x.standard_error());
  EXPECT_NEAR(x2.mean, 1.5 * 1.5 / 6, kMeanTestSigmas * x2.standard_error());
  EXPECT_NEAR(y2.mean, 1.0 / 6, kMeanTestSigmas * y2.standard_error());
}

INSTANTIATE_TEST_SUITE_P(Filters, FilterTest, ::testing::ValuesIn(filter_cases()),
                         [](const ::testing::TestParamInfo<FilterCase>& info) {
                           return info.param.name;
                         });

}  // namespace
}  // namespace bpm
