// Perlin noise as pbrt-v4 evaluates it: zero on the integer lattice, repeating every 256 units,
// continuous, within [-1, 1], with pbrt-v4's forward-difference slope.
#include "base/noise.h"

#include <gtest/gtest.h>

#include <cmath>

#include "base/rng.h"

namespace bpm {
namespace {

TEST(PerlinNoise, ZeroOnTheLatticeAndRepeatsEvery256Units) {
  Rng rng(3);
  for (int i = 0; i < 200; ++i) {
    const Vec3 lattice(float(int(rng.uniform() * 600) - 300), float(int(rng.uniform() * 600) - 300),
                       float(int(rng.uniform() * 600) - 300));
    EXPECT_EQ(perlin_noise(lattice), 0.0f) << lattice.x << " " << lattice.y << " " << lattice.z;
    const Vec3 p(rng.uniform() * 50 - 25, rng.uniform() * 50 - 25, rng.uniform() * 50 - 25);
    EXPECT_NEAR(perlin_noise(p), perlin_noise(p + Vec3(256, 0, -512)), 1e-4f);
  }
}

// Bounded by 1 (each ramp is at most the offset's 1-norm along two axes, and the blend of the
// eight is at most about 1), not constant, of mean about 0, and continuous: a step of 1e-3 moves
// it by at most 3e-3 times the largest slope, about 2.
TEST(PerlinNoise, BoundedVariedAndContinuous) {
  Rng rng(5);
  double sum = 0, sum2 = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const Vec3 p(rng.uniform() * 40, rng.uniform() * 40, rng.uniform() * 40);
    const float v = perlin_noise(p);
    ASSERT_LE(std::fabs(v), 1.0f) << p.x << " " << p.y << " " << p.z;
    EXPECT_LE(std::fabs(perlin_noise(p + Vec3(1e-3f, -1e-3f, 1e-3f)) - v), 6e-3f);
    sum += v;
    sum2 += double(v) * v;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_GT(sd, 0.1);
  EXPECT_LT(std::fabs(mean), 5 * sd / std::sqrt(double(n)) + 0.01);
}

// The slope is the forward difference over 0.01 along each axis (pbrt-v4's DNoise).
TEST(PerlinNoise, SlopeIsTheForwardDifference) {
  const Vec3 p(3.3f, -1.7f, 8.2f);
  const Vec3 s = perlin_noise_slope(p);
  EXPECT_NEAR(s.x, (perlin_noise(p + Vec3(0.01f, 0, 0)) - perlin_noise(p)) / 0.01f, 1e-4f);
  EXPECT_NEAR(s.z, (perlin_noise(p + Vec3(0, 0, 0.01f)) - perlin_noise(p)) / 0.01f, 1e-4f);
  // Near the lattice the slope is that point's gradient, one of the twelve edge directions: two
  // components of magnitude 1 and one 0.
  const Vec3 g = perlin_noise_slope(Vec3(7, 2, -4) + Vec3(1e-4f, 1e-4f, 1e-4f));
  const float m = std::fabs(g.x) + std::fabs(g.y) + std::fabs(g.z);
  EXPECT_NEAR(m, 2.0f, 0.1f);
}

}  // namespace
}  // namespace bpm
