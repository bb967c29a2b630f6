// Tests of the equal-area square-sphere map (orientation, inverse, equal solid angles) and of
// the 2D piecewise-constant distribution (density against its own pdf and cell frequencies), and
// of Henyey-Greenstein sampling.
#include "base/sampling.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "base/chi2_test_util.h"
#include "base/rng.h"

namespace bpm {
namespace {

TEST(EqualArea, CentreIsUpAndCornersAreDown) {
  Vec3 up = equal_area_square_to_sphere({0.5f, 0.5f});
  EXPECT_NEAR(up.z, 1.0f, 1e-6f);
  for (Vec2 c : {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1), Vec2(1, 1)})
    EXPECT_NEAR(equal_area_square_to_sphere(c).z, -1.0f, 1e-6f);
  // The midpoints of the edges and the diamond's corners lie on the equator, +x at u = 1.
  Vec3 px = equal_area_square_to_sphere({1.0f, 0.5f});
  EXPECT_NEAR(px.x, 1.0f, 1e-6f);
  Vec3 py = equal_area_square_to_sphere({0.5f, 1.0f});
  EXPECT_NEAR(py.y, 1.0f, 1e-6f);
}

TEST(EqualArea, InverseAndUnitLength) {
  Rng rng(3);
  for (int k = 0; k < 100000; ++k) {
    Vec2 p(rng.uniform(), rng.uniform());
    Vec3 w = equal_area_square_to_sphere(p);
    ASSERT_NEAR(length(w), 1.0f, 1e-5f);
    Vec2 q = equal_area_sphere_to_square(w);
    ASSERT_NEAR(q.x, p.x, 2e-4f) << p.x << " " << p.y;
    ASSERT_NEAR(q.y, p.y, 2e-4f) << p.x << " " << p.y;
    // And from the sphere's side.
    Vec3 d = sample_uniform_sphere({rng.uniform(), rng.uniform()});
    Vec3 back = equal_area_square_to_sphere(equal_area_sphere_to_square(d));
    ASSERT_NEAR(dot(back, d), 1.0f, 1e-5f);
  }
}

// Uniform points of the square give uniform directions: the fraction of directions in each of 8
// bands of z and 8 sectors of phi is 1/64 of the sphere (Archimedes: bands of equal height have
// equal area), checked cell by cell within 4 sigma.
TEST(EqualArea, EqualAreasOfTheSquareAreEqualSolidAngles) {
  Rng rng(5);
  const int n = 640000, cells = 64;
  std::vector<int> count(cells, 0);
  for (int k = 0; k < n; ++k) {
    Vec3 w = equal_area_square_to_sphere({rng.uniform(), rng.uniform()});
    int band = std::clamp(int((w.z + 1) / 2 * 8), 0, 7);
    float phi = std::atan2(w.y, w.x);
    if (phi < 0) phi += 2 * kPi;
    int sector = std::clamp(int(phi / (2 * kPi) * 8), 0, 7);
    ++count[size_t(band * 8 + sector)];
  }
  double p = 1.0 / cells, sigma = std::sqrt(n * p * (1 - p));
  for (int c = 0; c < cells; ++c) EXPECT_NEAR(count[size_t(c)], n * p, 4 * sigma) << "cell " << c;
}

TEST(CosSinQuarterTurn, WithinAboutAnUlpOfDouble) {
  // Over the whole range |a| <= pi/4, against double-precision cos and sin of the same float a;
  // the results are at most 1, where a float ulp is 6e-8: two ulps allow for the rounding of the
  // float evaluation, and dropping the last term of either series (3e-7, 2.4e-8 at pi/4) fails.
  double worst = 0;
  for (int k = -200000; k <= 200000; ++k) {
    const float a = float(k) / 200000 * (kPi / 4);
    const Vec2 cs = cos_sin_quarter_turn(a);
    worst = std::max({worst, std::fabs(double(cs.x) - std::cos(double(a))),
                      std::fabs(double(cs.y) - std::sin(double(a)))});
  }
  EXPECT_LT(worst, 1.2e-7);
}

TEST(ConcentricDisk, SameMapAsThePolarFormula) {
  // Shirley and Chiu's map: r = ox, theta = (pi/4)(oy/ox) where |ox| > |oy|, else r = oy,
  // theta = pi/2 - (pi/4)(ox/oy); evaluated in double, it must equal the float map.
  Rng rng(11);
  for (int k = 0; k < 100000; ++k) {
    const Vec2 u(rng.uniform(), rng.uniform());
    const double ox = 2.0 * u.x - 1, oy = 2.0 * u.y - 1;
    const bool wide = std::fabs(ox) > std::fabs(oy);
    const double r = wide ? ox : oy,
                 theta = wide ? (kPi / 4) * (oy / ox) : kPi / 2 - (kPi / 4) * (ox / oy);
    const Vec2 d = sample_uniform_disk_concentric(u);
    EXPECT_NEAR(d.x, r * std::cos(theta), 4e-7) << u.x << " " << u.y;
    EXPECT_NEAR(d.y, r * std::sin(theta), 4e-7) << u.x << " " << u.y;
  }
  // The centre, the axes (one offset zero), the diagonals and the corners.
  EXPECT_EQ(sample_uniform_disk_concentric({0.5f, 0.5f}).x, 0.0f);
  EXPECT_EQ(sample_uniform_disk_concentric({0.5f, 0.5f}).y, 0.0f);
  const float h = std::sqrt(0.5f);
  const std::pair<Vec2, Vec2> cases[] = {{{0.5f, 1.0f}, {0, 1}},
                                         {{1.0f, 0.5f}, {1, 0}},
                                         {{0.5f, 0.0f}, {0, -1}},
                                         {{0.0f, 0.5f}, {-1, 0}},
                                         {{0.9f, 0.9f}, {0.8f * h, 0.8f * h}},
                                         {{0.1f, 0.9f}, {-0.8f * h, 0.8f * h}},
                                         {{1.0f, 1.0f}, {h, h}},
                                         {{0.0f, 0.0f}, {-h, -h}}};
  for (const auto& [u, want] : cases) {
    const Vec2 d = sample_uniform_disk_concentric(u);
    EXPECT_NEAR(d.x, want.x, 2e-7) << u.x << " " << u.y;
    EXPECT_NEAR(d.y, want.y, 2e-7) << u.x << " " << u.y;
  }
}

TEST(Distribution2D, SamplesFollowTheWeights) {
  const int w = 5, h = 4;
  std::vector<float> weights = {1,    0, 2, 3, 0.5f,  //
                                0,    0, 0, 0, 0,     // an empty row is never drawn
                                4,    1, 1, 1, 1,     //
                                0.2f, 3, 0, 2, 1};
  Distribution2D d(weights, w, h);
  double total = 0;
  for (float x : weights) total += x;
  Rng rng(9);
  const int n = 400000;
  std::vector<int> count(weights.size(), 0);
  for (int k = 0; k < n; ++k) {
    float pdf = 0;
    Vec2 p = d.sample({rng.uniform(), rng.uniform()}, &pdf);
    ASSERT_GE(p.x, 0.0f);
    ASSERT_LT(p.x, 1.0f);
    ASSERT_GE(p.y, 0.0f);
    ASSERT_LT(p.y, 1.0f);
    int x = int(p.x * w), y = int(p.y * h);
    ASSERT_GT(weights[size_t(y * w + x)], 0.0f);
    ASSERT_NEAR(pdf, d.pdf(p), 1e-5f * pdf);
    ASSERT_NEAR(pdf, weights[size_t(y * w + x)] / total * w * h, 1e-4f * pdf);
    ++count[size_t(y * w + x)];
  }
  for (size_t i = 0; i < weights.size(); ++i) {
    double p = weights[i] / total;
    EXPECT_NEAR(count[i], n * p, 4 * std::sqrt(n * p * (1 - p)) + 1e-9) << "cell " << i;
  }
  // All-zero weights: uniform.
  Distribution2D zero(std::vector<float>(6, 0.0f), 3, 2);
  float pdf = 0;
  zero.sample({0.3f, 0.7f}, &pdf);
  EXPECT_NEAR(pdf, 1.0f, 1e-6f);
}

// Alias-method draws follow the weights, zero weights are never drawn, and the reported pmf is the
// weight's share. The weights span six decades, so a bin that must lend most of its mass and one
// that borrows from several others are both exercised.
TEST(AliasTable, SamplesFollowTheWeights) {
  std::vector<float> weights = {1, 0, 2, 3, 0.5f, 0, 1e-3f, 40, 1e-6f, 7, 0, 2.5f, 1, 1, 9};
  AliasTable t(weights);
  double total = 0;
  for (float x : weights) total += x;
  Rng rng(11);
  const int n = 1000000;
  std::vector<int> count(weights.size(), 0);
  for (int k = 0; k < n; ++k) {
    float pmf = 0;
    const uint32_t bits = rng.next_u32();
    int i = t.sample(bits, rng.uniform(), &pmf);
    ASSERT_GE(i, 0);
    ASSERT_LT(i, int(weights.size()));
    ASSERT_GT(weights[size_t(i)], 0.0f) << "a zero weight was drawn";
    ASSERT_NEAR(pmf, weights[size_t(i)] / total, 1e-6 * pmf);
    ++count[size_t(i)];
  }
  for (size_t i = 0; i < weights.size(); ++i) {
    double p = weights[i] / total;
    EXPECT_NEAR(count[i], n * p, 4 * std::sqrt(n * p * (1 - p)) + 1e-9) << "entry " << i;
  }
  // The probabilities the table implies, integrated over the coin on a fine grid for each bin
  // (the coin's grid step bounds the error): equal to the weights' shares.
  const int bins = int(weights.size()), steps = 100000;
  std::vector<double> implied(weights.size(), 0.0);
  for (int b = 0; b < bins; ++b) {
    const uint32_t bits = uint32_t(((uint64_t(b) << 32) + uint64_t(bins) - 1) / uint64_t(bins));
    for (int c = 0; c < steps; ++c)
      implied[size_t(t.sample(bits, (float(c) + 0.5f) / steps))] += 1.0 / (double(bins) * steps);
  }
  for (size_t i = 0; i < weights.size(); ++i)
    EXPECT_NEAR(implied[i], weights[i] / total, 2.0 / steps) << "entry " << i;
  // All-zero weights: uniform.
  AliasTable zero(std::vector<float>(4, 0.0f));
  EXPECT_NEAR(zero.pmf(2), 0.25f, 1e-7f);
}

}  // namespace
// The first 2^k values of the van der Corput sequence fall one in each interval of width 2^-k,
// whatever k, so the photon methods' wavelength offsets are stratified at every power of two.
TEST(RadicalInverse, FirstPowerOfTwoValuesStratify) {
  EXPECT_EQ(radical_inverse_base2(0), 0.0);
  EXPECT_EQ(radical_inverse_base2(1), 0.5);
  EXPECT_EQ(radical_inverse_base2(2), 0.25);
  EXPECT_EQ(radical_inverse_base2(3), 0.75);
  for (int k = 0; k <= 10; ++k) {
    const uint32_t n = 1u << k;
    std::vector<int> hits(n, 0);
    for (uint32_t i = 0; i < n; ++i) {
      double v = radical_inverse_base2(i);
      ASSERT_GE(v, 0.0);
      ASSERT_LT(v, 1.0);
      ++hits[size_t(v * n)];
    }
    for (uint32_t j = 0; j < n; ++j) EXPECT_EQ(hits[j], 1) << "k " << k << " interval " << j;
  }
}

// With the van der Corput sequence the second Sobol dimension forms a (0,2)-sequence: the first
// 2^m points put one point in every box of 2^-a by 2^-(m-a), for every a (the photon methods draw
// their wavelength offsets and hero strata from it).
TEST(Sobol2, WithVanDerCorputFormsA02Sequence) {
  for (int m = 0; m <= 8; ++m)
    for (int a = 0; a <= m; ++a) {
      const uint32_t n = 1u << m;
      std::vector<int> hits(n, 0);
      for (uint32_t i = 0; i < n; ++i) {
        // The top a bits of the first coordinate and the top m - a bits of the second.
        uint32_t x = a ? van_der_corput_bits(i) >> (32 - a) : 0;
        uint32_t y = m - a ? sobol2_bits(i) >> (32 - (m - a)) : 0;
        ++hits[(size_t(x) << (m - a)) | y];
      }
      for (uint32_t j = 0; j < n; ++j) EXPECT_EQ(hits[j], 1) << "m " << m << " a " << a;
    }
}

}  // namespace bpm

namespace bpm {
namespace {

// Henyey-Greenstein directions follow the phase function (chi-square over the sphere), for
// forward, backward and isotropic scattering about an oblique direction of travel.
TEST(HenyeyGreenstein, SamplesFollowThePhaseFunction) {
  const Vec3 travel = normalize(Vec3(0.3f, -0.5f, 0.8f));
  chi2::Options o;
  o.n_tests = 3;
  o.sub = 32;  // smooth
  for (float g : {0.7f, -0.4f, 0.0f}) {
    auto res = chi2::run(
        [&](Rng& rng) -> std::optional<Vec3> {
          return sample_henyey_greenstein(travel, g, {rng.uniform(), rng.uniform()});
        },
        [&](Vec3 w) { return double(henyey_greenstein(dot(travel, w), g)); }, 41, o);
    EXPECT_TRUE(res.passed()) << "g " << g << "\n" << res.report;
  }
}

}  // namespace
}  // namespace bpm

namespace bpm {
namespace {

// Under the Owen scramble the van der Corput sequence still puts its first 2^k values one in each
// interval of width 2^-k, and no longer at one offset within every interval (as a digital shift
// leaves them): the offsets of the first 2^k values within their intervals differ.
TEST(OwenVanDerCorput, FirstPowerOfTwoValuesStratifyAtRandomOffsets) {
  Rng seeds(97);
  for (int s = 0; s < 8; ++s) {
    const uint32_t seed = seeds.next_u32();
    for (int k = 0; k <= 10; ++k) {
      const uint32_t n = 1u << k;
      std::vector<int> hits(n, 0);
      double lo = 1, hi = 0;
      for (uint32_t i = 0; i < n; ++i) {
        const double v = double(owen_van_der_corput_bits(i, seed)) * 0x1p-32;
        ++hits[size_t(v * n)];
        const double offset = v * n - std::floor(v * n);
        lo = std::min(lo, offset);
        hi = std::max(hi, offset);
      }
      for (uint32_t j = 0; j < n; ++j) {
        ASSERT_EQ(hits[j], 1) << "seed " << seed << " k " << k;
      }
      if (k >= 2) {
        EXPECT_GT(hi - lo, 1e-3) << "seed " << seed << " k " << k;
      }
    }
  }
}

// Over random seeds each value of the scrambled sequence is uniform: chi-square over 32 equal
// bins, 8192 seeds, at the 0.1% level (61.1 for 31 degrees of freedom).
TEST(OwenVanDerCorput, EachValueIsUniformOverSeeds) {
  Rng seeds(5);
  for (uint32_t i : {0u, 1u, 6u, 1000u}) {
    constexpr int bins = 32, n = 8192;
    std::vector<int> count(bins, 0);
    for (int s = 0; s < n; ++s) ++count[owen_van_der_corput_bits(i, seeds.next_u32()) >> 27];
    double chi2 = 0;
    const double expected = double(n) / bins;
    for (int c : count) chi2 += (c - expected) * (c - expected) / expected;
    EXPECT_LT(chi2, 61.1) << "value " << i;
  }
}

}  // namespace
}  // namespace bpm
