#include "bpm/bpm_integrator.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "base/error.h"
#include "base/memory.h"
#include "bpm/accumulate.h"
#include "bpm/backward_maps.h"
#include "bpm/disc_shares.h"
#include "bpm/eye_pass.h"
#include "bpm/light_pass.h"
#include "bpm/masks.h"
#include "bpm/photon_count.h"
#include "bpm/statistics.h"
#include "integrator/progressive.h"
#include "photons/emission_guide.h"
#include "photons/medium_radius.h"
#include "photons/sensor_discs.h"

namespace bpm {
namespace {

// The most backward photons one eye path stores (BackwardPhoton::place).
int photons_per_path(const BpmSettings& s, const RenderScene& scene) {
  return backward_photons_per_path(s.diffuse_depth,
                                   s.split_in_media && scene.has_scattering_media());
}

void check(const BpmSettings& s) {
  if (s.diffuse_depth < 0 || s.diffuse_depth > 3)
    throw Error("bpm: --diffuse-depth (file: diffusedepth) must be in 0..3");
  if (!(s.k0 > 0) || !(s.k1 > 0)) throw Error("bpm: --k0 and --k1 (file: k0, k1) must be positive");
  if (!(s.alpha > 0 && s.alpha < 1)) throw Error("bpm: --alpha (file: alpha) must be in (0, 1)");
  if (s.photons_per_iteration <= 0)
    throw Error("bpm: --photons (file: photonsperiteration) must be positive");
  if (s.emission_samples < 1 || s.emission_samples > 1024)
    throw Error("bpm: --emission-samples (file: emissionsamples) must be in 1..1024");
  if (s.direct_samples < 1 || s.direct_samples > 1024)
    throw Error("bpm: --direct-samples (file: directsamples) must be in 1..1024");
  if (!(s.radius >= 0) || !std::isfinite(s.radius))
    throw Error("bpm: --radius (file: radius) must not be negative");
}

// 1 / (value + floor) per pixel from the running means; the floor, a tenth of the image's mean
// value, keeps dark pixels from drawing every photon (relMSE adds 0.01 to r^2 for the same reason).
void update_pixel_weights(const std::vector<double>& sum, const std::vector<uint32_t>& count,
                          std::vector<float>* weight) {
  double total = 0;
  size_t seen = 0;
  for (size_t p = 0; p < sum.size(); ++p)
    if (count[p]) {
      total += sum[p] / count[p];
      ++seen;
    }
  // Nothing to weigh by (no estimate yet, or means that are not positive under --debias): no
  // weights, the same whatever was there before (a resumed render recomputes them).
  if (seen == 0 || !(total > 0)) {
    weight->clear();
    return;
  }
  const double floor = 0.1 * total / double(seen);
  weight->assign(sum.size(), float(1 / floor));
  for (size_t p = 0; p < sum.size(); ++p)
    if (count[p]) (*weight)[p] = float(1 / (std::max(0.0, sum[p] / count[p]) + floor));
}

// Memory (base/memory.h). Per pixel, what the eye pass (with the edges and near-edge marks of the
// disc probes, the sample statistics with their copy at the end of a round, and the radii's
// shares), the masks,
// the emission guide and the photon count's moments (the round's, its copy at the end of a round
// and the merged) keep, and the camera connections' two sums and radius; with vertex
// connections, their two sums and target (kVertexPixelBytes).
constexpr double kPixelBytes =
    sizeof(Spectrum) + 2 * sizeof(float) + 4 * sizeof(uint8_t) + 2 * sizeof(uint16_t) +
    sizeof(float) + 3 * sizeof(SampleStats<double>) + sizeof(double) + sizeof(uint32_t) +
    sizeof(float) + sizeof(uint16_t) + 3 * PixelMoments::kValues * sizeof(double) +
    2 * sizeof(float) + 2 * sizeof(Spectrum) + sizeof(float);
constexpr double kVertexPixelBytes = 2 * sizeof(Spectrum) + sizeof(uint32_t);

// What the extra samples of emission and of direct light cost against whole iterations
// (emission_sample_count, direct_sample_count), in rays: all the rays the iterations cast and the
// pixels they sampled, and of each kind the extra samples and their rays.
struct ExtraSampleCost {
  enum : size_t { kRays, kPixels, kEmissionSamples, kEmissionRays, kDirectSamples, kDirectRays };
  std::array<double, 6> v{};
  // What an iteration costs per pixel without extra samples over what one extra sample of the
  // kind (kEmissionSamples or kDirectSamples) costs, less one (at least 0); -1 while no extra
  // sample of the kind has been taken (unknown).
  double ratio(size_t kind) const {
    const double samples = v[kind], sample_rays = v[kind + 1];
    if (!(v[kPixels] > 0) || !(samples > 0) || !(sample_rays > 0)) return -1;
    return std::max(0.0, base_rays() / (sample_rays / samples) - 1);
  }
  // What an iteration costs per pixel without extra samples, in rays (0: unknown).
  double base_rays() const {
    if (!(v[kPixels] > 0)) return 0;
    return std::max(0.0, v[kRays] - v[kEmissionRays] - v[kDirectRays]) / v[kPixels];
  }
};
// Per backward photon: the thread's list and the map's copy, its four fluxes (all, inner half,
// inner quarter, odd photons) and hit flag, its references in the two trees (about two per tree
// where spheres overlap cells), and its place among its pixel's for the accumulation.
constexpr double kBackwardPhotonBytes = 2 * sizeof(BackwardPhoton) + 4 * sizeof(Spectrum) + 1 +
                                        4 * (sizeof(SphereRef) + sizeof(uint32_t)) +
                                        sizeof(uint32_t);

// What an iteration's maps take once built, with the light pass's per-photon arrays and the
// spheres in media (their records and Embree's trees over them).
double maps_bytes(const BackwardMaps& maps, const LightPassParams& lp) {
  return double(maps.photons.capacity() * sizeof(BackwardPhoton) + maps.tree_bytes() +
                (lp.medium_spheres ? lp.medium_spheres->bytes() : 0) +
                maps.first_bucket.capacity() * sizeof(uint32_t) +
                size_t(maps.bucket_count() + 1) * sizeof(uint32_t) +
                maps.photons.size() * (4 * sizeof(Spectrum) + 1) +
                lp.photon_materials.capacity() * sizeof(Material));
}

// One render of bpm: what its iterations share, and what each leaves to the next. iteration() is
// the paper's Fig. 3, one method a stage; the round's end (integrator/control.h) merges what the
// round's iterations learnt (guided emission, the pixels' emission statistics and running means),
// and save and load keep it across a checkpoint.
class BpmRender {
 public:
  BpmRender(const LoadedScene& ls, const IntegratorOptions& opt, const BpmSettings& settings,
            Film* film);
  PassResult iteration(int pass, const RenderControl& control);
  // The sensors' estimates of the last iteration, into the film (IntegratorOptions::sensor_pass).
  void record_sensors(Film* film) const { sensor_sums_.record(film); }
  // The round's end and the checkpoint, as run_passes calls them.
  IntegratorState state();
  // The render's statistics once run_passes has filled `stats`.
  RenderStats finish(RenderStats stats);

 private:
  // The four stages of an iteration. Each returns false when the iteration is dropped.
  bool eye_pass(const WavelengthMaterials& wm, float scale, int pass, int it,
                const RenderControl& control);
  bool build_maps(int pass, const RenderControl& control, LightPassParams* lp);
  bool light_pass(const LightPassParams& lp, int pass, int it);
  // Probes the discs that gathered light (disc_shares.h), then adds the iteration to the film.
  void accumulate(const WavelengthMaterials& wm, int it);
  PassResult progress() const;

  // What the round learnt, as sums that add across processes (IntegratorState::learnt, merge,
  // keep_learnt), and the checkpoint.
  void learnt(std::vector<double>* out);
  void merge(const std::vector<double>& sums);
  void keep_learnt(const std::vector<double>& sums);
  size_t pixel_values() const;
  void save(ByteWriter& w);
  void load(ByteReader& r);
  std::pair<ExtraSampleCost, ExtraSampleCost> round_cost() const;
  void set_sample_counts();
  // The work the counters have counted so far (photon_count.h), and the next photon count from
  // what the rounds learnt.
  PassWork work_now() const;
  void choose_photons();
  // Combined estimators run as asked (photons/merge_weights.h).
  CombineAt combined() const { return s_.combine; }
  // Vertex connections run: asked for, with an image.
  bool vertex_connections() const {
    return s_.vertex_connections != ConnectionMode::kOff && opt_.image;
  }
  // Checks that the iteration's fixed part fits the memory budget; returns its bytes.
  double reserve_memory() const;
  // The camera connections as the settings ask and the scene allows, and each pixel's radius for
  // caustic light at a first vertex in iteration it (camera_connections.h).
  CameraConnections camera_connections() const;
  void set_caustic_radii(int it, float scale);

  const LoadedScene& ls_;
  const RenderScene& scene_;
  const IntegratorOptions& opt_;
  const BpmSettings s_;
  Film* film_;
  const size_t n_pixels_;
  const CameraSampler camera_;
  PixelMasks masks_;
  EyePixels eye_;
  tbb::enumerable_thread_specific<ObjectPhotonLists> thread_lists_;
  tbb::enumerable_thread_specific<EyeCounters> eye_counters_;
  BackwardMaps maps_;
  LightPassBuffers light_;
  LightPassResult light_result_;  // of the last light pass; its arrays are reused
  PixelSums pixel_sums_;
  BpmTotals tot_;
  // Guided emission learns from each iteration's photons, scored relative to the pixels they
  // reach; the pixels' values are the running means of their estimates. Both change at the end
  // of a round (integrator/control.h): estimate_new_ holds the round's sums and counts until then.
  EmissionGuide guide_;
  std::vector<double> estimate_sum_, estimate_new_;
  std::vector<uint32_t> estimate_count_;
  std::vector<float> pixel_weight_;
  // Carried from one iteration to the next, and merged at the end of each round: what the
  // pixels' extra samples cost (their sample counts follow from it); counted_: the counters'
  // totals at the last round.
  ExtraSampleCost cost_sum_, cost_new_, counted_;
  // Photons per iteration: the settings' when they fix it, else chosen at the end of each round
  // from the pixels' moments and the passes' work (photon_count.h), merged as the costs above.
  const bool adapt_photons_;
  int photons_;
  std::vector<double> moments_sum_, moments_new_;
  PassWork work_sum_, work_new_, work_counted_;
  const std::string size_;  // WxH, for messages
  const double fixed_bytes_;
  // In a scene where no light path can be a caustic, the backward photons that accept only
  // caustics (half of them at D = 0) would gather nothing: they are not made.
  const bool caustics_;
  // Disc probes at first vertices near edges only (photons/disc_probes.h); with a radius in
  // world units the radii on screen are unknown, and every disc is probed.
  NearEdges near_edges_;
  // Illuminance sensors, when the render has them (photons/sensor_discs.h).
  std::unique_ptr<SensorDiscs> sensors_;
  SensorIteration sensor_sums_;
  // The backward photons in scattering media as spheres for the photon beams (none without such
  // media).
  std::unique_ptr<MediumSpheres> medium_spheres_;
  float medium_min_length_;  // photons/medium_radius.h
  // Caustic photons joined to the camera (off where the settings, the camera or the scene rule
  // them out).
  CameraConnections connections_;
  VertexConnections vertex_;  // this iteration's targets (vertex_connections.h)
};

const char* const kMemoryAdvice =
    "lower --resolution or --diffuse-depth (or the radii: --k0, --k1, --radius), or raise "
    "--memory";

BpmSettings checked_settings(const BpmSettings& settings, size_t n_pixels) {
  BpmSettings s = settings;
  s.photons_per_iteration = photons_for(settings, n_pixels);
  check(s);
  return s;
}

EyeCounters eye_exemplar(const IntegratorOptions& opt) {
  EyeCounters c;
  c.rays.observer = opt.eye_ray_observer;
  return c;
}

BpmRender::BpmRender(const LoadedScene& ls, const IntegratorOptions& opt,
                     const BpmSettings& settings, Film* film)
    : ls_(ls),
      scene_(ls.scene),
      opt_(opt),
      s_(checked_settings(settings, size_t(film->width()) * size_t(film->height()))),
      film_(film),
      n_pixels_(size_t(film->width()) * size_t(film->height())),
      camera_(ls.camera, ls.filter, ls.film.raster_for(film->width(), film->height()), opt.seed),
      masks_(film->width(), film->height(), tbb::this_task_arena::max_concurrency()),
      eye_(n_pixels_),
      thread_lists_(
          [this] { return ObjectPhotonLists(scene_.objects.size() + scene_.media.size()); }),
      eye_counters_(eye_exemplar(opt)),
      guide_(s_.guide_emission ? EmissionGuide(scene_) : EmissionGuide()),
      estimate_sum_(n_pixels_, 0.0),
      estimate_new_(2 * n_pixels_, 0.0),
      estimate_count_(n_pixels_, 0),
      adapt_photons_(settings.photons_per_iteration == 0),
      photons_(s_.photons_per_iteration),
      moments_sum_(PixelMoments::kValues * n_pixels_, 0.0),
      moments_new_(moments_sum_.size(), 0.0),
      size_(std::to_string(film->width()) + "x" + std::to_string(film->height())),
      fixed_bytes_(reserve_memory()),
      caustics_(may_have_caustics(scene_)),
      near_edges_(s_.disc_probes && s_.radius <= 0, scene_, camera_.camera(), ls.film.width,
                  ls.film.height, ls.filter.radius),
      sensors_(make_sensor_discs(scene_, opt.sensors, camera_.camera(), s_)),
      sensor_sums_(opt.sensors.size()),
      medium_spheres_(scene_.has_scattering_media() ? std::make_unique<MediumSpheres>() : nullptr),
      medium_min_length_(
          scene_.has_scattering_media()
              ? median_surface_distance(scene_, camera_.camera(), film->width(), film->height())
              : 0) {
  pixel_sums_.places = photons_per_path(s_, scene_);
  connections_ = camera_connections();
  LightCounters light_exemplar;
  light_exemplar.observer = opt.light_ray_observer;
  light_.counters = tbb::enumerable_thread_specific<LightCounters>(light_exemplar);
  set_sample_counts();
}

// An eye path leaves at most D + 2 backward photons (two at x_1 when D = 0, one at each other
// diffuse vertex), and kMaxMediumSplits more where it splits in media: the worst iteration must
// fit the memory budget before the first one starts.
// The light pass holds the hits of a group of photons, and its entries get what the film, the
// actual maps and those hits leave (applied in more rounds).
double BpmRender::reserve_memory() const {
  // A photon's entry names its backward photon in 29 bits (PhotonEntry::kIndexMask).
  const double most = double(n_pixels_) * photons_per_path(s_, scene_);
  if (most > double(PhotonEntry::kIndexMask))
    throw Error("bpm at " + size_ + " would store up to " + std::to_string(uint64_t(most)) +
                " backward photons per iteration, more than its entries can name (" +
                std::to_string(PhotonEntry::kIndexMask) +
                "): lower --resolution or --diffuse-depth");
  const double fixed_bytes =
      double(film_->bytes()) +
      double(n_pixels_) * (kPixelBytes + (vertex_connections() ? kVertexPixelBytes : 0.0)) +
      light_pass_hit_bytes(opt_.max_depth, tbb::this_task_arena::max_concurrency(),
                           n_pixels_ * size_t(photons_per_path(s_, scene_)),
                           scene_.has_scattering_media(),
                           s_.camera_connections != ConnectionMode::kOff, vertex_connections());
  check_memory(
      "bpm at " + size_ + " with diffuse depth " + std::to_string(s_.diffuse_depth) + " (up to " +
          std::to_string(photons_per_path(s_, scene_)) +
          " backward photons per pixel and iteration)",
      fixed_bytes + double(n_pixels_) * photons_per_path(s_, scene_) * kBackwardPhotonBytes,
      opt_.memory_budget, kMemoryAdvice);
  return fixed_bytes;
}

CameraConnections BpmRender::camera_connections() const {
  CameraConnections cc;
  // Only a pinhole sees the connections' point.
  if (!opt_.image || !caustics_ || !camera_.camera().projects()) return cc;
  cc.mode = s_.camera_connections;
  // Where the camera's rays split in media (toward the last diffuse vertex, so at D = 0) they
  // cross the first kMaxMediumSplits pieces at full weight (gather_forced_in_medium, eye_pass.cpp).
  if (s_.split_in_media && s_.diffuse_depth == 0) cc.certain_pieces = kMaxMediumSplits;
  cc.camera = &camera_.camera();
  cc.camera_medium = camera_.camera().medium();
  cc.filter = &camera_.filter();
  cc.width = film_->width();
  cc.height = film_->height();
  cc.caustic_radius.assign(cc.on() ? n_pixels_ : 0, 0.0f);
  cc.world = s_.radius > 0;
  // The first vertex takes both parts of a material where gathering ends the path there
  // (choose_or_split, bpm/eye_pass.cpp).
  cc.gather_by_chance = !(s_.diffuse_depth == 0 && s_.split_coats);
  return cc;
}

// As backward_photon_at (bpm/eye_pass.cpp) makes them: at D = 0 the first vertex's caustic disc
// is the small one unless the radii are in world units or k0 = k1 (one disc for all light, of r1);
// at D > 0 it is the small one.
void BpmRender::set_caustic_radii(int it, float scale) {
  const bool small = s_.diffuse_depth > 0 || !(s_.radius > 0 || s_.k0 == s_.k1);
  const float base = s_.radius > 0
                         ? s_.radius
                         : (small ? s_.k0 : s_.k1) * camera_.camera().footprint({0, 0}).spread;
  const bool per_pixel = s_.radius_policy == RadiusPolicy::kPerPixel;
  tbb::parallel_for(size_t(0), n_pixels_, [&](size_t p) {
    const DiscScales d = per_pixel ? DiscScales::of(s_, it, opt_.first_iteration, eye_.lit_share[p])
                                   : DiscScales{scale, scale};
    connections_.caustic_radius[p] = base * (small ? d.small : d.large);
  });
}

// Fig. 3: one iteration, an independent estimate of the image.
PassResult BpmRender::iteration(int pass, const RenderControl& control) {
  const int it = opt_.first_iteration + pass;  // the index random streams and radii follow
  if (!opt_.image && !caustics_) {
    // Sensors alone in a scene without caustics: the photons would add nothing, the paths from
    // the sensors find everything.
    sensor_sums_.clear();
    sensor_sums_.finish(scene_, *sensors_, opt_.max_depth, s_.bias_model, opt_.seed, it, 0);
    return progress();
  }
  const float scale = radius_scale(s_, it);
  // One set of wavelengths for every eye and light path of the iteration.
  const WavelengthMaterials wm(scene_, iteration_wavelengths(opt_.seed, it, ls_.film.spectral));
  // 1. Eye pass: backward photons, and the light the eye paths count themselves (no image: none).
  if (opt_.image && !eye_pass(wm, scale, pass, it, control)) return PassResult{false, 0, "", ""};
  // 2. Per-object sphere trees over the backward photons.
  LightPassParams lp{&wm, opt_.max_depth, s_.normal_cos, {}};
  if (!build_maps(pass, control, &lp)) return PassResult{false, 0, "", "memory"};
  // The photons carry their merge factors where some backward photon is combined.
  lp.combine = combined() != CombineAt::kNowhere &&
               std::any_of(maps_.photons.begin(), maps_.photons.end(),
                           [](const BackwardPhoton& bp) { return bp.combined; });
  lp.merge_photons = double(photons_);
  if (vertex_connections()) {
    find_vertex_targets(maps_, n_pixels_, double(photons_), &vertex_);
    vertex_.alone = s_.vertex_connections == ConnectionMode::kAlone;
    lp.vertex = &vertex_;
  }
  if (connections_.on()) {
    set_caustic_radii(it, scale);
    weigh_merges_against_camera(maps_, connections_, &lp);
  }
  if (sensors_) {
    sensors_->set_scale(scale);
    sensor_sums_.clear();
    lp.sensors = sensors_.get();
    lp.sensor_sums = &sensor_sums_;
  }
  // 3. Light pass: a fixed number of photons, in groups.
  if (!light_pass(lp, pass, it)) return PassResult{false, 0, "", ""};
  if (sensors_)
    sensor_sums_.finish(scene_, *sensors_, opt_.max_depth, s_.bias_model, opt_.seed, it,
                        light_result_.emitted);
  // 4. Accumulation of the iteration into the film; masks balanced for the next one.
  if (opt_.image) accumulate(wm, it);
  return progress();
}

bool BpmRender::eye_pass(const WavelengthMaterials& wm, float scale, int pass, int it,
                         const RenderControl& control) {
  const auto t = Clock::now();
  // Under the per-pixel policy each pixel scales the first iteration's radii (DiscScales).
  const bool per_pixel = s_.radius_policy == RadiusPolicy::kPerPixel;
  const float shared = per_pixel ? 1.0f : scale;
  EyePassParams ep{&wm,
                   s_.diffuse_depth,
                   opt_.max_depth,
                   s_.k0 * shared,
                   s_.k1 * shared,
                   s_.emission_samples,
                   s_.direct_samples,
                   s_.radius * shared,
                   per_pixel ? &s_ : nullptr,
                   it,
                   opt_.first_iteration,
                   medium_min_length_,
                   caustics_,
                   s_.normal_cos,
                   s_.disc_probes,
                   &near_edges_,
                   opt_.equiangular,
                   s_.split_in_media,
                   combined(),
                   double(photons_),
                   s_.split_coats,
                   vertex_connections() ? double(n_pixels_) : 0.0};
  // Where the first vertices' discs are probed: near edges, within this iteration's radii (the
  // first iteration's, the largest, under the per-pixel policy).
  near_edges_.mark(s_.k0 * shared, s_.k1 * shared);
  const bool complete = run_eye_pass(scene_, ep, camera_, masks_, control, pass, it, &eye_,
                                     {thread_lists_, eye_counters_});
  tot_.eye_s += since(t);
  // An eye pass cut short (an interrupt, or the time budget after the first iteration) leaves
  // pixels without their estimate: the iteration is dropped.
  return complete;
}

bool BpmRender::build_maps(int pass, const RenderControl& control, LightPassParams* lp) {
  const auto t = Clock::now();
  std::vector<ObjectPhotonLists*> lists;
  for (ObjectPhotonLists& l : thread_lists_) lists.push_back(&l);
  build_backward_maps(lists, scene_.objects.size() + scene_.media.size(), s_.centre_tree, &maps_);
  // The time budget holds inside an iteration: its light pass ends early with the photons
  // traced so far (the iteration is still a complete estimate, only noisier).
  if (medium_spheres_) {
    medium_spheres_->build(maps_, scene_.objects.size(), scene_.media.size());
    lp->medium_spheres = medium_spheres_.get();
  }
  lp->stop = [&control] { return control.stop_requested(); };
  lp->scene = &scene_;
  resolve_photon_materials(maps_, lp);
  if (!guide_.empty() && !pixel_weight_.empty()) lp->pixel_weight = &pixel_weight_;
  if (opt_.memory_budget > 0) {
    // The eye pass's lists keep their memory for the next iteration: a second copy of the
    // backward photons (counted by their number, not the lists' capacities, which depend on
    // how the threads shared the pixels: a budget decision must not).
    const double list_bytes = double(maps_.photons.size() * sizeof(BackwardPhoton));
    // With camera connections, a weight per backward photon (weigh_merges_against_camera).
    const double used = fixed_bytes_ + maps_bytes(maps_, *lp) + list_bytes +
                        (connections_.on() ? double(maps_.photons.size() * sizeof(float)) : 0.0);
    // Over the budget (the estimate before the first iteration assumed typical trees and no
    // textured materials): an error in the first iteration, which has nothing to keep; later,
    // the render ends with the iterations so far and says why.
    if (used > double(opt_.memory_budget)) {
      if (pass == 0)
        check_memory("bpm's backward photons and trees at " + size_, used, opt_.memory_budget,
                     kMemoryAdvice);
      tot_.build_s += since(t);
      return false;
    }
    lp->entry_bytes_limit = std::max<size_t>(1, size_t(double(opt_.memory_budget) - used));
  }
  tot_.build_s += since(t);
  tot_.add_maps(maps_);
  return true;
}

bool BpmRender::light_pass(const LightPassParams& lp, int pass, int it) {
  BpmSettings s = s_;
  s.photons_per_iteration = photons_;
  run_light_pass(scene_, maps_, lp, s, masks_, opt_.seed, it, &light_,
                 guide_.empty() ? nullptr : &guide_, &light_result_);
  // Its time counts even if the iteration is dropped below: its rays reach the counters.
  tot_.add_light_pass_time(light_result_);
  // The film averages iterations with equal weights, so an iteration the budget cut to a share
  // f of its photons adds variance ~ 1/f to a mean of n: with n - 1 whole ones, keeping it
  // helps only when ((n - 1) + 1/f) / n^2 < 1 / (n - 1), about f > 1/2. A later iteration with
  // less than half its photons is dropped; the first is always kept (an image needs one).
  if (light_result_.cut && pass > 0 && 2 * light_result_.emitted < uint64_t(photons_)) return false;
  tot_.add_light_pass(light_result_);
  return true;
}

void BpmRender::accumulate(const WavelengthMaterials& wm, int it) {
  auto t = Clock::now();
  if (s_.disc_probes)
    probe_lit_discs(scene_, light_result_, s_.normal_cos, opt_.seed, it, &maps_, &eye_counters_);
  tot_.probe_s += since(t);
  t = Clock::now();
  accumulate_iteration(maps_, &light_result_, &eye_, wm.wl, ls_.film.max_component_value, s_, film_,
                       &pixel_sums_, guide_.empty() ? nullptr : &estimate_new_, &moments_new_,
                       camera_.filter().mean_weight());
  tot_.accumulate_s += since(t);
  // The iteration's work, counted once it joined the image (a dropped one's goes with the next).
  const PassWork now = work_now();
  work_new_ += now - work_counted_;
  work_counted_ = now;
  work_new_.v[PassWork::kPhotons] += double(light_result_.emitted);
  if (medium_spheres_) work_new_.v[PassWork::kMediumSpheres] += double(medium_spheres_->size());
  work_new_.v[PassWork::kIterations] += 1;
  masks_.rebuild(eye_.cost_ns);
}

PassResult BpmRender::progress() const {
  PassResult r;
  for (const EyeCounters& c : eye_counters_) r.rays += c.rays.total();
  for (const LightCounters& c : light_.counters)
    r.rays += c.light_rays + c.camera_rays + c.vertex_rays;
  char text[128];
  std::snprintf(text, sizeof text, "  %zu backward photons  coverage %.2f%s", maps_.photons.size(),
                light_result_.coverage,
                light_result_.cut ? "  (light pass cut short by the budget)" : "");
  r.progress = text;
  return r;
}

// The round's costs so far: cost_new_ (kept from a checkpoint or another process's share) and
// what the counters added since the last round; and the counters' totals now.
std::pair<ExtraSampleCost, ExtraSampleCost> BpmRender::round_cost() const {
  using C = ExtraSampleCost;
  C now, round = cost_new_;
  for (const EyeCounters& c : eye_counters_) {
    now.v[C::kRays] += double(c.rays.total());
    now.v[C::kPixels] += double(c.pixels);
    now.v[C::kEmissionSamples] += double(c.emission_samples);
    now.v[C::kEmissionRays] += double(c.emission_rays);
    now.v[C::kDirectSamples] += double(c.direct_samples);
    now.v[C::kDirectRays] += double(c.direct_rays);
  }
  for (const LightCounters& c : light_.counters)
    now.v[C::kRays] += double(c.light_rays + c.camera_rays + c.vertex_rays);
  for (size_t k = 0; k < now.v.size(); ++k) round.v[k] += now.v[k] - counted_.v[k];
  return {round, now};
}

void BpmRender::set_sample_counts() {
  const double emission = cost_sum_.ratio(ExtraSampleCost::kEmissionSamples),
               direct = cost_sum_.ratio(ExtraSampleCost::kDirectSamples);
  // Under adaptive sampling the extra samples follow the rate of iterations each pixel's error
  // asks for (at_asked_rate).
  const std::vector<float> asked =
      opt_.adaptive ? asked_pass_rates(moments_sum_) : std::vector<float>(n_pixels_, -1.0f);
  const auto shared = [&](size_t p, int count, bool emission_alone = false) {
    return uint16_t(at_asked_rate(count, asked[p], opt_.adaptive_floor, emission_alone));
  };
  for (size_t p = 0; p < n_pixels_; ++p) {
    const SampleStats<double>& st = eye_.sample_stats[p];
    eye_.emission_samples[p] =
        eye_.sees_emission[p] ? shared(p, emission_sample_count(st, emission, s_.emission_samples),
                                       st.rest_n() >= 2 && !(st.variance(st.kRest) > 0))
                              : 1;
  }
  lend_emission_samples(film_->width(), film_->height(), ls_.filter.radius, &eye_);
  for (size_t p = 0; p < n_pixels_; ++p) {
    const SampleStats<double>& st = eye_.sample_stats[p];
    // The pixel's estimates: their count and sample variance, from its moments.
    const double* m = moments_sum_.data() + PixelMoments::kValues * p;
    const double n = m[PixelMoments::kCount], sum = m[PixelMoments::kSum];
    const double variance = n < 2 ? 0.0 : (m[PixelMoments::kSquares] - sum * sum / n) / (n - 1);
    const SampleStats<double> pooled =
        with_neighbours_rare(eye_.sample_stats, film_->width(), film_->height(), p);
    eye_.direct_samples[p] = shared(
        p, direct_sample_count(pooled, n, std::max(0.0, variance), direct, s_.direct_samples));
    if (combined() == CombineAt::kChosen)
      eye_.continue_level[p] =
          uint8_t(continue_level(pooled, n, std::max(0.0, variance), cost_sum_.base_rays()));
    eye_.lit_share[p] = st.lit_share();
  }
}

constexpr size_t kStats = SampleStats<double>::kValues;

// The learnt sums: per pixel whether it saw emission, then its emission statistics, the round's
// costs, and with guided emission the guide's cells and the pixels' estimate sums and counts.
void BpmRender::learnt(std::vector<double>* out) {
  for (uint8_t& saw : eye_.saw_emission) {
    out->push_back(saw);
    saw = 0;
  }
  for (SampleStats<double>& st : eye_.round_stats) {
    out->insert(out->end(), st.v.begin(), st.v.end());
    st = {};
  }
  const auto [round, now] = round_cost();
  out->insert(out->end(), round.v.begin(), round.v.end());
  counted_ = now;
  cost_new_ = {};
  out->insert(out->end(), moments_new_.begin(), moments_new_.end());
  std::fill(moments_new_.begin(), moments_new_.end(), 0.0);
  out->insert(out->end(), work_new_.v.begin(), work_new_.v.end());
  work_new_ = {};
  if (guide_.empty()) return;
  guide_.take_learnt(out);
  out->insert(out->end(), estimate_new_.begin(), estimate_new_.end());
  std::fill(estimate_new_.begin(), estimate_new_.end(), 0.0);
}

// The learnt sums before the guide's: per pixel whether it saw emission and its emission
// statistics, the costs, the pixels' moments and the work.
size_t BpmRender::pixel_values() const {
  return (1 + kStats) * n_pixels_ + ExtraSampleCost().v.size() + moments_new_.size() +
         PassWork::kValues;
}

void BpmRender::merge(const std::vector<double>& sums) {
  // Rounded to float before they join, as the guide's sums below.
  const double* stats = sums.data() + n_pixels_;
  for (size_t p = 0; p < n_pixels_; ++p) {
    std::array<double, kStats>& st = eye_.sample_stats[p].v;
    for (size_t k = 0; k < kStats; ++k) st[k] += double(float(stats[kStats * p + k]));
    if (sums[p] > 0) eye_.sees_emission[p] = 1;
  }
  const double* c = stats + kStats * n_pixels_;
  for (size_t k = 0; k < cost_sum_.v.size(); ++k) cost_sum_.v[k] += double(float(c[k]));
  const double* m = c + cost_sum_.v.size();
  for (size_t i = 0; i < moments_sum_.size(); ++i) moments_sum_[i] += double(float(m[i]));
  set_sample_counts();
  const double* w = m + moments_sum_.size();
  for (size_t k = 0; k < PassWork::kValues; ++k) work_sum_.v[k] += double(float(w[k]));
  choose_photons();
  if (guide_.empty()) return;
  // A round's sums are rounded to float precision before they join: processes add their
  // shares in another order than one process adds passes, and a difference in the last bits
  // of a sum would move a boundary of the guided density, so that the same seed would draw
  // other photons.
  const size_t guide_at = pixel_values();
  std::vector<double> learnt(sums.size() - guide_at);
  for (size_t i = 0; i < learnt.size(); ++i) learnt[i] = double(float(sums[guide_at + i]));
  guide_.merge(learnt.data());
  tot_.guide_moved = guide_.moved();
  const double* e = learnt.data() + 2 * guide_.cells();
  for (size_t p = 0; p < n_pixels_; ++p) {
    estimate_sum_[p] += e[2 * p];
    estimate_count_[p] += uint32_t(e[2 * p + 1]);
  }
  update_pixel_weights(estimate_sum_, estimate_count_, &pixel_weight_);
}

void BpmRender::keep_learnt(const std::vector<double>& sums) {
  const double* stats = sums.data() + n_pixels_;
  for (size_t p = 0; p < n_pixels_; ++p) {
    eye_.saw_emission[p] = sums[p] > 0;
    std::copy_n(stats + kStats * p, kStats, eye_.round_stats[p].v.begin());
  }
  const double* c = stats + kStats * n_pixels_;
  std::copy_n(c, cost_new_.v.size(), cost_new_.v.begin());
  const double* m = c + cost_new_.v.size();
  std::copy_n(m, moments_new_.size(), moments_new_.begin());
  std::copy_n(m + moments_new_.size(), PassWork::kValues, work_new_.v.begin());
  if (guide_.empty()) return;
  const double* guide = sums.data() + pixel_values();
  guide_.keep_learnt(guide);
  const double* e = guide + 2 * guide_.cells();
  estimate_new_.assign(e, e + 2 * n_pixels_);
}

PassWork BpmRender::work_now() const {
  PassWork w;
  for (const EyeCounters& c : eye_counters_) {
    w.v[PassWork::kEyeRays] += double(c.rays.total());
    w.v[PassWork::kBackwardPhotons] += double(c.backward_photons);
  }
  for (const LightCounters& c : light_.counters) {
    w.v[PassWork::kLightRays] += double(c.light_rays + c.camera_rays + c.vertex_rays);
    w.v[PassWork::kQueries] += double(c.queries);
    w.v[PassWork::kBeams] += double(c.beams);
    w.v[PassWork::kEntries] += double(c.entries);
  }
  return w;
}

// The balance is computed (and reported) for a fixed count too; only an adapting render takes it.
void BpmRender::choose_photons() {
  const PhotonCountChoice c =
      choose_photon_count(moments_sum_, work_sum_, photons_, s_.photons_per_iteration);
  if (adapt_photons_) photons_ = c.photons;
  tot_.photon_share = c.photon_share;
  tot_.photons_best = c.best;
  tot_.variance = c.variance;
  tot_.photon_variance = c.photon_variance;
}

void BpmRender::save(ByteWriter& w) {
  w.put_vector(eye_.sees_emission);
  w.put_vector(eye_.saw_emission);
  w.put_vector(eye_.sample_stats);
  w.put_vector(eye_.round_stats);
  w.put(cost_sum_.v);
  w.put(round_cost().first.v);  // the counters start from zero when the render goes on
  w.put(int32_t(photons_));
  w.put_vector(moments_sum_);
  w.put_vector(moments_new_);
  w.put(work_sum_.v);
  PassWork round = work_new_;  // as the costs: the counters start from zero again
  round += work_now() - work_counted_;
  w.put(round.v);
  w.put(uint8_t(!guide_.empty()));
  if (guide_.empty()) return;
  guide_.save(w);
  w.put_vector(estimate_sum_);
  w.put_vector(estimate_count_);
  w.put_vector(estimate_new_);
}

void BpmRender::load(ByteReader& r) {
  eye_.sees_emission = r.get_vector<uint8_t>();
  eye_.saw_emission = r.get_vector<uint8_t>();
  eye_.sample_stats = r.get_vector<SampleStats<double>>();
  eye_.round_stats = r.get_vector<SampleStats<double>>();
  if (eye_.sees_emission.size() != n_pixels_ || eye_.saw_emission.size() != n_pixels_ ||
      eye_.sample_stats.size() != n_pixels_ || eye_.round_stats.size() != n_pixels_)
    throw Error(r.what() + " is truncated or corrupt (pixels that see emission)");
  cost_sum_.v = r.get<decltype(cost_sum_.v)>();
  cost_new_.v = r.get<decltype(cost_new_.v)>();
  // The counters start again from zero.
  counted_ = {};
  photons_ = r.get<int32_t>();
  moments_sum_ = r.get_vector<double>();
  moments_new_ = r.get_vector<double>();
  work_sum_.v = r.get<std::array<double, PassWork::kValues>>();
  work_new_.v = r.get<std::array<double, PassWork::kValues>>();
  work_counted_ = {};
  const size_t moments = PixelMoments::kValues * n_pixels_;
  if (photons_ < 1 || moments_sum_.size() != moments || moments_new_.size() != moments)
    throw Error(r.what() + " is truncated or corrupt (photon count)");
  set_sample_counts();
  if (r.get<uint8_t>() != uint8_t(!guide_.empty()))
    throw Error(r.what() + " differs in guided emission (--no-guide)");
  if (guide_.empty()) return;
  guide_.load(r);
  estimate_sum_ = r.get_vector<double>();
  estimate_count_ = r.get_vector<uint32_t>();
  estimate_new_ = r.get_vector<double>();
  if (estimate_sum_.size() != n_pixels_ || estimate_count_.size() != n_pixels_ ||
      estimate_new_.size() != 2 * n_pixels_)
    throw Error(r.what() + " is truncated or corrupt (pixel estimates)");
  update_pixel_weights(estimate_sum_, estimate_count_, &pixel_weight_);
}

IntegratorState BpmRender::state() {
  IntegratorState state;
  state.learnt = [this](std::vector<double>* out) { learnt(out); };
  state.merge = [this](const std::vector<double>& sums) { merge(sums); };
  state.keep_learnt = [this](const std::vector<double>& sums) { keep_learnt(sums); };
  state.save = [this](ByteWriter& w) { save(w); };
  state.load = [this](ByteReader& r) { load(r); };
  return state;
}

RenderStats BpmRender::finish(RenderStats stats) {
  for (const EyeCounters& c : eye_counters_) tot_.eye.add(c);
  for (const LightCounters& c : light_.counters) tot_.light.add(c);
  stats.rays = tot_.eye.rays;
  stats.light_rays = tot_.light.light_rays;
  tot_.photons_last = photons_;
  tot_.camera_connections = connections_.on();
  tot_.vertex_connections = vertex_connections();
  if (combined() == CombineAt::kChosen) {
    double sum = 0;
    for (uint8_t level : eye_.continue_level)
      sum += level == kNeverContinue ? 0.0 : std::ldexp(1.0, -int(level));
    tot_.continue_probability = n_pixels_ > 0 ? sum / double(n_pixels_) : -1;
  }
  if (s_.radius_policy == RadiusPolicy::kPerPixel && stats.passes > 0) {
    const int last = opt_.first_iteration + stats.passes - 1;
    // Over the pixels whose discs of the kind have received photons.
    double sum[2] = {0, 0}, n[2] = {0, 0};
    for (const std::array<float, 2>& share : eye_.lit_share) {
      const DiscScales d = DiscScales::of(s_, last, opt_.first_iteration, share);
      for (int k = 0; k < 2; ++k)
        if (share[size_t(k)] > 0) {
          sum[k] += k == 0 ? d.small : d.large;
          n[k] += 1;
        }
    }
    tot_.small_scale_mean = n[0] > 0 ? sum[0] / n[0] : -1;
    tot_.large_scale_mean = n[1] > 0 ? sum[1] / n[1] : -1;
    tot_.shared_scale = radius_scale(s_, last);
  }
  stats.details = to_json(tot_, s_, stats.passes, n_pixels_);
  return stats;
}

}  // namespace

RenderStats render_bpm(const LoadedScene& ls, const IntegratorOptions& opt,
                       const BpmSettings& settings, Film* film) {
  IntegratorOptions o = opt;
  BpmRender bpm(ls, o, settings, film);
  if (!opt.sensors.empty()) o.sensor_pass = [&bpm](int, Film* f) { bpm.record_sensors(f); };
  RenderStats stats;
  run_passes(
      o, film, "iteration",
      [&bpm](int pass, const RenderControl& control) { return bpm.iteration(pass, control); },
      &stats, bpm.state());
  return bpm.finish(stats);
}

}  // namespace bpm
