// Stage 3b of a bpm iteration: the probes of the discs that may be cut (photons/disc_probes.h),
// cast after the light pass and only for the backward photons that gathered light. The share of a
// disc where photons can land divides what the disc gathered (accumulate.h); a disc that gathered
// nothing needs none. Most backward photons gather nothing in an iteration (they are many and the
// photons few), so this costs a fraction of probing every disc in the eye pass, and the estimate
// is the same in expectation.
#pragma once
#include <tbb/enumerable_thread_specific.h>

#include <cstdint>

#include "bpm/backward_maps.h"
#include "bpm/eye_pass.h"
#include "bpm/light_pass.h"

namespace bpm {

// Probes the disc of every backward photon of `maps` whose probes are pending
// (BackwardPhoton::probes_pending) and that received light in `light` (as accumulate_iteration
// reads it), and records what they found in its disc_found and disc_cut. Each disc's probes draw
// from a stream keyed by the seed, the iteration and the backward photon's pixel and place, so that
// the result depends on no thread. The rays count as the eye pass's probe rays (`counters`).
void probe_lit_discs(const RenderScene& scene, const LightPassResult& light, float normal_cos,
                     uint64_t seed, int iteration, BackwardMaps* maps,
                     tbb::enumerable_thread_specific<EyeCounters>* counters);

}  // namespace bpm
