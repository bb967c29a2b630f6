#include "bpm/photon_count.h"

#include <algorithm>
#include <cmath>

#include "bpm/accumulate.h"

namespace bpm {

namespace {

// The time of one unit of each count against one eye ray's (about 0.22 us on 2 cores), fitted to
// the stage times of seven scenes (docs/MEASUREMENTS.md, "Photons per iteration"): a backward
// photon costs its tree's build and its accumulation, a sphere in a medium its Embree build on
// top, a query the leaf it descends to, a beam its traversal of the spheres, an entry its gather
// and application; a light ray counts as an eye ray.
constexpr double kBackwardPhotonRays = 1.5;
constexpr double kMediumSphereRays = 5;
constexpr double kQueryRays = 0.5;
constexpr double kBeamRays = 2.5;
constexpr double kEntryRays = 0.3;

}  // namespace

double PassWork::eye_cost() const {
  if (!(v[kIterations] > 0)) return 0;
  return (v[kEyeRays] + kBackwardPhotonRays * v[kBackwardPhotons] +
          kMediumSphereRays * v[kMediumSpheres]) /
         v[kIterations];
}

double PassWork::photon_cost() const {
  if (!(v[kPhotons] > 0)) return 0;
  return (v[kLightRays] + kQueryRays * v[kQueries] + kBeamRays * v[kBeams] +
          kEntryRays * v[kEntries]) /
         v[kPhotons];
}

PhotonCountChoice choose_photon_count(const std::vector<double>& moments, const PassWork& work,
                                      int current, int initial) {
  PhotonCountChoice c{current, -1, 0};
  constexpr size_t kV = PixelMoments::kValues;
  const size_t pixels = moments.size() / kV;
  // The relative MSE's weights, 1 / (mean^2 + floor) with a floor of a tenth of the image's mean
  // (as the emission guide's pixel weights), over the pixels with two iterations or more.
  double total = 0;
  size_t seen = 0;
  for (size_t p = 0; p < pixels; ++p) {
    const double* m = &moments[kV * p];
    if (m[PixelMoments::kCount] < 2) continue;
    total += std::abs(m[PixelMoments::kSum]) / m[PixelMoments::kCount];
    ++seen;
  }
  if (seen == 0 || !(total > 0)) return c;
  const double floor = 0.1 * total / double(seen);
  double var = 0, photon_var = 0, per_photon = 0;
  for (size_t p = 0; p < pixels; ++p) {
    const double* m = &moments[kV * p];
    const double n = m[PixelMoments::kCount];
    if (n < 2) continue;
    const double mean = m[PixelMoments::kSum] / n;
    const double w = 1 / (mean * mean + floor * floor);
    var += w * std::max(0.0, (m[PixelMoments::kSquares] - m[PixelMoments::kSum] * mean) / (n - 1));
    photon_var += w * m[PixelMoments::kPhotonVariance] / n;
    per_photon += w * m[PixelMoments::kPhotonVarianceTimesN] / n;
  }
  c.variance = var / double(seen);
  c.photon_variance = photon_var / double(seen);
  const double eye_cost = work.eye_cost(), photon_cost = work.photon_cost();
  if (!(var > 0) || !(per_photon > 0) || !(eye_cost > 0) || !(photon_cost > 0)) return c;
  c.photon_share = std::min(1.0, photon_var / var);
  // The eye pass's variance: what the light pass does not explain, at least 2% of the whole (where
  // the photons explain it all, a count 7 times the balance at equal shares, capped below).
  const double eye_var = std::max(var - photon_var, 0.02 * var);
  c.best = std::sqrt(per_photon * eye_cost / (eye_var * photon_cost));
  const double lo = std::max(double(kMinPhotons), 0.5 * current);
  const double hi = std::max(lo, std::min(double(initial), 2.0 * current));
  const double n = std::clamp(c.best, lo, hi);
  // In whole chunks of photons (photons/light_path.h), at least one; the initial count at most.
  constexpr double kChunk = 1024;
  c.photons = int(std::min(std::max(kChunk, std::round(n / kChunk) * kChunk),
                           std::max(double(initial), kChunk)));
  return c;
}

}  // namespace bpm
