#include "bpm/photon_count.h"

#include <gtest/gtest.h>

#include <cmath>

#include "bpm/accumulate.h"

namespace bpm {
namespace {

// Moments of `pixels` pixels over n iterations whose estimates have mean `mean`, eye variance
// eye_var and photon variance photon_var with `photons` photons, as the iterations would sum them
// in expectation.
std::vector<double> moments(size_t pixels, double n, double mean, double eye_var, double photon_var,
                            double photons) {
  std::vector<double> m(pixels * PixelMoments::kValues);
  for (size_t p = 0; p < pixels; ++p) {
    double* v = &m[p * PixelMoments::kValues];
    v[PixelMoments::kSum] = n * mean;
    v[PixelMoments::kSquares] = n * mean * mean + (n - 1) * (eye_var + photon_var);
    v[PixelMoments::kPhotonVariance] = n * photon_var;
    v[PixelMoments::kPhotonVarianceTimesN] = n * photon_var * photons;
    v[PixelMoments::kCount] = n;
  }
  return m;
}

// Work of `iterations` iterations of `photons` photons: eye_rays per iteration, light_rays per
// photon (nothing else counted).
PassWork work(double iterations, double eye_rays, double photons, double light_rays) {
  PassWork w;
  w.v[PassWork::kIterations] = iterations;
  w.v[PassWork::kEyeRays] = iterations * eye_rays;
  w.v[PassWork::kPhotons] = iterations * photons;
  w.v[PassWork::kLightRays] = iterations * photons * light_rays;
  return w;
}

TEST(PhotonCount, BalancesTheVariancesAgainstTheirCosts) {
  // N* = sqrt(V_p T_e / (V_e c)): V_p = 0.01 * 1e5 = 1000, T_e = 2e5 rays, V_e = 0.04, c = 5 rays,
  // within a factor 2 of the current 40000.
  const PhotonCountChoice c = choose_photon_count(moments(64, 10, 1, 0.04, 0.01, 1e5),
                                                  work(10, 2e5, 1e5, 5), 40000, 100000);
  const double best = std::sqrt(1000 * 2e5 / (0.04 * 5));
  EXPECT_NEAR(c.best, best, 1e-6 * best);
  EXPECT_NEAR(c.photon_share, 0.2, 1e-9);
  EXPECT_EQ(c.photons % 1024, 0);
  EXPECT_NEAR(c.photons, best, 512);
}

TEST(PhotonCount, MovesAtMostTwofoldARound) {
  // The photons explain nearly nothing: N* far below; and nearly all: far above.
  const PhotonCountChoice low = choose_photon_count(moments(16, 10, 1, 1.0, 1e-4, 1e5),
                                                    work(10, 1e5, 1e5, 10), 100000, 100000);
  EXPECT_LT(low.best, 50000);
  EXPECT_NEAR(low.photons, 50000, 512);
  const PhotonCountChoice high = choose_photon_count(moments(16, 10, 1, 1e-4, 1.0, 1e5),
                                                     work(10, 1e6, 1e5, 1), 100000, 1000000);
  EXPECT_GT(high.best, 200000);
  EXPECT_NEAR(high.photons, 200000, 512);
  // Never below kMinPhotons, never above the initial count.
  EXPECT_GE(choose_photon_count(moments(16, 10, 1, 1.0, 1e-6, 1e5), work(10, 1e3, 1e5, 10),
                                kMinPhotons, 100000)
                .photons,
            kMinPhotons);
  EXPECT_EQ(
      choose_photon_count(moments(16, 10, 1, 1e-6, 1.0, 1e5), work(10, 1e9, 1e5, 1), 60000, 100000)
          .photons,
      100000);
}

TEST(PhotonCount, KeepsTheCountWithoutEnoughToGoBy) {
  // One iteration per pixel: no variance across iterations yet.
  EXPECT_EQ(choose_photon_count(moments(16, 1, 1, 0.1, 0.1, 1e5), work(1, 1e5, 1e5, 5), 123904, 1e5)
                .photons,
            123904);
  // No photon variance (the photons reached no pixel), or no work counted.
  EXPECT_EQ(choose_photon_count(moments(16, 10, 1, 0.1, 0, 1e5), work(10, 1e5, 1e5, 5), 123904, 1e5)
                .photons,
            123904);
  EXPECT_EQ(choose_photon_count(moments(16, 10, 1, 0.1, 0.1, 1e5), PassWork{}, 123904, 1e5).photons,
            123904);
}

}  // namespace
}  // namespace bpm
