// Stage 3 of a bpm iteration, the light pass (section 3 of the paper): a fixed number of photons,
// in batches that bound the memory of the recorded entries. Each batch runs in two phases. Phase
// one: photons travel as photons/light_path.h says; at each diffuse hit the hit object's tree gives
// the backward photons whose spheres contain the hit, and each accepted pair is appended as
// (backward photon, contribution) to the lists of its chunk, one list per mask slot. Phase two:
// each slot applies the entries of its own pixels, chunk by chunk in order, so that no locks are
// needed and the sums do not depend on the thread count.
#pragma once
#include <tbb/enumerable_thread_specific.h>

#include <cstdint>
#include <functional>
#include <vector>

#include "base/rng.h"
#include "bpm/backward_maps.h"
#include "bpm/masks.h"
#include "bpm/settings.h"
#include "photons/light_path.h"
#include "scene/render_scene.h"

namespace bpm {

struct PhotonEntry {
  // Index into BackwardMaps::photons, with kInnerBit set when the photon lies within r / sqrt 2 of
  // the backward photon (the inner half of its disc) and kQuarterBit within r / 2 (the inner
  // quarter), for the bias estimate (radius_bias in photons/density.h).
  uint32_t key;
  Spectrum value;  // flux * f * |cos_s| / |cos_g|, before 1 / (pi r^2 N)
  static constexpr uint32_t kInnerBit = 1u << 31, kQuarterBit = 1u << 30;
  static constexpr uint32_t kIndexMask = kQuarterBit - 1;
  uint32_t backward_photon() const { return key & kIndexMask; }
  bool inner() const { return key & kInnerBit; }
  bool quarter() const { return key & kQuarterBit; }
};

struct LightPassParams {
  const WavelengthMaterials* materials = nullptr;  // this iteration's wavelengths
  int max_depth = 5;
  float normal_cos = 0.5f;
  // When the scene has textured materials: each backward photon's material, resolved once at its
  // point (resolve_photon_materials) instead of once per photon that reaches it; may be empty.
  std::vector<Material> photon_materials;
  // Per pixel, 1 / (its estimated value + a floor): a photon's score for the guide is the sum of
  // its contributions weighted so. Empty: photons are not scored.
  const std::vector<float>* pixel_weight = nullptr;
  // A stop request (an interrupt, the time budget), asked before each chunk of photons: once true,
  // the pass ends with the photons traced so far (at least its first chunk). Empty: never.
  std::function<bool()> stop = nullptr;
  // Bytes the entry lists of a batch may hold (the memory budget left after the film and the
  // maps); 0: no limit. A batch that reaches it ends at a chunk and the next batch goes on from
  // there: the image is the same, since entries are applied in photon order whatever the batches.
  size_t entry_bytes_limit = 0;
};

// Fills prm->photon_materials for the backward photons of maps when a material is textured.
void resolve_photon_materials(const BackwardMaps& maps, LightPassParams* prm);

// Traces one photon emitted as `e` says. owner[pixel] is the mask slot of the pixel; out has one
// list per slot. Returns the photon's score for the guide (zero when params.pixel_weight is null).
float trace_photon(const RenderScene& scene, const BackwardMaps& maps,
                   const LightPassParams& params, const std::vector<uint16_t>& owner,
                   const EmissionDraw& e, Rng& rng, std::vector<std::vector<PhotonEntry>>& out,
                   LightCounters& counters);

// What the light pass keeps between iterations: the entry lists and photon scores of each chunk
// of a batch and the per-thread counters.
struct LightPassBuffers {
  std::vector<std::vector<std::vector<PhotonEntry>>> chunks;  // [chunk][slot]
  std::vector<std::vector<CellScore>> scores;                 // [chunk]
  tbb::enumerable_thread_specific<LightCounters> counters;
};

struct LightPassResult {
  std::vector<Spectrum> flux;          // per backward photon: the sum of its entries' values
  std::vector<Spectrum> flux_inner;    // the same over the entries of its inner half (inner())
  std::vector<Spectrum> flux_quarter;  // and of its inner quarter (quarter())
  uint64_t emitted = 0;                // photons emitted, N of eq. (2)
  bool cut = false;                    // a stop request ended the pass before all its photons
  int batches = 0;
  // Fraction of the backward photons accepting indirect light that were hit (a statistic only).
  double coverage = 0;
  double trace_s = 0, apply_s = 0;
  size_t peak_entry_bytes = 0;
};

// Photons per batch: the entries of one batch are held in memory until they are applied.
constexpr uint64_t kPhotonsPerBatch = 100000;

// Shoots settings.photons_per_iteration photons (streams keyed by seed, pass_index and photon
// index) in batches of kPhotonsPerBatch (fewer when params.entry_bytes_limit ends one early); stops
// early, at a chunk, when params.stop says so. With a guide the photons start where it sends them,
// and with params.pixel_weight as well their scores are added to it (learning does not change its
// density until its update).
LightPassResult run_light_pass(const RenderScene& scene, const BackwardMaps& maps,
                               const LightPassParams& params, const BpmSettings& settings,
                               const PixelMasks& masks, uint64_t seed, int pass_index,
                               LightPassBuffers* buffers, EmissionGuide* guide = nullptr);

}  // namespace bpm
