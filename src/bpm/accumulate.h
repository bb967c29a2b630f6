// Stage 4 of a bpm iteration: every sampled pixel's estimate, the eye pass's part plus what its
// backward photons gathered (eq. 2), joins the film as one pass; the film's per-pixel moments give
// the error estimate (eq. 5, 4).
#pragma once
#include <cstdint>
#include <vector>

#include "bpm/backward_maps.h"
#include "bpm/eye_pass.h"
#include "bpm/light_pass.h"
#include "film/film.h"

namespace bpm {

// light_sums->flux[g]: the summed contributions backward photon g received from the pass's
// `emitted` photons (where reached[g]); with those from the inner discs, each pixel's bias estimate
// of the pass over its photon part (radius_bias under bias_model) goes to the film beside its
// estimate, or with `debias` is taken from it. When `estimates` is given (2 per pixel), each
// sampled pixel's estimate (the mean over its wavelengths) is added to its first and 1 to its
// second. Where the pixel sees emission, the estimate less its emission part goes to its round
// statistics (EyePixels::round_stats), and so does whether its small and its other discs received
// light (SampleStats::add_lit).
//
// The light pass's sums are used up: afterwards flux[g] and flux_inner[g] hold backward photon g's
// parts of its pixel's estimate and bias (its shares), where it received light.
//
// `sums` holds, per pixel, its backward photons that received light (kept from one iteration to
// the next, so that its memory is allocated once): `places` of them per pixel at most (one per
// BackwardPhoton::place), kMaxBackwardPhotonsPerPath.
struct PixelSums {
  static constexpr uint32_t kNone = ~0u;
  int places = 0;
  std::vector<uint32_t> by_place;  // [pixel * places + bp.place]: g, or kNone
};

// Per pixel, sums over iterations of what the choice of the photon count reads (bpm_integrator):
// the estimate L (the mean over its wavelengths) and its square, the variance of its photon part
// over the light pass alone, and that variance times the photons emitted (the variance of one
// photon's share), and the iterations summed.
struct PixelMoments {
  static constexpr size_t kValues = 5;
  enum : size_t { kSum, kSquares, kPhotonVariance, kPhotonVarianceTimesN, kCount };
};

// `moments` (PixelMoments::kValues per pixel), when given, gets each sampled pixel's sums, and its
// round statistics 1 / the direct samples it took (SampleStats::add_direct_taken). The
// photon part's variance over the light pass is (A - B)^2, A and B the parts that the photons of
// even and of odd index brought (LightPassResult::flux_odd): two independent halves of the pass.
// mean_filter_weight: what the pixels' camera samples' filter weights average
// (Filter::mean_weight), for the camera connections' sums (LightPassResult::camera).
void accumulate_iteration(const BackwardMaps& maps, LightPassResult* light_sums, EyePixels* eye,
                          const Wavelengths& wl, float max_component_value,
                          const PhotonSettings& settings, Film* film, PixelSums* sums,
                          std::vector<double>* estimates = nullptr,
                          std::vector<double>* moments = nullptr, float mean_filter_weight = 1);

// Per pixel, from its PixelMoments sums, an estimate of the rate of iterations that its error
// asks for under adaptive sampling (RenderControl samples a pixel with that probability, within
// [its floor, 1]): the relative error of its mean so far (over the mean plus 1% of the pixels'
// mean) over the 90th percentile's. The control's own figure weighs the film's three channels,
// this one the mean over the wavelengths: colour noise counts less here. -1 where the pixel has
// fewer estimates than the control waits for (kWarmupPasses) or all of them were black (the
// control samples such a pixel every pass).
std::vector<float> asked_pass_rates(const std::vector<double>& moments);

}  // namespace bpm
