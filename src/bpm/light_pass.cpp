#include "bpm/light_pass.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include "base/error.h"
#include "photons/density.h"

namespace bpm {
namespace {

// Domain separation of photon streams from pixel streams.
constexpr uint64_t kPhotonStream = 0x70686f746f6e73ull;

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Adds the entries of one diffuse hit: the photon arrives at sp along -wi with `flux`. Returns
// the sum of the entries' contributions to their pixels (per unit of 1 / N), each times the
// pixel's weight, when prm.pixel_weight is set.
float gather_at_hit(const BackwardMaps& maps, const LightPassParams& prm,
                    const std::vector<uint16_t>& owner, int object, const SurfacePoint& sp, Vec3 wi,
                    const Spectrum& flux, PhotonClass cls, int bounces, bool hero_only,
                    std::vector<std::vector<PhotonEntry>>& out, LightCounters& counters) {
  float score = 0;
  ++counters.queries;
  auto use = [&](uint32_t g) {
    const BackwardPhoton& bp = maps.photons[g];
    if (int(bp.eye_depth) + bounces > prm.max_depth) return;
    if (dot(bp.ng, sp.ng) < prm.normal_cos) return;
    // Resolved per backward photon when any material is textured (resolve_photon_materials).
    const Material& m = prm.photon_materials.empty() ? prm.materials->materials[bp.material]
                                                     : prm.photon_materials[g];
    Spectrum value = photon_contribution(m, bp.ng, bp.ns, bp.wo, wi, flux);
    if (value.is_black()) return;
    value *= hero_join_factor(bp.hero_only, hero_only);
    const float d2 = length_squared(sp.p - bp.p), r2 = bp.radius * bp.radius;
    const uint32_t bits =
        (2 * d2 < r2 ? PhotonEntry::kInnerBit : 0u) | (4 * d2 < r2 ? PhotonEntry::kQuarterBit : 0u);
    out[owner[bp.pixel]].push_back({g | bits, value});
    ++counters.entries;
    if (prm.pixel_weight)
      score += (bp.tau * value).average() * (*prm.pixel_weight)[bp.pixel] /
               (kPi * bp.radius * bp.radius);
  };
  // The backward photons found are fetched in groups before any is used: each record is likely a
  // cache miss, and their misses then overlap. They are used in the order the query found them.
  constexpr int kFetched = 32;
  uint32_t found[kFetched];
  int n_found = 0;
  auto use_found = [&] {
    for (int k = 0; k < n_found; ++k) use(found[k]);
    n_found = 0;
  };
  maps.query(object, cls, sp.p, [&](uint32_t g) {
    if (n_found == kFetched) use_found();
    found[n_found++] = g;
    const char* record = reinterpret_cast<const char*>(&maps.photons[g]);
    __builtin_prefetch(record);
    __builtin_prefetch(record + sizeof(BackwardPhoton) - 1);
  });
  use_found();
  return score;
}

}  // namespace

void resolve_photon_materials(const BackwardMaps& maps, LightPassParams* prm) {
  prm->photon_materials.clear();
  const WavelengthMaterials& wm = *prm->materials;
  if (!wm.per_point &&
      std::none_of(wm.textured.begin(), wm.textured.end(), [](char t) { return t != 0; }))
    return;
  prm->photon_materials.resize(maps.photons.size());
  tbb::parallel_for(size_t(0), maps.photons.size(), [&](size_t g) {
    const BackwardPhoton& bp = maps.photons[g];
    Material storage;
    prm->photon_materials[g] = wm.at(int(bp.material), TextureContext{bp.p, bp.uv}, storage);
  });
}

float trace_photon(const RenderScene& scene, const BackwardMaps& maps, const LightPassParams& prm,
                   const std::vector<uint16_t>& owner, const EmissionDraw& e, Rng& rng,
                   std::vector<std::vector<PhotonEntry>>& out, LightCounters& counters) {
  // A backward photon adds at least one eye vertex; direct photons are never used (next-event
  // estimation counts direct light).
  float score = 0;
  trace_light_path(scene, *prm.materials, prm.max_depth, 1, e, rng, counters,
                   [&](const PhotonHit& h) {
                     if (h.cls != PhotonClass::kDirect && maps.has_photons(h.object))
                       score += gather_at_hit(maps, prm, owner, h.object, h.sp, h.wi, h.flux, h.cls,
                                              h.bounces, h.hero_only, out, counters);
                   });
  // The score as if the photon had been emitted without guidance.
  return e.weight > 0 ? score / e.weight : 0;
}

namespace {

// Bytes the entry lists of one chunk hold.
size_t chunk_bytes(const std::vector<std::vector<PhotonEntry>>& by_slot) {
  size_t b = 0;
  for (const auto& v : by_slot) b += v.capacity() * sizeof(PhotonEntry);
  return b;
}

struct BatchResult {
  uint64_t kept = 0;     // photons traced into the lists, from the batch's first one
  bool stopped = false;  // prm.stop ended the batch (and the pass)
};

// Phase one of a batch: every chunk traces its photons into its own lists. The photons kept are
// all `count`, or a prefix of whole chunks when prm.stop or prm.entry_bytes_limit ended the batch
// early (the lists of the chunks past them are emptied). The first chunk always runs, except
// after a stop request in a later batch.
BatchResult trace_batch(const RenderScene& scene, const BackwardMaps& maps,
                        const LightPassParams& prm, const PixelMasks& masks, uint64_t seed,
                        int pass_index, uint64_t first_photon, uint64_t count,
                        const EmissionGuide* guide, LightPassBuffers* buf) {
  const int slots = masks.slots();
  const int n_chunks = int((count + kPhotonsPerChunk - 1) / kPhotonsPerChunk);
  auto stop = [&] { return prm.stop && prm.stop(); };
  // A pass keeps at least its first chunk: N of eq. (2) is never zero.
  if (first_photon > 0 && stop()) return {0, true};
  // What every chunk's lists hold now (they keep their capacity from earlier batches). Every chunk
  // has its slots, also one that does not run (phase two reads them all).
  std::atomic<size_t> entry_bytes{0};
  for (auto& by_slot : buf->chunks) {
    by_slot.resize(size_t(slots));
    entry_bytes += chunk_bytes(by_slot);
  }
  auto full = [&] { return prm.entry_bytes_limit && entry_bytes.load() > prm.entry_bytes_limit; };
  const int kept = run_chunks_until(
      n_chunks, [&] { return stop() || full(); },
      [&](int c) {
        LightCounters& lc = buf->counters.local();
        std::vector<std::vector<PhotonEntry>>& by_slot = buf->chunks[size_t(c)];
        const size_t bytes_before = chunk_bytes(by_slot);
        for (auto& v : by_slot) v.clear();
        std::vector<CellScore>& scores = buf->scores[size_t(c)];
        scores.clear();
        uint64_t first = uint64_t(c) * kPhotonsPerChunk;
        uint64_t last = std::min(first + kPhotonsPerChunk, count);
        for (uint64_t k = first; k < last; ++k) {
          uint64_t index = first_photon + k;
          Rng rng(stream_key(seed ^ kPhotonStream, uint64_t(pass_index), index, 1));
          const EmissionDraw e = guide ? guide->sample(rng) : unguided_emission(scene, rng);
          float score = trace_photon(scene, maps, prm, masks.owner(), e, rng, by_slot, lc);
          if (guide && prm.pixel_weight) scores.push_back({e.cell, score});
        }
        entry_bytes += chunk_bytes(by_slot) - bytes_before;
      });
  BatchResult r;
  r.kept = std::min(count, uint64_t(kept) * kPhotonsPerChunk);
  r.stopped = kept < n_chunks && stop();
  const bool full_batch_cut = kept < n_chunks && !r.stopped;
  for (int c = kept; c < int(buf->chunks.size()); ++c) {
    for (auto& v : buf->chunks[size_t(c)]) {
      v.clear();
      // Past a batch the entry limit ended, the memory goes back, so that the next one fits.
      if (full_batch_cut) v.shrink_to_fit();
    }
    buf->scores[size_t(c)].clear();
  }
  return r;
}

// Phase two: each slot applies the entries of its own pixels, chunk by chunk in order.
void apply_batch(const LightPassBuffers& buf, int slots, LightPassResult* res,
                 std::vector<uint8_t>* hit) {
  tbb::parallel_for(tbb::blocked_range<int>(0, slots, 1), [&](const tbb::blocked_range<int>& r) {
    for (int slot = r.begin(); slot < r.end(); ++slot)
      for (const auto& by_slot : buf.chunks)
        for (const PhotonEntry& e : by_slot[size_t(slot)]) {
          const uint32_t g = e.backward_photon();
          res->flux[g] += e.value;
          if (e.inner()) res->flux_inner[g] += e.value;
          if (e.quarter()) res->flux_quarter[g] += e.value;
          (*hit)[g] = 1;
        }
  });
}

}  // namespace

LightPassResult run_light_pass(const RenderScene& scene, const BackwardMaps& maps,
                               const LightPassParams& prm, const BpmSettings& s,
                               const PixelMasks& masks, uint64_t seed, int pass_index,
                               LightPassBuffers* buf, EmissionGuide* guide) {
  const uint64_t total = uint64_t(s.photons_per_iteration);
  const size_t n_bp = maps.photons.size();
  BPM_CHECK(n_bp <= PhotonEntry::kIndexMask);  // the memory budget refuses far fewer
  LightPassResult res;
  res.flux.assign(n_bp, Spectrum());
  res.flux_inner.assign(n_bp, Spectrum());
  res.flux_quarter.assign(n_bp, Spectrum());
  std::vector<uint8_t> hit(n_bp, 0);
  // A stop request (interrupt, time budget) ends the pass at a chunk boundary: N of eq. (2) is
  // then the photons emitted so far.
  for (uint64_t first = 0; first < total;) {
    const uint64_t count = std::min(kPhotonsPerBatch, total - first);
    // Sized for a whole batch, so that a shorter last batch keeps the lists' memory (its chunks
    // past `count` stay empty).
    const uint64_t batch = std::min(kPhotonsPerBatch, total);
    buf->chunks.resize(size_t((batch + kPhotonsPerChunk - 1) / kPhotonsPerChunk));
    buf->scores.resize(buf->chunks.size());
    auto t = std::chrono::steady_clock::now();
    const BatchResult b =
        trace_batch(scene, maps, prm, masks, seed, pass_index, first, count, guide, buf);
    if (b.kept == 0) {  // stopped before the batch began: the lists hold the last one's entries
      res.cut = true;
      break;
    }
    first += b.kept;
    res.emitted += b.kept;
    res.cut = b.stopped;
    ++res.batches;
    res.trace_s += seconds_since(t);
    size_t entry_bytes = 0;
    for (const auto& by_slot : buf->chunks)
      for (const auto& v : by_slot) entry_bytes += v.capacity() * sizeof(PhotonEntry);
    res.peak_entry_bytes = std::max(res.peak_entry_bytes, entry_bytes);

    t = std::chrono::steady_clock::now();
    apply_batch(*buf, masks.slots(), &res, &hit);
    if (guide && prm.pixel_weight)
      for (const std::vector<CellScore>& s : buf->scores) guide->learn(s);
    res.apply_s += seconds_since(t);
    if (res.cut) break;
    // A batch the entry limit ended: its lists go back too, so that the next batch has the whole
    // limit (kept, they would leave it room for one chunk).
    if (b.kept < count)
      for (auto& by_slot : buf->chunks)
        for (auto& v : by_slot) std::vector<PhotonEntry>().swap(v);
  }
  size_t n_indirect = 0, covered = 0;
  for (size_t g = 0; g < n_bp; ++g)
    if (maps.photons[g].accepts & kAcceptsIndirect) {
      ++n_indirect;
      covered += hit[g];
    }
  res.coverage = n_indirect ? double(covered) / double(n_indirect) : 1.0;
  return res;
}

}  // namespace bpm
