#include "bpm/accumulate.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <utility>

#include "base/error.h"
#include "integrator/progressive.h"
#include "photons/density.h"
#include "photons/disc_probes.h"

namespace bpm {

namespace {

// A pixel's PixelMoments: its estimate L, whose photon part is photon_L, odd_L of it from the odd
// photons of `emitted`; and beside them in its round statistics, 1 / the direct samples it took.
void add_moments(const Spectrum& L, const Spectrum& photon_L, const Spectrum& odd_L,
                 uint64_t emitted, int direct_samples, double* m, SampleStats<double>* stats) {
  stats->add_direct_taken(direct_samples);
  const double l = L.average(), halves = (photon_L - odd_L * 2).average();
  m[PixelMoments::kSum] += l;
  m[PixelMoments::kSquares] += l * l;
  m[PixelMoments::kPhotonVariance] += halves * halves;
  m[PixelMoments::kPhotonVarianceTimesN] += halves * halves * double(emitted);
  m[PixelMoments::kCount] += 1;
}

// A pixel's backward photons' shares (in place of their sums, by accumulate_iteration) summed:
// its photon part, its bias and the odd photons' part; and whether a small disc, and another,
// received light.
struct PixelShares {
  Spectrum photon_L, bias, odd_L;
  bool small_lit = false, large_lit = false;
};

// `at`: the pixel's backward photons by place (PixelSums::by_place), summed in the maps' order.
PixelShares pixel_shares(const BackwardMaps& maps, const LightPassResult& light, const uint32_t* at,
                         size_t places) {
  // In the maps' order (an insertion sort of a few).
  uint32_t found[kMaxBackwardPhotonsPerPath];
  size_t n = 0;
  for (size_t k = 0; k < places; ++k) {
    const uint32_t g = at[k];
    if (g == PixelSums::kNone) continue;
    size_t i = n++;
    for (; i > 0 && found[i - 1] > g; --i) found[i] = found[i - 1];
    found[i] = g;
  }
  PixelShares s;
  for (size_t k = 0; k < n; ++k) {
    (maps.photons[found[k]].small_disc() ? s.small_lit : s.large_lit) = true;
    s.photon_L += light.flux[found[k]];
    s.bias += light.flux_inner[found[k]];
    s.odd_L += light.flux_odd[found[k]];
  }
  return s;
}

// Pixel p's sums of camera and vertex connections (camera_connections.h, vertex_connections.h)
// added to its shares, per photon emitted. filter_weight: its camera sample's.
void add_connections(const LightPassResult& light, float filter_weight, float mean_filter_weight,
                     size_t p, PixelShares* sh) {
  const float per_photon = float(1.0 / double(light.emitted));
  if (!light.camera.empty()) {
    // The film weighs the whole estimate by the pixel's sample's filter weight, whose mean the
    // camera connections' shares already hold: divided out, so that a filter with negative lobes
    // (weights of either sign) does not flip them at random.
    const float norm =
        per_photon * (filter_weight != 0 ? mean_filter_weight / filter_weight : 1.0f);
    sh->photon_L += light.camera[p] * norm;
    sh->odd_L += light.camera_odd[p] * norm;
  }
  if (!light.vertex.empty()) {  // made at the pixel's own eye vertex, weighed as its merges
    sh->photon_L += light.vertex[p] * per_photon;
    sh->odd_L += light.vertex_odd[p] * per_photon;
  }
}

}  // namespace

void accumulate_iteration(const BackwardMaps& maps, LightPassResult* light_sums,
                          EyePixels* eye_pixels, const Wavelengths& wl, float max_component_value,
                          const PhotonSettings& settings, Film* film, PixelSums* sums,
                          std::vector<double>* estimates, std::vector<double>* moments,
                          float mean_filter_weight) {
  const int w = film->width(), h = film->height();
  LightPassResult& light = *light_sums;
  EyePixels& eye = *eye_pixels;
  // Each backward photon that received light: its shares of its pixel's estimate and bias (in place
  // of its sums, whose cache lines are at hand), and its place among its pixel's, in parallel over
  // the photons in the maps' order; each pixel then adds its shares in that order.
  const size_t places = size_t(sums->places);
  BPM_CHECK(places >= 1 && places <= kMaxBackwardPhotonsPerPath);
  std::vector<uint32_t>& at = sums->by_place;
  at.resize(size_t(w) * size_t(h) * places);
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, at.size(), 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
        std::fill(at.begin() + long(r.begin()), at.begin() + long(r.end()), PixelSums::kNone);
      });
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, maps.photons.size(), 1 << 12),
      [&](const tbb::blocked_range<size_t>& r) {
        for (size_t g = r.begin(); g < r.end(); ++g) {
          if (!light.reached[g] || light.flux[g].is_black()) continue;
          const BackwardPhoton& bp = maps.photons[g];
          // eq. (2): L = tau * sum f dPhi / (pi r^2), with dPhi = flux / N emitted.
          const float norm =
              float(1.0 / (kPi * double(bp.radius) * bp.radius * double(light.emitted)));
          // Over the part of each nested disc where photons can land (photons/disc_probes.h).
          NestedSums nested{light.flux[g], light.flux_inner[g], light.flux_quarter[g]};
          divide_by_disc_shares(&nested, bp.disc_found, bp.disc_cut);
          const Spectrum share = bp.tau * nested.all * norm,
                         bias = bp.tau * radius_bias(nested, norm, settings.bias_model);
          light.flux[g] = share;
          light.flux_inner[g] = bias;
          const float odd_share = bp.disc_cut ? disc_share(bp.disc_found, bp.disc_cut, 0) : 1.0f;
          light.flux_odd[g] = bp.tau * light.flux_odd[g] * (norm / odd_share);
          const size_t place = bp.place;
          BPM_CHECK(place < places);
          uint32_t& slot = at[size_t(bp.pixel) * places + place];
          BPM_CHECK(slot == PixelSums::kNone);
          slot = uint32_t(g);
        }
      });
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y < r.end(); ++y)
      for (int x = 0; x < w; ++x) {
        uint32_t p = uint32_t(y) * uint32_t(w) + uint32_t(x);
        if (!eye.sampled[p]) continue;
        PixelShares sh = pixel_shares(maps, light, at.data() + p * places, places);
        add_connections(light, eye.filter_weight[p], mean_filter_weight, p, &sh);
        const Spectrum &photon_L = sh.photon_L, &bias = sh.bias;
        eye.round_stats[p].add_lit(sh.small_lit, sh.large_lit);
        Spectrum L = eye.radiance[p] + photon_L;
        if (moments && L.is_finite())
          add_moments(L, photon_L, sh.odd_L, light.emitted, eye.direct_samples[p],
                      moments->data() + PixelMoments::kValues * size_t(p), &eye.round_stats[p]);
        if (settings.debias)
          L -= bias;
        else if (bias.is_finite() && eye.filter_weight[p] != 0 && recordable(L))
          film->add_bias(x, y, film->rgb_of(bias, wl), spectrum_to_luminance(bias, wl));
        record_pass(film, p, L, wl, eye.filter_weight[p], max_component_value, settings.debias);
        if (eye.sees_emission[p] && L.is_finite())
          eye.round_stats[p].add_rest(L.average() - eye.emission_part[p]);
        if (estimates && L.is_finite()) {
          (*estimates)[2 * size_t(p)] += L.average();
          (*estimates)[2 * size_t(p) + 1] += 1;
        }
      }
  });
}

std::vector<float> asked_pass_rates(const std::vector<double>& moments) {
  const size_t n = moments.size() / PixelMoments::kValues;
  // Each pixel's mean and the standard error of it, where it has the estimates adaptive
  // sampling waits for and one of them was not black (-1: none).
  std::vector<double> mean(n, 0.0), error(n, -1.0);
  double mean_sum = 0;
  size_t counted = 0;
  for (size_t p = 0; p < n; ++p) {
    const double* m = moments.data() + PixelMoments::kValues * p;
    const double count = m[PixelMoments::kCount], sum = m[PixelMoments::kSum],
                 squares = m[PixelMoments::kSquares];
    if (count < kWarmupPasses || !(squares > 0)) continue;
    mean[p] = std::fabs(sum / count);
    const double variance = std::max(0.0, (squares - sum * sum / count) / (count - 1));
    error[p] = std::sqrt(variance / count);
    mean_sum += mean[p];
    ++counted;
  }
  std::vector<float> asked(n, -1.0f);
  if (counted == 0) return asked;
  const double offset = 0.01 * mean_sum / double(counted) + 1e-12;  // as the control's
  std::vector<double> rel(n, -1.0), relative;
  for (size_t p = 0; p < n; ++p)
    if (error[p] >= 0) relative.push_back(rel[p] = error[p] / (mean[p] + offset));
  const double ref = reference_relative_error(std::move(relative));
  if (!(ref > 0)) return asked;
  for (size_t p = 0; p < n; ++p)
    if (rel[p] >= 0) asked[p] = float(rel[p] / ref);
  return asked;
}

}  // namespace bpm
