// Stage 3 of a bpm iteration, the light pass (section 3 of the paper): a fixed number of photons,
// in groups that bound the memory of what is recorded. Each group runs in three phases.
// Trace: photons travel as photons/light_path.h says, in chunks; each chunk records the diffuse
// hits of its photons, with the bucket each hit's query falls in (a leaf of the hit object's
// sphere tree; a whole centre tree). Gather: the group's hits, sorted by bucket, are queried in
// that order, so that a leaf and the backward photons it holds are read from cache by all the
// hits that fall in it instead of being fetched from memory hit after hit; each accepted pair is
// appended as (backward photon, contribution) to the lists of its gather chunk, one list per mask
// slot. Apply: each slot applies the entries of its own pixels, gather chunk by gather chunk in
// order, so that no locks are needed and the sums do not depend on the thread count.
#pragma once
#include <tbb/enumerable_thread_specific.h>

#include <cstdint>
#include <functional>
#include <vector>

#include "base/rng.h"
#include "bpm/backward_maps.h"
#include "bpm/camera_connections.h"
#include "bpm/masks.h"
#include "bpm/medium_spheres.h"
#include "bpm/settings.h"
#include "bpm/vertex_connections.h"
#include "photons/light_path.h"
#include "photons/sensor_discs.h"
#include "scene/render_scene.h"

namespace bpm {

struct PhotonEntry {
  // Index into BackwardMaps::photons, with kInnerBit set when the photon lies within r / sqrt 2 of
  // the backward photon (the inner half of its disc) and kQuarterBit within r / 2 (the inner
  // quarter), for the bias estimate (radius_bias in photons/density.h).
  // kOddBit marks an entry of a photon of odd index in its chunk: the two halves of the photons
  // estimate the light pass's own variance (LightPassResult::flux_odd).
  uint32_t key;
  Spectrum value;  // flux * f * |wi.ns| / |wi.ng of the photon's hit|, before 1 / (pi r^2 N)
  static constexpr uint32_t kInnerBit = 1u << 31, kQuarterBit = 1u << 30, kOddBit = 1u << 29;
  static constexpr uint32_t kIndexMask = kOddBit - 1;
  uint32_t backward_photon() const { return key & kIndexMask; }
  bool inner() const { return key & kInnerBit; }
  bool quarter() const { return key & kQuarterBit; }
  bool odd() const { return key & kOddBit; }
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
  // the pass ends with the photons traced so far (at least its first chunk), once their group is
  // gathered. Empty: never.
  std::function<bool()> stop = nullptr;
  // Bytes the entry lists of a group may hold (the memory budget left after the film, the maps
  // and a group's hits); 0: no limit. A group whose entries reach it applies them, frees them and
  // goes on gathering, in the same order: the image is the same.
  size_t entry_bytes_limit = 0;
  // Illuminance sensors: the photons' crossings of their discs are added to sensor_sums, chunk by
  // chunk in order. Null: none.
  const SensorDiscs* sensors = nullptr;
  SensorIteration* sensor_sums = nullptr;
  // The backward photons in scattering media, which gather the photons' beams. Null: none.
  const MediumSpheres* medium_spheres = nullptr;
  // The scene, for the rays that test whether a photon is cut off from a backward photon whose
  // disc has geometry near (BackwardPhoton::cut_off_tested). Null: no test.
  const RenderScene* scene = nullptr;
  // Combined estimators (photons/merge_weights.h): the photons carry their merge factors, and
  // each merge at a backward photon whose eye path went on is weighed, with N = merge_photons.
  bool combine = false;
  double merge_photons = 0;
  // Caustic photons joined to the camera (bpm/camera_connections.h), their merges at the discs
  // seen directly weighed against that: per backward photon, the weight of its merges of caustic
  // photons, or -1 until it is needed (weigh_merges_against_camera; the gather's threads set it
  // through atomic references). Null: none.
  const CameraConnections* camera = nullptr;
  mutable std::vector<float> camera_weights{};
  // Photons' vertices joined to eye vertices (bpm/vertex_connections.h), and the merges at the
  // targets weighed against that. Null: none.
  const VertexConnections* vertex = nullptr;
};

// Fills prm->photon_materials for the backward photons of maps when a material is textured.
void resolve_photon_materials(const BackwardMaps& maps, LightPassParams* prm);

// Sets prm->camera, and prm->camera_weights to "not yet known" for each backward photon of maps:
// the gather finds a weight the first time a caustic photon reaches its backward photon
// (merge_weight_against_camera where merges_against_camera, else 1), so that an iteration whose
// caustic photons land nowhere in view costs nothing.
void weigh_merges_against_camera(const BackwardMaps& maps, const CameraConnections& camera,
                                 LightPassParams* prm);

// A diffuse hit of a photon, waiting for its gather.
struct PendingHit {
  Vec3 p, ng, wi;  // the hit, its geometric normal, toward where the photon came from
  Spectrum flux;
  uint32_t bucket;  // BackwardMaps::bucket_of the hit's query
  uint32_t photon;  // the photon's index in its chunk
  int object;
  int16_t bounces;
  PhotonClass cls;
  bool hero_only;
  float score = 0;         // set by the gather: the hit's part of its photon's score for the guide
  float merge_factor = 0;  // PhotonHit's
  float arrival = 0;       // PhotonMis::arrival_density, with vertex connections
};

// A beam of a photon through a scattering medium (PhotonBeam), waiting for its gather.
struct PendingBeam {
  Ray ray;  // unit direction
  float t_max;
  Spectrum flux;
  uint32_t photon;  // the photon's index in its chunk
  int16_t medium, bounces;
  PhotonClass cls;
  bool hero_only;
  float score = 0;  // set by the gather, as PendingHit::score
};

// A photon's emission cell and weight, for its score (EmissionGuide).
struct EmittedPhoton {
  uint32_t cell;
  float weight;
};

// What the light pass keeps between iterations (so that their memory is allocated once): per
// chunk of a group's photons their hits and emissions, the hits in gather order, per gather chunk
// the entry lists (the hits', then the beams', a trace chunk's each), per chunk its photons'
// scores, and the per-thread counters.
struct LightPassBuffers {
  std::vector<std::vector<PendingHit>> hits;                // [chunk]
  std::vector<std::vector<EmittedPhoton>> emitted;          // [chunk]
  std::vector<std::vector<SensorCrossing>> crossings;       // [chunk], with sensors
  std::vector<std::vector<PendingBeam>> beams;              // [chunk], with medium spheres
  std::vector<std::vector<CameraHit>> camera_hits;          // [chunk], with connections
  std::vector<std::vector<const CameraHit*>> camera_bands;  // [band of 8 rows]
  std::vector<std::vector<VertexHit>> vertex_hits;          // [chunk], with connections
  std::vector<PendingHit*> order;
  std::vector<uint32_t> bucket_start;                         // of the counting sort
  std::vector<std::vector<std::vector<PhotonEntry>>> chunks;  // [gather chunk][slot]
  std::vector<std::vector<CellScore>> scores;                 // [chunk]
  std::vector<LightCounters> chunk_counters;  // [chunk]: added to counters for the chunks kept
  tbb::enumerable_thread_specific<LightCounters> counters;
};

struct LightPassResult {
  // Per backward photon: 1 where an entry reached it; the sums below hold only there.
  std::vector<uint8_t> reached;
  std::vector<Spectrum> flux;          // per backward photon: the sum of its entries' values
  std::vector<Spectrum> flux_inner;    // the same over the entries of its inner half (inner())
  std::vector<Spectrum> flux_quarter;  // and of its inner quarter (quarter())
  std::vector<Spectrum> flux_odd;      // and over the entries of the odd photons (odd())
  // Per pixel, with camera connections: the sum of their shares of it, and of the odd photons'.
  std::vector<Spectrum> camera, camera_odd;
  // Per pixel, with vertex connections: the sum of their values, and of the odd photons'.
  std::vector<Spectrum> vertex, vertex_odd;
  uint64_t emitted = 0;  // photons emitted, N of eq. (2)
  bool cut = false;      // a stop request ended the pass before all its photons
  // Gather rounds: one per group (two where the iteration has backward photons in media: the
  // hits', then the beams'), more where the memory limit split one.
  int batches = 0;
  // Fraction of the backward photons accepting indirect light that were hit (a statistic only).
  double coverage = 0;
  // Seconds, every part of the pass in one of them: tracing the photons (emission, rays,
  // scattering, each hit's leaf); gathering at the hits (their sort by leaf, the backward photons
  // found, their entries) and at the spheres in media that the beams reach; applying the entries,
  // the emission guide's learning and the coverage.
  double trace_s = 0, gather_s = 0, apply_s = 0;
  size_t peak_entry_bytes = 0;
};

// Photons per group: the hits of a group are sorted together, and its entries are held in memory
// until they are applied. A group ends earlier, at a chunk, once its hits and its beams in media
// together reach `hits` (where photons leave many), so that its memory is bounded; where it ends
// depends on the paths alone, so the order of every sum is fixed by the scene, the seed and the
// settings. A group has about as many hits as the iteration has backward photons, so that a leaf of
// the trees is reached by about as many hits of a group, and read from cache by all but the first,
// at any resolution; within [131072, 1048576] hits, and half as many photons.
struct GroupSize {
  uint64_t photons, hits;
};
GroupSize group_size(size_t backward_photons);
constexpr uint64_t kHitBytes = sizeof(PendingHit) + sizeof(PendingHit*);
static_assert(sizeof(PendingBeam) <= kHitBytes, "a beam counts as a hit toward a group's cap");
// What the light pass's hits (and with `beams`, its beams through scattering media; with `camera`
// and `vertex`, its camera and vertex connections) may take with at most `backward_photons`, for
// the memory budget.
double light_pass_hit_bytes(int max_depth, int threads, size_t backward_photons, bool beams,
                            bool camera, bool vertex);
// Hits per gather chunk.
constexpr int kHitsPerGather = 1024;

// Shoots settings.photons_per_iteration photons (streams keyed by seed, pass_index and photon
// index) in groups of group_size(backward photons) at most; stops early, at a chunk of the trace,
// when params.stop says so (the group's gather still runs). With a guide the photons start where it
// sends them, and with params.pixel_weight as well their scores are added to it (learning does not
// change its density until its update).
// The result goes to *result (its arrays keep their memory from one iteration to the next).
void run_light_pass(const RenderScene& scene, const BackwardMaps& maps,
                    const LightPassParams& params, const BpmSettings& settings,
                    const PixelMasks& masks, uint64_t seed, int pass_index,
                    LightPassBuffers* buffers, EmissionGuide* guide, LightPassResult* result);

}  // namespace bpm
