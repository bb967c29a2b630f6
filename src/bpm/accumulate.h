// Stage 4 of a bpm iteration: every sampled pixel's estimate, the eye pass's part plus what its
// backward photons gathered (eq. 2), joins the film as one pass; the film's per-pixel moments give
// the error estimate (eq. 5, 4).
#pragma once
#include <cstdint>
#include <vector>

#include "bpm/backward_maps.h"
#include "bpm/eye_pass.h"
#include "film/film.h"

namespace bpm {

// flux[g]: the summed contributions backward photon g received from `emitted` photons, and
// flux_inner[g] those from within r / sqrt 2: each pixel's bias estimate of the pass,
// 2 (L(r) - L(r / sqrt 2)) over its photon part, goes to the film beside its estimate. When
// `estimates` is given, each sampled pixel's estimate (the mean over its wavelengths) is added to
// it and that pixel's count in `counts` incremented.
void accumulate_iteration(const BackwardMaps& maps, const std::vector<Spectrum>& flux,
                          const std::vector<Spectrum>& flux_inner, uint64_t emitted,
                          const EyePixels& eye, const Wavelengths& wl, float max_component_value,
                          bool debias, Film* film, std::vector<double>* estimates = nullptr,
                          std::vector<uint32_t>* counts = nullptr);

}  // namespace bpm
