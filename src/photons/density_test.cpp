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

// Photons that cross a facet under uniform radiance arrive in proportion to |wi.ng_photon|. Their
// mean contribution at a point of a neighbouring facet (tilted 40 degrees, as on a curved mesh,
// with its shading normal tilted 20 degrees the other way) is the reflected radiance: (R / pi^2)
// times the integral of |wi.ns| over the directions above the photon's facet and the shading
// surface, per unit of flux / pi. The weight |wi.ns| / |wi.ng_photon| exceeds t for a share of
// about 1 / t^2 of the photons. Weighed by the point's own geometric normal instead, it would
// exceed t for a share of about 1 / t (photons that graze the point's plane, not their facet):
// rare photons of unbounded weight, whose mean does not exist.
TEST(PhotonContribution, PhotonsOfATiltedFacetAverageToTheReflectedRadiance) {
  DiffuseMaterial d;
  for (int c = 0; c < Spectrum::kChannels; ++c) d.reflectance[c] = 0.5f;
  const Material m = d;
  auto tilted = [](float degrees) {
    const float a = degrees * kPi / 180;
    return Vec3{std::sin(a), 0, std::cos(a)};
  };
  const Vec3 n_photon = tilted(40), ns = tilted(-20);
  const Vec3 wo = normalize(Vec3{-0.3f, 0.2f, 1});
  const Frame photon_frame = Frame::from_z(n_photon);
  Rng rng(11);
  const int n = 400000;
  double sum = 0, sum2 = 0, largest = 0;
  for (int k = 0; k < n; ++k) {
    const Vec3 wi = photon_frame.to_world(sample_cosine_hemisphere({rng.uniform(), rng.uniform()}));
    const double v = photon_contribution(m, n_photon, ns, wo, wi, Spectrum(1.0f))[0];
    sum += v;
    sum2 += v * v;
    largest = std::max(largest, v);
  }
  const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
  // The integral of max(0, wi.ns) over the hemisphere of n_photon, by quadrature on the sphere.
  double integral = 0;
  const int steps = 1000;
  for (int i = 0; i < steps; ++i)
    for (int j = 0; j < 2 * steps; ++j) {
      const double theta = (i + 0.5) * kPi / steps, phi = (j + 0.5) * kPi / steps;
      const Vec3 w{float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)),
                   float(std::cos(theta))};
      const float c = dot(w, ns);
      if (dot(w, n_photon) > 0 && c > 0)
        integral += c * std::sin(theta) * (kPi / steps) * (kPi / steps);
    }
  const double expected = 0.5 / kPi * integral / kPi;
  EXPECT_NEAR(mean, expected, 4 * se + 1e-4 * expected);
  // Of 400000 photons, the largest weighs about sqrt(400000) = 630 times the mean; a 1 / t tail
  // would give one near 400000 times.
  EXPECT_LT(largest, 3000 * expected);
}

// radius_bias from the sums a density gives over the three nested discs: one whose disc averages
// are L0 + a rho^2 + b rho at radius rho. The three-radius model recovers a r^2 + b r exactly; the
// two-radius one recovers a r^2 when b = 0, and sees 2 (1 - 1 / sqrt 2) = 0.586 of the r term.
TEST(RadiusBias, ModelsRecoverTheTermsTheyAssume) {
  const float r = 0.5f, norm = 0.01f, L0 = 2;
  auto sums = [&](float a, float b) {
    auto disc = [&](float rho) { return Spectrum(L0 + a * rho * rho + b * rho); };
    // sum over a disc of radius rho = its average times pi rho^2 N = average / norm * (rho / r)^2
    return NestedSums{disc(r) / norm, disc(r / std::sqrt(2.0f)) / (2 * norm),
                      disc(r / 2) / (4 * norm)};
  };
  for (float a : {0.0f, 1.5f, -3.0f})
    for (float b : {0.0f, 0.8f, -0.4f}) {
      const float truth = a * r * r + b * r;
      EXPECT_NEAR(radius_bias(sums(a, b), norm, BiasModel::kSquareAndLinear)[3], truth, 1e-4f)
          << a << " " << b;
      EXPECT_NEAR(radius_bias(sums(a, b), norm, BiasModel::kSquare)[3],
                  a * r * r + 2 * (1 - 1 / std::sqrt(2.0f)) * b * r, 1e-4f)
          << a << " " << b;
    }
}

// NestedSums puts a contribution in every disc that holds it.
TEST(RadiusBias, NestedSumsCountEachDisc) {
  NestedSums s;
  const float r2 = 1;
  s.add(Spectrum(1), 0.2f, r2);  // within r / 2 (d^2 < 1/4)
  s.add(Spectrum(2), 0.3f, r2);  // within r / sqrt 2 only
  s.add(Spectrum(4), 0.9f, r2);  // within r only
  EXPECT_FLOAT_EQ(s.all[0], 7);
  EXPECT_FLOAT_EQ(s.half[0], 3);
  EXPECT_FLOAT_EQ(s.quarter[0], 1);
}

}  // namespace
}  // namespace bpm
