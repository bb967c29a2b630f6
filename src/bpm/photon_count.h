// How many photons an iteration traces, chosen by the render from its own statistics.
//
// An iteration's estimate of a pixel has two independent parts of noise: that of the eye pass
// (which points the backward photons stand on, the light the eye paths count themselves), with a
// variance V_e per iteration whatever the photons, and that of the light pass over those points,
// V_p / N with N photons. An iteration costs T_e + c N (the eye pass and what scales with the
// backward photons, then c per photon). After a time T the film averages T / (T_e + c N)
// iterations, so its variance is (V_e + V_p / N) (T_e + c N) / T, least at
//
//   N* = sqrt(V_p T_e / (V_e c)),
//
// where the time goes to the two passes in the ratio of their variances. Near N* the loss is
// small (twice or half N* costs 12%), so rough estimates serve. The render measures them:
// V_p from the two halves of each light pass (the photons of even and odd index, A and B:
// (A - B)^2 estimates the variance of A + B over the light pass alone), V_e as the variance of
// the iterations' estimates less that, both over pixels weighted as the relative MSE weighs them;
// T_e and c as counted work (rays, backward photons, queries, beams, entries; each in units of
// about one ray's time), so that the count, and the image, depend on the scene, the seed and the
// budget alone and never on the machine or its load.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace bpm {

// Work counted in the passes: the eye pass's rays, backward photons and spheres in media (their
// trees and accumulation); the light pass's rays, diffuse-hit queries, beams and entries; the
// photons traced and the iterations.
struct PassWork {
  enum : std::size_t {
    kEyeRays,
    kBackwardPhotons,
    kMediumSpheres,
    kLightRays,
    kQueries,
    kBeams,
    kEntries,
    kPhotons,
    kIterations,
    kValues
  };
  std::array<double, kValues> v{};
  PassWork& operator+=(const PassWork& o) {
    for (std::size_t k = 0; k < kValues; ++k) v[k] += o.v[k];
    return *this;
  }
  PassWork operator-(const PassWork& o) const {
    PassWork d = *this;
    for (std::size_t k = 0; k < kValues; ++k) d.v[k] -= o.v[k];
    return d;
  }
  // Per iteration, in rays, what does not scale with the photons; per photon what does.
  double eye_cost() const;
  double photon_cost() const;
};

// What the choice read and made, for the run's record.
struct PhotonCountChoice {
  int photons = 0;           // the next iterations' count
  double photon_share = -1;  // the light pass's part of an iteration's variance (-1: unknown)
  double best = 0;           // N* before the limits
  // An iteration's relative variance, and the light pass's part of it, per pixel (means over the
  // pixels, each variance over its mean^2 + floor^2).
  double variance = 0, photon_variance = 0;
};

// The next count from the pixels' PixelMoments sums (bpm/accumulate.h) and the work so far, given
// the current count: N* within [current / 2, 2 current] (one round moves it at most so far) and
// [kMinPhotons, initial]. Never above the initial count (photons_for): the balance weighs the
// variance alone, and more photons per iteration mean fewer iterations in the same time, whose
// radii then shrink less, so that the bias stays larger (on the surface scenes of
// bench/equal_time it asked for up to 2.8 times the initial count and gained no variance). The
// current count where there is not yet enough to go by (no pixel with two iterations, no photon
// variance or no work counted).
constexpr int kMinPhotons = 4096;
PhotonCountChoice choose_photon_count(const std::vector<double>& moments, const PassWork& work,
                                      int current, int initial);

}  // namespace bpm
