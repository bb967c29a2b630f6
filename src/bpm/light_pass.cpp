#include "bpm/light_pass.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include "base/error.h"
#include "photons/density.h"
#include "photons/disc_probes.h"
#include "photons/medium_cuts.h"

namespace bpm {
namespace {

// Domain separation of photon streams from pixel streams.
constexpr uint64_t kPhotonStream = 0x70686f746f6e73ull;

// The part of a photon's score for the guide of an entry of `value` (before 1 / (pi r^2 N)) at
// backward photon bp: 0 when prm.pixel_weight is not set. `bp` is the backward photon's record,
// or its sphere's (MediumSphere): its radius, pixel and tau are read.
template <class Record>
float entry_score(const Record& bp, const Spectrum& value, const LightPassParams& prm) {
  if (!prm.pixel_weight) return 0;
  return (bp.tau * value).average() * (*prm.pixel_weight)[bp.pixel] / (kPi * bp.radius * bp.radius);
}

// Appends backward photon g's entry for a photon (or a beam's nearest point) at squared distance d2
// from its centre with `value`, to the list of the slot that owns its pixel. Returns the entry's
// score (entry_score).
template <class Record>
float add_entry(const Record& bp, uint32_t g, float d2, const Spectrum& value, uint32_t photon,
                const LightPassParams& prm, const std::vector<uint16_t>& owner,
                std::vector<std::vector<PhotonEntry>>& out) {
  const float r2 = bp.radius * bp.radius;
  const uint32_t bits = (2 * d2 < r2 ? PhotonEntry::kInnerBit : 0u) |
                        (4 * d2 < r2 ? PhotonEntry::kQuarterBit : 0u) |
                        (photon & 1 ? PhotonEntry::kOddBit : 0u);
  out[owner[bp.pixel]].push_back({g | bits, value});
  return entry_score(bp, value, prm);
}

// The weight of merging photon hit h (whose path may be combined) at backward photon bp: against
// the eye path's continuation where it went on from there (photons/merge_weights.h: the eye's BSDF
// density there of the photon's direction against the merge's pi r^2 N), and against the vertex
// connections where bp is their target (bpm/vertex_connections.h).
float combined_merge_weight(const BackwardPhoton& bp, const Material& m, const PendingHit& h,
                            const LightPassParams& prm) {
  double others = 0;
  if (bp.combined) {
    const Frame frame = Frame::from_z(bp.ns);
    const Vec3 wo = frame.to_local(bp.wo);
    // The lobes the eye path gathered with at x (choose_eye_vertex).
    const BsdfPart part =
        bsdf_traced_part_probability(m, wo) == 0 ? BsdfPart::kAll : BsdfPart::kGathered;
    const float p = bsdf_pdf(m, wo, frame.to_local(h.wi), TransportMode::kRadiance, part);
    const double density =
        std::ldexp(kPi * double(bp.radius) * bp.radius * prm.merge_photons, bp.continue_level);
    others += double(h.merge_factor) * p / density;
  }
  if (prm.vertex && bp.vertex_target && h.arrival > 0) {
    if (prm.vertex->alone) return 0;
    others += connection_over_merge(bp.radius, prm.vertex->pixels(), h.arrival);
  }
  return float(1 / (1 + others));
}

// The weight of backward photon g's merges of caustic photons against the camera connections
// (weigh_merges_against_camera): found once, by whichever thread needs it first (they all find
// the same).
float camera_merge_weight(const LightPassParams& prm, uint32_t g, const BackwardPhoton& bp,
                          const Material& m) {
  std::atomic_ref<float> known(prm.camera_weights[g]);
  float w = known.load(std::memory_order_relaxed);
  if (w >= 0) return w;
  w = merges_against_camera(*prm.camera, bp)
          ? merge_weight_against_camera(*prm.scene, *prm.camera, bp, m, prm.materials->wl)
          : 1.0f;
  known.store(w, std::memory_order_relaxed);
  return w;
}

// Adds the entries of one diffuse hit (its query was counted when it was recorded). Returns the
// sum of the entries' contributions to their pixels (per unit of 1 / N), each times the pixel's
// weight, when prm.pixel_weight is set.
float gather_at_hit(const BackwardMaps& maps, const LightPassParams& prm,
                    const std::vector<uint16_t>& owner, const PendingHit& h,
                    std::vector<std::vector<PhotonEntry>>& out, LightCounters& counters) {
  float score = 0;
  PathCounters rays;  // photon_cut_off's, added to counters.cut_off_rays
  auto use = [&](uint32_t g) {
    const BackwardPhoton& bp = maps.photons[g];
    if (int(bp.eye_depth) + h.bounces > prm.max_depth) return;
    if (dot(bp.ng, h.ng) < prm.normal_cos) return;
    if (bp.cut_off_tested && prm.scene &&
        photon_cut_off(*prm.scene, bp.p, dot(bp.ng, bp.wo) >= 0 ? bp.ng : -bp.ng, h.p, h.object,
                       bp.radius, prm.normal_cos, rays))
      return;
    // Resolved per backward photon when any material is textured (resolve_photon_materials).
    const Material& m = prm.photon_materials.empty() ? prm.materials->materials[bp.material]
                                                     : prm.photon_materials[g];
    Spectrum value = photon_contribution(m, h.ng, bp.ns, bp.wo, h.wi, h.flux);
    if (value.is_black()) return;
    value *= hero_join_factor(bp.hero_only, h.hero_only);
    if (h.merge_factor > 0 || h.arrival > 0) {
      value *= combined_merge_weight(bp, m, h, prm);
      if (prm.vertex && value.is_black()) return;
    }
    if (prm.camera && h.cls == PhotonClass::kCaustic) {
      value *= camera_merge_weight(prm, g, bp, m);
      if (value.is_black()) return;
    }
    score += add_entry(bp, g, length_squared(h.p - bp.p), value, h.photon, prm, owner, out);
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
  maps.query_bucket(h.bucket, h.object, h.cls, h.p, [&](uint32_t g) {
    if (n_found == kFetched) use_found();
    found[n_found++] = g;
    const char* record = reinterpret_cast<const char*>(&maps.photons[g]);
    __builtin_prefetch(record);
    __builtin_prefetch(record + sizeof(BackwardPhoton) - 1);
  });
  use_found();
  counters.cut_off_rays += rays.probe_rays;
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
    if (bp.medium >= 0) return;  // no material in a medium
    Material storage;
    prm->photon_materials[g] = wm.at(int(bp.material), TextureContext{bp.p, bp.uv}, storage);
  });
}

void weigh_merges_against_camera(const BackwardMaps& maps, const CameraConnections& camera,
                                 LightPassParams* prm) {
  prm->camera = &camera;
  prm->camera_weights.assign(maps.photons.size(), -1.0f);
}

namespace {

// Bytes the entry lists of one chunk hold.
size_t chunk_bytes(const std::vector<std::vector<PhotonEntry>>& by_slot) {
  size_t b = 0;
  for (const auto& v : by_slot) b += v.capacity() * sizeof(PhotonEntry);
  return b;
}

// Bytes the entry lists of all the chunks hold.
size_t lists_bytes(const LightPassBuffers& buf) {
  size_t b = 0;
  for (const auto& by_slot : buf.chunks) b += chunk_bytes(by_slot);
  return b;
}

struct TraceResult {
  uint64_t kept = 0;     // photons traced, from the group's first one
  int chunks = 0;        // the chunks that traced them
  bool stopped = false;  // prm.stop ended the trace (and the pass)
};

// What the chunks of a group share: the photons' streams (seed, pass, the group's first photon),
// the group's photon count, and where their hits go.
struct GroupTrace {
  const RenderScene& scene;
  const BackwardMaps& maps;
  const LightPassParams& prm;
  uint64_t seed;
  int pass_index;
  uint64_t first_photon, count;
  const EmissionGuide* guide;
  bool scored;  // the emissions are recorded for the guide's scores
};

// A caustic photon's hit joined to the camera (camera_connections.h), on a surface that is not a
// curve (where eye paths never gather).
void connect_hit_to_camera(const RenderScene& scene, const CameraConnections& camera,
                           const WavelengthMaterials& wm, const PhotonHit& h, bool odd,
                           LightCounters& lc, std::vector<CameraHit>& hits) {
  const Object& object = scene.objects[size_t(h.object)];
  if (std::holds_alternative<Curves>(object.shape)) return;
  Material storage;
  const Material& m = wm.at(object.material, texture_context(h.sp), storage);
  const size_t before = hits.size();
  connect_to_camera(scene, camera, m, h.sp, h.wi, h.flux, h.hero_only, odd, wm.wl, &lc.camera_rays,
                    hits);
  lc.camera_hits += hits.size() - before;
}

// Domain separation of the streams that draw the pixels of vertex connections.
constexpr uint64_t kVertexStream = 0x766572746578ull;

// A photon's vertex joined to the target of a pixel drawn at random (vertex_connections.h), from
// a stream keyed by the photon and its bounces.
void connect_hit_to_eye_vertex(const GroupTrace& g, uint64_t photon, const PhotonHit& h, bool odd,
                               LightCounters& lc, std::vector<VertexHit>& out) {
  const VertexConnections& vc = *g.prm.vertex;
  Rng rng(stream_key(g.seed ^ kVertexStream, uint64_t(g.pass_index), photon, uint64_t(h.bounces)));
  // Uniform over the P pixels for any P below 2^32 (the top 32 bits of a 32-by-32-bit product: at
  // most one draw in 2^32 / P apart between pixels).
  const uint32_t pixel = uint32_t((uint64_t(rng.next_u32()) * uint64_t(vc.target.size())) >> 32);
  const uint32_t target = vc.target[pixel];
  if (target == VertexConnections::kNone) return;
  const BackwardPhoton& bp = g.maps.photons[target];
  const WavelengthMaterials& wm = *g.prm.materials;
  Material storage;
  const Material& m_z =
      wm.at(g.scene.objects[size_t(h.object)].material, texture_context(h.sp), storage);
  const Material& m_x =
      g.prm.photon_materials.empty() ? wm.materials[bp.material] : g.prm.photon_materials[target];
  const size_t before = out.size();
  connect_to_eye_vertex(g.scene, vc, h, m_z, bp, pixel, m_x, g.prm.max_depth, odd, wm.wl,
                        &lc.vertex_rays, out);
  lc.vertex_hits += out.size() - before;
}

// Traces chunk c of the group, recording its photons' hits and emissions and its counters.
void trace_chunk(const GroupTrace& g, int c, LightPassBuffers* buf) {
  const RenderScene& scene = g.scene;
  const BackwardMaps& maps = g.maps;
  const EmissionGuide* guide = g.guide;
  LightCounters lc;
  lc.observer = buf->counters.local().observer;
  // Filled through lists of this thread's own (their memory taken from the chunk's, and given
  // back): neighbouring chunks' list headers share cache lines, and other threads fill those.
  std::vector<PendingHit> hits;
  std::vector<EmittedPhoton> emitted;
  hits.swap(buf->hits[size_t(c)]);
  emitted.swap(buf->emitted[size_t(c)]);
  hits.clear();
  emitted.clear();
  const SensorDiscs* sensors = g.prm.sensors;
  std::vector<SensorCrossing>& crossings = buf->crossings[size_t(c)];
  crossings.clear();
  std::vector<PendingBeam>& beams = buf->beams[size_t(c)];
  beams.clear();
  std::vector<CameraHit>& camera_hits = buf->camera_hits[size_t(c)];
  camera_hits.clear();
  const CameraConnections* camera = g.prm.camera;
  std::vector<VertexHit>& vertex_hits = buf->vertex_hits[size_t(c)];
  vertex_hits.clear();
  const bool media = g.prm.medium_spheres && !g.prm.medium_spheres->empty();
  const uint64_t first = uint64_t(c) * kPhotonsPerChunk;
  const uint64_t last = std::min(first + kPhotonsPerChunk, g.count);
  auto photon_rng = [&](uint64_t k) {
    return Rng(stream_key(g.seed ^ kPhotonStream, uint64_t(g.pass_index), g.first_photon + k, 1));
  };
  // Each photon's stream is made one photon ahead, so that its part of the guide's table
  // arrives while the photon before it is traced.
  Rng next = photon_rng(first);
  for (uint64_t k = first; k < last; ++k) {
    Rng rng = next;
    if (k + 1 < last) {
      next = photon_rng(k + 1);
      if (guide) guide->prefetch(next);
    }
    const EmissionDraw e = guide ? guide->sample(rng) : unguided_emission(scene, rng);
    const uint32_t photon = uint32_t(k - first);
    // A backward photon adds at least one eye vertex; direct photons are never used
    // (next-event estimation counts direct light).
    auto on_hit = [&](const PhotonHit& h) {
      if (camera && h.cls == PhotonClass::kCaustic && h.medium < 0)
        connect_hit_to_camera(scene, *camera, *g.prm.materials, h, photon & 1, lc, camera_hits);
      if (g.prm.vertex && h.mis)
        connect_hit_to_eye_vertex(g, g.first_photon + k, h, photon & 1, lc, vertex_hits);
      // Photons in media reach the spheres there by their beams (on_beam).
      if (h.cls == PhotonClass::kDirect || h.medium >= 0 || !maps.has_photons(h.object)) return;
      ++lc.queries;
      const uint32_t bucket = maps.bucket_of(h.object, h.cls, h.sp.p);
      if (bucket == BackwardMaps::kNoBucket) return;
      hits.push_back({h.sp.p, h.sp.ng, h.wi, h.flux, bucket, photon, h.object, int16_t(h.bounces),
                      h.cls, h.hero_only, 0.0f, h.merge_factor,
                      h.mis ? h.mis->arrival_density() : 0.0f});
    };
    // Direct beams are never used either (next-event estimation in the medium).
    auto on_beam = [&](const PhotonBeam& b) {
      if (!media || b.cls == PhotonClass::kDirect) return;
      ++lc.beams;
      beams.push_back({b.ray, b.t_max, b.flux, photon, int16_t(b.medium), int16_t(b.bounces), b.cls,
                       b.hero_only});
    };
    trace_light_path(
        scene, *g.prm.materials, g.prm.max_depth, 1, e, rng, lc, on_hit,
        SensorSegments(scene, sensors, g.prm.materials->wl, crossings, g.prm.max_depth), on_beam,
        g.prm.combine || g.prm.vertex);
    if (g.scored) emitted.push_back({e.cell, e.weight});
  }
  buf->hits[size_t(c)].swap(hits);
  buf->emitted[size_t(c)].swap(emitted);
  buf->chunk_counters[size_t(c)] = lc;
}

// What chunk c holds toward a group's cap: its hits and its beams (each at most kHitBytes).
size_t chunk_records(const LightPassBuffers& buf, int c) {
  return buf.hits[size_t(c)].size() + buf.beams[size_t(c)].size();
}

// Workers take chunks in order and stop taking them once the records (chunk_records) of the
// chunks traced reach group_hits, or a stop is requested; at most one chunk per worker is traced
// past the prefix kept. The prefix never needs a chunk no worker took: a worker skips chunk c only
// when the chunks before it that have finished, all of them kept, already hold group_hits records.
// So without a stop request the prefix ends at group_hits or at the group's end. Returns per chunk
// whether it ran.
template <class Stop>
std::vector<uint8_t> trace_chunks_in_order(const GroupTrace& g, int n_chunks, int workers,
                                           uint64_t group_hits, Stop& stop, LightPassBuffers* buf) {
  std::vector<uint8_t> ran(size_t(n_chunks), 0);
  std::atomic<uint64_t> traced{0};
  std::atomic<int> next{0};
  tbb::parallel_for(
      tbb::blocked_range<int>(0, workers, 1),
      [&](const tbb::blocked_range<int>&) {
        for (int c; (c = next.fetch_add(1)) < n_chunks;) {
          if (c > 0 && (stop() || traced.load() >= group_hits)) break;
          trace_chunk(g, c, buf);
          ran[size_t(c)] = 1;
          traced += chunk_records(*buf, c);
        }
      },
      tbb::simple_partitioner());
  return ran;
}

// The longest prefix of the chunks that ran that starts before group_hits records; its counters
// join the thread's.
TraceResult keep_prefix(const std::vector<uint8_t>& ran, int workers, uint64_t count,
                        uint64_t group_hits, LightPassBuffers* buf) {
  const int n_chunks = int(ran.size());
  int kept = 0;
  uint64_t kept_records = 0;
  while (kept < n_chunks && ran[size_t(kept)] && kept_records < group_hits)
    kept_records += chunk_records(*buf, kept++);
  const bool stopped = kept < n_chunks && kept_records < group_hits;
  // A group ended by its records leaves the lists past those it may use unused: their memory, from
  // a larger group, goes back.
  if (kept_records >= group_hits)
    for (size_t c = size_t(kept) + size_t(workers); c < buf->hits.size(); ++c) {
      std::vector<PendingHit>().swap(buf->hits[c]);
      std::vector<EmittedPhoton>().swap(buf->emitted[c]);
      std::vector<SensorCrossing>().swap(buf->crossings[c]);
      std::vector<PendingBeam>().swap(buf->beams[c]);
      std::vector<CameraHit>().swap(buf->camera_hits[c]);
      std::vector<VertexHit>().swap(buf->vertex_hits[c]);
    }
  LightCounters& total = buf->counters.local();
  for (int c = 0; c < kept; ++c) total.add(buf->chunk_counters[size_t(c)]);
  return {std::min(count, uint64_t(kept) * kPhotonsPerChunk), kept, stopped};
}

// Trace: chunks of photons are traced in parallel, each recording its photons' hits and
// emissions (and counters). A group keeps the longest prefix of its chunks that starts before
// group_hits records (hits and beams), so that its memory is bounded whatever the paths and its
// size does not depend on the threads (a chunk traced past the prefix is traced again in the next
// group); or fewer whole chunks when prm.stop ended the trace. The first chunk always runs, except
// after a stop request in a later group.
TraceResult trace_group(const RenderScene& scene, const BackwardMaps& maps,
                        const LightPassParams& prm, uint64_t seed, int pass_index,
                        uint64_t first_photon, uint64_t count, uint64_t group_hits,
                        const EmissionGuide* guide, LightPassBuffers* buf) {
  const int n_chunks = int((count + kPhotonsPerChunk - 1) / kPhotonsPerChunk);
  auto stop = [&] { return prm.stop && prm.stop(); };
  // A pass keeps at least its first chunk: N of eq. (2) is never zero.
  if (first_photon > 0 && stop()) return {0, 0, true};
  if (buf->hits.size() < size_t(n_chunks)) {
    buf->hits.resize(size_t(n_chunks));
    buf->emitted.resize(size_t(n_chunks));
    buf->chunk_counters.resize(size_t(n_chunks));
    buf->crossings.resize(size_t(n_chunks));
    buf->beams.resize(size_t(n_chunks));
    buf->camera_hits.resize(size_t(n_chunks));
    buf->vertex_hits.resize(size_t(n_chunks));
  }
  const GroupTrace g{
      scene, maps, prm, seed, pass_index, first_photon, count, guide, guide && prm.pixel_weight};
  const int workers = tbb::this_task_arena::max_concurrency();
  const std::vector<uint8_t> ran =
      trace_chunks_in_order(g, n_chunks, workers, group_hits, stop, buf);
  return keep_prefix(ran, workers, count, group_hits, buf);
}

// The hits of the first `chunks` chunks in bucket order, and within a bucket in chunk and photon
// order (a counting sort).
void sort_hits(const BackwardMaps& maps, int chunks, LightPassBuffers* buf) {
  std::vector<uint32_t>& start = buf->bucket_start;
  start.assign(size_t(maps.bucket_count()) + 1, 0);
  size_t total = 0;
  for (int c = 0; c < chunks; ++c) {
    for (const PendingHit& h : buf->hits[size_t(c)]) ++start[h.bucket + 1];
    total += buf->hits[size_t(c)].size();
  }
  for (size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
  buf->order.resize(total);
  for (int c = 0; c < chunks; ++c)
    for (PendingHit& h : buf->hits[size_t(c)]) buf->order[start[h.bucket]++] = &h;
}

// Gather: gather chunks from `first` on (gather(g, lists) fills chunk g's lists, one per mask
// slot) add their entries, until all n have run or the entries reach the memory limit (the first
// always runs). Returns how many ran, a prefix (the lists of any past them are emptied: they run
// again in the next round), and the bytes all the lists hold.
struct GatherRound {
  int kept;
  size_t bytes;
};
template <class Gather>
GatherRound gather_round(const LightPassParams& prm, const PixelMasks& masks, int first, int n,
                         const Gather& gather, LightPassBuffers* buf) {
  for (auto& by_slot : buf->chunks) by_slot.resize(size_t(masks.slots()));
  std::atomic<size_t> bytes{lists_bytes(*buf)};
  auto full = [&] { return prm.entry_bytes_limit && bytes.load() > prm.entry_bytes_limit; };
  const int kept = run_chunks_until(n - first, full, [&](int i) {
    std::vector<std::vector<PhotonEntry>>& by_slot = buf->chunks[size_t(first + i)];
    const size_t bytes_before = chunk_bytes(by_slot);
    for (auto& v : by_slot) v.clear();
    gather(first + i, by_slot);
    bytes += chunk_bytes(by_slot) - bytes_before;
  });
  for (int g = first + kept; g < n; ++g)
    for (auto& v : buf->chunks[size_t(g)]) v.clear();
  return {kept, bytes.load()};
}

// Apply: each slot applies the entries of its own pixels, gather chunk by gather chunk in order.
// A backward photon's sums start from zero at its first entry (the arrays are not cleared).
void apply_entries(const std::vector<std::vector<std::vector<PhotonEntry>>>& chunks, int begin,
                   int end, int slots, LightPassResult* res) {
  tbb::parallel_for(tbb::blocked_range<int>(0, slots, 1), [&](const tbb::blocked_range<int>& r) {
    for (int slot = r.begin(); slot < r.end(); ++slot)
      for (int g = begin; g < end; ++g)
        for (const PhotonEntry& e : chunks[size_t(g)][size_t(slot)]) {
          const uint32_t b = e.backward_photon();
          if (!res->reached[b]) {
            res->reached[b] = 1;
            res->flux[b] = res->flux_inner[b] = res->flux_quarter[b] = res->flux_odd[b] =
                Spectrum();
          }
          res->flux[b] += e.value;
          if (e.inner()) res->flux_inner[b] += e.value;
          if (e.quarter()) res->flux_quarter[b] += e.value;
          if (e.odd()) res->flux_odd[b] += e.value;
        }
  });
}

}  // namespace

GroupSize group_size(size_t backward_photons) {
  const uint64_t hits =
      std::clamp<uint64_t>(backward_photons, uint64_t(1) << 17, uint64_t(1) << 20) &
      ~uint64_t(2 * kPhotonsPerChunk - 1);
  return {hits / 2, hits};
}

double light_pass_hit_bytes(int max_depth, int threads, size_t backward_photons, bool beams,
                            bool camera, bool vertex) {
  // The kept chunks' hits with their lists' spare capacity, and a chunk per thread traced past
  // them or kept from an earlier group (max_depth + 1 hits per photon at most, and in scattering
  // media about as many beams, one per stretch of a segment through one medium, each no larger
  // than a hit); the emissions. A camera connection is made at a caustic photon's hit in view, most
  // of which are also hits recorded: counted as many as those. A vertex connection is made at most
  // once per hit, recorded or not (a photon's first hit is not): counted as many as the hits and
  // the photons.
  const GroupSize g = group_size(backward_photons);
  const double per_hit = double(kHitBytes) +
                         (camera ? double(sizeof(CameraHit) + sizeof(CameraHit*)) : 0.0) +
                         (vertex ? double(sizeof(VertexHit)) : 0.0);
  const double per_photon = double(std::max(max_depth, 0) + 1) * (beams ? 2.0 : 1.0);
  return per_hit * (2.0 * double(g.hits) + 2.0 * double(threads) * kPhotonsPerChunk * per_photon) +
         2.0 * double(g.photons) * (sizeof(EmittedPhoton) + (vertex ? sizeof(VertexHit) : 0));
}

namespace {

// Charges every interval of the pass to one stage: the time since the last lap.
class StageClock {
 public:
  void lap(double& stage) {
    const auto now = std::chrono::steady_clock::now();
    stage += std::chrono::duration<double>(now - t_).count();
    t_ = now;
  }

 private:
  std::chrono::steady_clock::time_point t_ = std::chrono::steady_clock::now();
};

// The arrays keep their memory from the last iteration (fresh pages cost a fault each), and
// only the flags are cleared: the sums of a backward photon are set at its first entry.
void reset_result(size_t n_bp, size_t n_pixels, size_t n_vertex_pixels, LightPassResult& res) {
  res.reached.assign(n_bp, 0);
  res.camera.assign(n_pixels, Spectrum());
  res.camera_odd.assign(n_pixels, Spectrum());
  res.vertex.assign(n_vertex_pixels, Spectrum());
  res.vertex_odd.assign(n_vertex_pixels, Spectrum());
  res.flux.resize(n_bp);
  res.flux_inner.resize(n_bp);
  res.flux_quarter.resize(n_bp);
  res.flux_odd.resize(n_bp);
  res.emitted = 0;
  res.cut = false;
  res.batches = 0;
  res.coverage = 0;
  res.trace_s = res.gather_s = res.apply_s = 0;
  res.peak_entry_bytes = 0;
}

// The camera connections of the first `chunks` chunks spread over the pixels: listed per band of
// rows that their filters reach (chunk by chunk in order), then each band in parallel adds its
// hits in that order, so that every pixel's sum does not depend on the threads.
void add_camera_hits(const CameraConnections& cc, int chunks, LightPassBuffers& buf,
                     LightPassResult& res) {
  constexpr int kRows = 8;
  std::vector<std::vector<const CameraHit*>>& bands = buf.camera_bands;
  bands.resize(size_t((cc.height + kRows - 1) / kRows));
  for (auto& b : bands) b.clear();
  for (int c = 0; c < chunks; ++c)
    for (const CameraHit& hit : buf.camera_hits[size_t(c)]) {
      const auto [first, last] = rows_reached(cc, hit);
      for (int b = first / kRows; b <= last / kRows && first <= last; ++b)
        bands[size_t(b)].push_back(&hit);
    }
  tbb::parallel_for(0, int(bands.size()), [&](int b) {
    const int row0 = b * kRows, row1 = std::min(cc.height, row0 + kRows);
    for (const CameraHit* hit : bands[size_t(b)])
      spread_to_pixels(cc, *hit, row0, row1, res.camera.data(), res.camera_odd.data());
  });
}

// The vertex connections of the first `chunks` chunks added to their pixels' sums, chunk by chunk
// in order.
void add_vertex_hits(int chunks, const LightPassBuffers& buf, LightPassResult& res) {
  for (int c = 0; c < chunks; ++c)
    for (const VertexHit& hit : buf.vertex_hits[size_t(c)]) {
      res.vertex[hit.pixel] += hit.value;
      if (hit.odd) res.vertex_odd[hit.pixel] += hit.value;
    }
}

// Rounds of gather and apply over n gather chunks (gather_round's): one, unless the entries reach
// the memory limit; a round keeps a prefix of the chunks and the next goes on from there, so that
// the entries are applied in the same order whatever the rounds.
template <class Gather>
void gather_and_apply(int n, const Gather& gather, const LightPassParams& prm,
                      const PixelMasks& masks, LightPassBuffers* buf, LightPassResult& res,
                      StageClock& clock) {
  if (buf->chunks.size() < size_t(n)) buf->chunks.resize(size_t(n));
  // The lists keep their memory for the next call. Where all of them already hold more than the
  // limit, those past the n chunks (left by a larger group, or by the hits before the beams) give
  // it back first, so that they do not end the first round at its first chunk.
  if (prm.entry_bytes_limit && lists_bytes(*buf) > prm.entry_bytes_limit)
    for (size_t g = size_t(n); g < buf->chunks.size(); ++g)
      for (auto& v : buf->chunks[g]) std::vector<PhotonEntry>().swap(v);
  int done = 0;
  do {
    const GatherRound round =
        n > 0 ? gather_round(prm, masks, done, n, gather, buf) : GatherRound{0, 0};
    const int kept = round.kept;
    size_t entries = 0;
    for (int g = done; g < done + kept; ++g)
      for (const auto& v : buf->chunks[size_t(g)]) entries += v.size();
    res.peak_entry_bytes = std::max(res.peak_entry_bytes, round.bytes);
    buf->counters.local().entries += entries;
    clock.lap(res.gather_s);
    apply_entries(buf->chunks, done, done + kept, masks.slots(), &res);
    clock.lap(res.apply_s);
    ++res.batches;
    done += kept;
    // The limit ended the round: the lists' memory goes back, so that the next round has it.
    if (done < n)
      for (auto& by_slot : buf->chunks)
        for (auto& v : by_slot) std::vector<PhotonEntry>().swap(v);
  } while (done < n);
}

// The sorted hits, kHitsPerGather of `order` per gather chunk.
void gather_and_apply_hits(const BackwardMaps& maps, const LightPassParams& prm,
                           const PixelMasks& masks, LightPassBuffers* buf, LightPassResult& res,
                           StageClock& clock) {
  const size_t n_hits = buf->order.size();
  const int n_gather = int((n_hits + kHitsPerGather - 1) / kHitsPerGather);
  auto gather = [&](int g, std::vector<std::vector<PhotonEntry>>& by_slot) {
    const size_t begin = size_t(g) * kHitsPerGather;
    const size_t end = std::min(n_hits, begin + kHitsPerGather);
    for (size_t k = begin; k < end; ++k) {
      // The hits lie in their chunks' lists, read here out of order: fetched a few ahead.
      if (k + 4 < end) {
        const char* next = reinterpret_cast<const char*>(buf->order[k + 4]);
        __builtin_prefetch(next);
        __builtin_prefetch(next + sizeof(PendingHit) - 1);
      }
      PendingHit& h = *buf->order[k];
      h.score = gather_at_hit(maps, prm, masks.owner(), h, by_slot, buf->counters.local());
    }
  };
  gather_and_apply(n_gather, gather, prm, masks, buf, res, clock);
}

// add_entry for a beam at a sphere whose discs a surface cuts (photons/medium_cuts.h): each nested
// disc's sum is divided by its own share across the beam, as one entry per disc the beam passes
// through, counted in it and the larger ones, so that every sum comes out right.
float add_cut_beam_entries(const MediumSphere& bp, float d2, const Spectrum& value,
                           const PendingBeam& b, const LightPassParams& prm,
                           const std::vector<uint16_t>& owner,
                           std::vector<std::vector<PhotonEntry>>& out) {
  const float r = bp.radius, r2 = r * r, line = cut_line_distance(bp.cut, b.ray.d);
  const Spectrum all = value / disc_share_before(line, r),
                 half = value / disc_share_before(line, r * float(M_SQRT1_2)),
                 quarter = value / disc_share_before(line, r / 2);
  const uint32_t odd = b.photon & 1 ? PhotonEntry::kOddBit : 0u;
  std::vector<PhotonEntry>& list = out[owner[bp.pixel]];
  if (4 * d2 < r2) {
    list.push_back({bp.index | PhotonEntry::kInnerBit | PhotonEntry::kQuarterBit | odd, quarter});
    list.push_back({bp.index | PhotonEntry::kInnerBit | odd, half - quarter});
    list.push_back({bp.index | odd, all - half});
  } else if (2 * d2 < r2) {
    list.push_back({bp.index | PhotonEntry::kInnerBit | odd, half});
    list.push_back({bp.index | odd, all - half});
  } else {
    list.push_back({bp.index | odd, all});
  }
  return entry_score(bp, all, prm);
}

// The entries of one beam: at each sphere it reaches, its flux at the point nearest the centre
// times the phase function toward the sphere's eye path (before 1 / (pi r^2 N), as a hit's).
// Returns the beam's score, as gather_at_hit's.
float gather_beam(const RenderScene& scene, const LightPassParams& prm,
                  const std::vector<uint16_t>& owner, const PendingBeam& b,
                  std::vector<std::pair<const MediumSphere*, float>>& found,
                  std::vector<std::vector<PhotonEntry>>& out) {
  found.clear();
  prm.medium_spheres->query(b.medium, b.cls, b.ray, b.t_max, prm.max_depth - b.bounces, &found);
  if (found.empty()) return 0;
  const Medium& m = scene.media[size_t(b.medium)];
  const Wavelengths& wl = prm.materials->wl;
  // sigma_t once per beam (medium_transmittance would sample it at every sphere), and one
  // exponential per sphere where it is the same at every wavelength (a grey medium).
  const Spectrum sigma_t = m.rgb_grid ? Spectrum() : m.sigma_a.sample(wl) + m.sigma_s.sample(wl);
  const bool grey = sigma_t.max_component() == sigma_t.min_component();
  auto transmittance = [&](float t) {
    if (m.rgb_grid) return medium_transmittance(scene, b.medium, b.ray, t, wl);
    const float tau = m.depth(b.ray, 0, t);
    if (grey) return Spectrum(std::exp(-sigma_t[0] * tau));
    Spectrum T;
    for (int k = 0; k < Spectrum::kChannels; ++k) T[k] = std::exp(-sigma_t[k] * tau);
    return T;
  };
  float score = 0;
  for (const auto& [sphere, t] : found) {
    const MediumSphere& bp = *sphere;
    Spectrum value =
        b.flux * transmittance(t) *
        (henyey_greenstein(dot(bp.wo, b.ray.d), m.g) * hero_join_factor(bp.hero_only, b.hero_only));
    if (value.is_black()) continue;
    const float d2 = length_squared(b.ray.o + b.ray.d * t - bp.p);
    score += length_squared(bp.cut) == 0
                 ? add_entry(bp, bp.index, d2, value, b.photon, prm, owner, out)
                 : add_cut_beam_entries(bp, d2, value, b, prm, owner, out);
  }
  return score;
}

// The beams of the first `chunks` chunks, a trace chunk's per gather chunk, in rounds as the hits'
// (after them, in the same lists: the memory limit holds for both; a round may pass it by about
// a trace chunk's beam entries per thread, coarser than the hits' gather chunks).
void gather_and_apply_beams(const RenderScene& scene, const LightPassParams& prm,
                            const PixelMasks& masks, int chunks, LightPassBuffers* buf,
                            LightPassResult& res, StageClock& clock) {
  if (!prm.medium_spheres || prm.medium_spheres->empty()) return;
  auto gather = [&](int c, std::vector<std::vector<PhotonEntry>>& by_slot) {
    thread_local std::vector<std::pair<const MediumSphere*, float>> found;
    for (PendingBeam& b : buf->beams[size_t(c)])
      b.score = gather_beam(scene, prm, masks.owner(), b, found, by_slot);
  };
  gather_and_apply(chunks, gather, prm, masks, buf, res, clock);
}

// Each photon's score is the sum of its hits' and beams', in the order of its path, as if it had
// been emitted without guidance (weight removed); the guide learns them in photon order.
void learn_scores(int chunks, LightPassBuffers* buf, EmissionGuide& guide) {
  if (buf->scores.size() < size_t(chunks)) buf->scores.resize(size_t(chunks));
  tbb::parallel_for(0, chunks, [&](int c) {
    const std::vector<PendingHit>& hits = buf->hits[size_t(c)];
    const std::vector<PendingBeam>& beams = buf->beams[size_t(c)];
    const std::vector<EmittedPhoton>& emitted = buf->emitted[size_t(c)];
    std::vector<CellScore>& scores = buf->scores[size_t(c)];
    scores.clear();
    size_t j = 0, k = 0;
    for (uint32_t p = 0; p < uint32_t(emitted.size()); ++p) {
      float score = 0;
      for (; j < hits.size() && hits[j].photon == p; ++j) score += hits[j].score;
      for (; k < beams.size() && beams[k].photon == p; ++k) score += beams[k].score;
      scores.push_back({emitted[p].cell, emitted[p].weight > 0 ? score / emitted[p].weight : 0});
    }
  });
  for (int c = 0; c < chunks; ++c) guide.learn(buf->scores[size_t(c)]);
}

// The share of the backward photons that accept indirect light which some photon reached (1 when
// none accepts it).
double coverage(const BackwardMaps& maps, const std::vector<uint8_t>& reached) {
  struct Coverage {
    size_t indirect = 0, covered = 0;
  };
  const Coverage cov = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, maps.photons.size(), 1 << 14), Coverage{},
      [&](const tbb::blocked_range<size_t>& r, Coverage c) {
        for (size_t g = r.begin(); g < r.end(); ++g)
          if (maps.photons[g].accepts & kAcceptsIndirect) {
            ++c.indirect;
            c.covered += reached[g];
          }
        return c;
      },
      [](Coverage a, const Coverage& b) {
        return Coverage{a.indirect + b.indirect, a.covered + b.covered};
      });
  const size_t n_indirect = cov.indirect, covered = cov.covered;
  return n_indirect ? double(covered) / double(n_indirect) : 1.0;
}

}  // namespace

void run_light_pass(const RenderScene& scene, const BackwardMaps& maps, const LightPassParams& prm,
                    const BpmSettings& s, const PixelMasks& masks, uint64_t seed, int pass_index,
                    LightPassBuffers* buf, EmissionGuide* guide, LightPassResult* out) {
  const uint64_t total = uint64_t(s.photons_per_iteration);
  const size_t n_bp = maps.photons.size();
  BPM_CHECK(n_bp <= PhotonEntry::kIndexMask);  // the memory budget refuses far fewer
  LightPassResult& res = *out;
  reset_result(n_bp, prm.camera ? prm.camera->caustic_radius.size() : 0,
               prm.vertex ? prm.vertex->target.size() : 0, res);
  // A stop request (interrupt, time budget) ends the pass at a chunk boundary: N of eq. (2) is
  // then the photons emitted so far.
  const GroupSize group = group_size(n_bp);
  StageClock clock;
  for (uint64_t first = 0; first < total;) {
    const uint64_t count = std::min(group.photons, total - first);
    const TraceResult tr =
        trace_group(scene, maps, prm, seed, pass_index, first, count, group.hits, guide, buf);
    clock.lap(res.trace_s);
    if (tr.kept == 0) {  // stopped before the group began
      res.cut = true;
      break;
    }
    first += tr.kept;
    res.emitted += tr.kept;
    if (prm.sensor_sums)
      for (int c = 0; c < tr.chunks; ++c) prm.sensor_sums->add(buf->crossings[size_t(c)]);
    if (prm.camera) add_camera_hits(*prm.camera, tr.chunks, *buf, res);
    if (prm.vertex) add_vertex_hits(tr.chunks, *buf, res);
    res.cut = tr.stopped;
    sort_hits(maps, tr.chunks, buf);
    gather_and_apply_hits(maps, prm, masks, buf, res, clock);
    gather_and_apply_beams(scene, prm, masks, tr.chunks, buf, res, clock);
    if (guide && prm.pixel_weight) learn_scores(tr.chunks, buf, *guide);
    clock.lap(res.apply_s);
    if (res.cut) break;
  }
  res.coverage = coverage(maps, res.reached);
  clock.lap(res.apply_s);
}

}  // namespace bpm
