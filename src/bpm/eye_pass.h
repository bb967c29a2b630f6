// Stage 1 of a bpm iteration, the eye pass (DESIGN.md, "one path, counted exactly once"): a
// camera path through specular vertices and up to D + 1 diffuse vertices. It counts emission seen
// through specular vertices only, direct light at each diffuse vertex by next-event estimation,
// and leaves backward photons at each diffuse vertex for the light pass to fill: caustic photons
// only at x_1..x_D, every photon but direct ones at x_(D+1), where the path ends. Caustic light at
// x_1 is gathered over the small radius r0, the rest over r1; so with D = 0, x_1 has two backward
// photons. The pass runs block by block, each thread over the pixels of its mask (section 3).
#pragma once
#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "base/rng.h"
#include "bpm/backward_photon.h"
#include "bpm/masks.h"
#include "integrator/counters.h"
#include "integrator/progressive.h"
#include "photons/disc_probes.h"
#include "photons/settings.h"
#include "scene/render_scene.h"

namespace bpm {

struct EyePassParams {
  const WavelengthMaterials* materials = nullptr;  // this iteration's wavelengths
  int diffuse_depth = 1;
  int max_depth = 5;
  // Radii in pixel footprints (the camera ray's PixelFootprint at the vertex's path length):
  // k0 and k1 times radius_scale(iteration), or with pixel_radii the first iteration's, which each
  // pixel scales by its own schedule (DiscScales).
  float k0 = 0, k1 = 0;
  // At most this many camera samples per iteration for emission seen before the first diffuse
  // vertex (emitter edges, lights behind glass): cheap paths that end at that vertex, averaged
  // with the full path's share. Each pixel takes EyePixels::emission_samples of them.
  int emission_samples = 1;
  // At most this many samples of direct light (next-event estimation and a BSDF sample that looks
  // for the light, averaged) at the last diffuse vertex of a surface; each pixel takes
  // EyePixels::direct_samples of them.
  int direct_samples = 1;
  // When positive, every backward photon's radius in world units instead of the per-length radii
  // (BpmSettings::radius, times the iteration's radius scale as k0 and k1 are).
  float world_radius = 0;
  // With RadiusPolicy::kPerPixel, the settings whose schedule each pixel follows at its own pace
  // (DiscScales::of), the iteration's index (also for kContinueExploreEvery) and that of the
  // render's first; null: the radii above are the iteration's.
  const PhotonSettings* pixel_radii = nullptr;
  int iteration = 0, first_iteration = 0;
  // In a scattering medium the radii are never those of a shorter path than this
  // (photons/medium_radius.h).
  float medium_min_length = 0;
  // False where no light path can be a caustic (no material has a traced lobe,
  // may_have_caustics): then no backward photon accepts caustic photons.
  bool caustics = true;
  // Photons count only where the normals agree to within this cosine (PhotonSettings).
  float normal_cos = 0.5f;
  // Measure the share of each backward photon's disc where photons can land (disc_probes.h),
  // at first vertices seen directly only where near_edges marks the pixel (all when null), and
  // in media the surfaces that cut the discs across beams (photons/medium_cuts.h).
  bool disc_probes = true;
  const NearEdges* near_edges = nullptr;
  // Direct light in media also sampled along the rays that lead to diffuse vertices
  // (IntegratorOptions::equiangular).
  bool equiangular = true;
  // Eye paths toward their last diffuse vertex both scatter on every piece of their rays through
  // a scattering medium and cross it (BpmSettings::split_in_media).
  bool split_in_media = false;
  // Combined estimators (photons/merge_weights.h; BpmSettings::combine): the eye path goes on
  // from its last diffuse vertex on a surface for indirect light, weighed against the merge there
  // with merge_photons photons.
  CombineAt combine = CombineAt::kNowhere;
  double merge_photons = 0;
  // At the first vertex of a material with both parts (BsdfPart) where gathering would end the
  // path, it takes both parts instead of one by chance (BpmSettings::split_coats).
  bool split_coats = true;
  // Vertex connections (bpm/vertex_connections.h): the pixels they draw from (0: none). The first
  // backward photon of an eye path that accepts indirect light where paths are combined is their
  // target, and its merges and continuation are weighed against them.
  double vertex_pixels = 0;
};

struct EyeCounters {
  PathCounters rays;  // camera, bounce, shadow and probe rays
  uint64_t backward_photons = 0;
  uint64_t pixels = 0;  // pixels sampled (over the iterations)
  // The extra camera samples for emission, and the rays they cast (counted in `rays` too).
  uint64_t emission_samples = 0, emission_rays = 0;
  // The extra samples of direct light beyond the first, and the rays they cast (in `rays` too).
  uint64_t direct_samples = 0, direct_rays = 0;
  // Eye paths that went on past their last diffuse vertex (combined estimators), and their rays
  // (in `rays` too; the first, which the first direct sample shares, included).
  uint64_t continued = 0, continuation_rays = 0;
  // The vertices with traced lobes only and the medium vertices that continuations went through,
  // and their rays and shadow rays (with light to count) that got across a scattering medium.
  uint64_t continued_traced = 0, continued_in_media = 0, continued_through_media = 0;
  void add(const EyeCounters& o) {
    rays.add(o.rays);
    backward_photons += o.backward_photons;
    pixels += o.pixels;
    emission_samples += o.emission_samples;
    emission_rays += o.emission_rays;
    direct_samples += o.direct_samples;
    direct_rays += o.direct_rays;
    continued += o.continued;
    continuation_rays += o.continuation_rays;
    continued_traced += o.continued_traced;
    continued_in_media += o.continued_in_media;
    continued_through_media += o.continued_through_media;
  }
};

// Backward photons of one thread, one list per scene object (no locks: each thread has its own).
using ObjectPhotonLists = std::vector<std::vector<BackwardPhoton>>;

// The levels of the probability q = 2^-level of going on from a last vertex whose gathered lobes
// are not glossy (EyePixels::continue_level; continue_level below says why at least 1/16), and
// the level of q = 0: the merge alone, as the partition (but in every kContinueExploreEvery-th
// iteration, where such a pixel takes q = 2^-kMaxContinueLevel, so that it goes on measuring).
constexpr int kMaxContinueLevel = 4;
constexpr int kContinueLevels = kMaxContinueLevel + 1;
constexpr int kNeverContinue = 7;
constexpr int kContinueExploreEvery = 8;

// With CombineAt::kChosen, what the path's continuation from a last vertex whose gathered lobes
// are not glossy brought (taken with the probability q of EyePixels::continue_level, its light
// then divided by q): whether it met such a vertex, and if taken its rays and, for each level l,
// the second moment it would add to the pixel's estimate with q_l = 2^-l: its light X_l as the
// weights give it at q_l (each light found, of light y before the merge's part of its weight and
// a = the merge's density over the continuation's at q = 1, counts y q_l / (q_l + a)) squared
// over q_l, plus the merges' on the same paths, y^2 a / (q_l + a)^2 per light found (the balance
// heuristic's second moments of one sample of each, the merge's density a times the
// continuation's); the same at its own q (`moment_now`); and with q = 0, the merges' alone,
// y^2 / a, which only lights the merge could find (a > 0) allow: `unmergeable` counts the others.
// Light as means over the wavelengths.
struct EyeContinuation {
  bool at_vertex = false;
  double taken = 0, rays = 0, moment_now = 0, merges_alone = 0, unmergeable = 0;
  std::array<double, kContinueLevels> moment_at{};
  // Of the continuation under way (taken with the probability q; `start` clears them): X_l, the
  // merges' second moments, and the same at q; noted only where the pixel chose q (`noting`).
  bool noting = false;
  double q = 1, light_now = 0, merges_now = 0, merges_alone_now = 0, unmergeable_now = 0;
  std::array<double, kContinueLevels> light_at{}, merges_at{};
  void start(double probability, bool chosen) {
    noting = chosen;
    q = probability;
    light_at = merges_at = {};
    light_now = merges_now = merges_alone_now = unmergeable_now = 0;
  }
  // A light found with the weight w, of whose denominator the merge (with the vertex connection)
  // holds the share `merge_share`.
  void found(double light, double w, double merge_share) {
    if (!noting || !std::isfinite(light) || light == 0 || !(w > 0) || !(merge_share < 1)) return;
    const double y = light / (1 - merge_share), a = q * merge_share / (1 - merge_share);
    if (a > 0)
      merges_alone_now += y * y / a;
    else
      unmergeable_now += 1;
    light_now += light;
    merges_now += y * y * a / ((q + a) * (q + a));
    for (int l = 0; l < kContinueLevels; ++l) {
      const double ql = std::ldexp(1.0, -l);
      light_at[size_t(l)] += y * ql / (ql + a);
      merges_at[size_t(l)] += y * y * a / ((ql + a) * (ql + a));
    }
  }
  // The continuation under way ended, having cast `continuation_rays`.
  void add(uint64_t continuation_rays) {
    taken += 1;
    rays += double(continuation_rays);
    for (int l = 0; l < kContinueLevels; ++l) {
      const double ql = std::ldexp(1.0, -l);
      moment_at[size_t(l)] += light_at[size_t(l)] * light_at[size_t(l)] / ql + merges_at[size_t(l)];
    }
    moment_now += light_now * light_now / q + merges_now;
    merges_alone += merges_alone_now;
    unmergeable += unmergeable_now;
  }
};

// What an eye path counts itself: everything, and the part of it seen before the first diffuse
// vertex (emitters seen directly or through specular vertices only); and where it took two or
// more samples of direct light at its last vertex, their sample variance (of their means over the
// wavelengths; -1 where it took fewer); and what its continuations brought (EyeContinuation).
struct EyeRadiance {
  Spectrum total, emission;
  double direct_variance = -1;
  EyeContinuation continued;
};

// What a pixel's radii are scaled by in an iteration, its small discs' (k0) and the others' (k1):
// 1 where the radii above are already the iteration's. Under RadiusPolicy::kPerPixel a pixel
// follows the progressive schedule counted in the iterations that brought its discs photons: at
// iteration i, the schedule's scale at i times the share of its sampled iterations so far in which
// a disc of the kind received one (EyePixels::lit_share). A render whose first iteration is a > 0
// (IntegratorOptions::first_iteration) counts the iterations before it as lit: a + (i - a) share,
// so that with every share 1 it is the shared schedule, whatever a. Where photons reach every
// iteration that is the shared schedule; where they seldom do, the radius shrinks as seldom, as
// progressive photon mapping's per-point radii shrink with the photons found (Hachisuka et al.
// 2008), so that a dim pixel's estimate keeps the photons its noise needs and a bright one's still
// sharpens.
struct DiscScales {
  float small = 1, large = 1;
  static DiscScales of(const PhotonSettings& s, int iteration, int first,
                       const std::array<float, 2>& share) {
    const double rest = double(iteration - first);
    return {radius_scale_at(s, first + rest * share[0]),
            radius_scale_at(s, first + rest * share[1])};
  }
};

// Traces one eye path for `pixel`; returns the radiance the eye pass itself accounts for and
// appends the path's backward photons to out[object] (radii: k0 or k1 footprints). With
// emission_only the path ends at its first diffuse vertex and stores nothing: only `emission` is
// computed. near_edge: the pixel's mark_near_edges bits, which decide whether a first vertex seen
// directly probes its discs. The ray's weight is the throughput the path starts with. flight_u:
// when in [0, 1), the uniform number of the path's first free flight in a scattering medium
// (PathState::flight_u). direct_samples: the samples of direct light at the last diffuse vertex
// of a surface, at most params.direct_samples. continue_level: with CombineAt::kChosen, the path
// goes on from a last vertex whose gathered lobes are not glossy with the probability
// 2^-continue_level, never at kNeverContinue (EyeRadiance::continued). scales: the pixel's
// DiscScales.
EyeRadiance trace_eye_path(const RenderScene& scene, const EyePassParams& params, CameraRay ray,
                           PixelFootprint footprint, uint32_t pixel, Rng& rng,
                           ObjectPhotonLists& out, EyeCounters& counters,
                           bool emission_only = false, uint8_t near_edge = 3, float flight_u = -1,
                           int direct_samples = 1, int continue_level = 0, DiscScales scales = {});

// A pixel's statistics for its extra samples, over the iterations: of emission seen before the
// first diffuse vertex (per camera sample) and of the rest of its estimate (per iteration), for
// the emission samples (counts, sums and sums of squares of means over the wavelengths); the sum
// of 1 / the direct samples it took per estimate (the estimates' own moments are PixelMoments,
// bpm/accumulate.h) and the sample variances of its direct light at one vertex, for the direct
// samples; and what its continuations brought (EyeContinuation), for their probability; and in
// how many of its iterations its discs received photons, for its radii (DiscScales).
template <class T>
struct SampleStats {
  static constexpr int kValues = 13 + kContinueLevels + 2 + 3;
  // Where each group starts in v: count, sum and sum of squares for the first two; then the sum
  // of 1 / direct samples over the estimates, and the count and sum of direct variances; then the
  // iterations whose path met a vertex where the continuation is chosen, and of the continuations
  // taken the count, rays, the second moments they added and would add at each level and with
  // q = 0, and the lights only they find (EyeContinuation); then the iterations accumulated, and
  // those in which a small disc, and another disc, received photons.
  enum : int {
    kEmission = 0,
    kRest = 3,
    kInverseSamples = 6,
    kDirect = 7,
    kContinued = 9,
    kContinuedLevels = 13,
    kContinuedNever = 13 + kContinueLevels,
    kLit = 13 + kContinueLevels + 2
  };
  std::array<T, kValues> v{};
  // Non-finite values (numerical accidents) are left out.
  void add_emission(double x) { add(kEmission, x); }
  void add_rest(double x) { add(kRest, x); }
  void add_direct_taken(int direct_samples) { v[kInverseSamples] += T(1.0 / direct_samples); }
  void add_direct_variance(double s2) {
    if (!std::isfinite(s2) || s2 < 0) return;
    v[kDirect] += 1;
    v[kDirect + 1] += T(s2);
  }
  void add_continuation(const EyeContinuation& c) {
    if (!c.at_vertex) return;
    v[kContinued] += 1;
    v[kContinued + 1] += T(c.taken);
    v[kContinued + 2] += T(c.rays);
    v[kContinued + 3] += T(c.moment_now);
    for (int l = 0; l < kContinueLevels; ++l) v[kContinuedLevels + l] += T(c.moment_at[size_t(l)]);
    v[kContinuedNever] += T(c.merges_alone);
    v[kContinuedNever + 1] += T(c.unmergeable);
  }
  void add_lit(bool small, bool large) {
    v[kLit] += 1;
    v[kLit + 1] += T(small);
    v[kLit + 2] += T(large);
  }
  // The shares of the iterations in which the small and the other discs received photons: 1
  // before any is known.
  std::array<float, 2> lit_share() const {
    if (!(v[kLit] > 0)) return {1, 1};
    return {float(v[kLit + 1] / v[kLit]), float(v[kLit + 2] / v[kLit])};
  }
  T emission_n() const { return v[kEmission]; }
  T rest_n() const { return v[kRest]; }
  T direct_n() const { return v[kDirect]; }
  // The mean of the direct variances.
  double direct_variance() const { return double(v[kDirect + 1]) / double(v[kDirect]); }
  // The sample variance of the values added at `at` (kEmission or kRest); 0 with fewer than two.
  double variance(int at) const {
    const double n = double(v[size_t(at)]), sum = double(v[size_t(at) + 1]),
                 sum2 = double(v[size_t(at) + 2]);
    return n < 2 ? 0.0 : std::max(0.0, (sum2 - sum * sum / n) / (n - 1));
  }

 private:
  void add(int at, double x) {
    if (!std::isfinite(x)) return;
    v[size_t(at)] += 1;
    v[size_t(at) + 1] += T(x);
    v[size_t(at) + 2] += T(x * x);
  }
};

// Camera samples per iteration for the emission of a pixel that has seen some, from its
// statistics over the iterations so far: with C the cost of an iteration per pixel without extra
// samples and c that of one extra sample, the count E that makes the pixel's variance V_rest +
// V_emission / E times its cost C + (E - 1) c least: E = sqrt(cost_ratio V_emission / V_rest)
// rounded, where cost_ratio = C / c - 1. Within [1, max_samples]: 1 until both parts have two
// samples, then max_samples while the cost ratio is unknown (negative).
int emission_sample_count(const SampleStats<double>& s, double cost_ratio, int max_samples);

// A pixel's count of extra samples (emission or direct, from the rules above) under adaptive
// sampling, given the rate of iterations its error asks for (`asked`, asked_pass_rates in
// bpm/accumulate.h; < 0: unknown, the count as it is) and the floor of its sampling probability.
// The rules balance extra samples against the pixel's own iterations, whose rate its error sets;
// where the floor samples it more often than that, it takes fewer in proportion (at least one).
// A pixel whose estimate is its emission alone (`emission_alone`: the rest never varied; the sky,
// a light against black) gains from extra samples nothing that more iterations of it would not
// give at the same cost: it takes as many as its error asks for beyond one an iteration, which its
// sampling probability (at most 1) cannot give, within [1, count].
int at_asked_rate(int count, float asked, float floor, bool emission_alone);

// A pixel's camera samples land within its filter's radius of its centre, so a pixel whose centre
// lies within twice that radius (`filter_radius`, in pixels) of one that saw emission may see it
// too: an emitter's edge, or a small bright emitter that its samples reach a few times in a
// thousand. Until it has two samples of emission in its own statistics, such a pixel takes the
// most emission samples (EyePixels::emission_samples) of the pixels about it that have; else its
// first sight of a small emitter may wait for most of the render, with one sample an iteration
// where its neighbours take several. Pixels with statistics keep their own counts.
struct EyePixels;
void lend_emission_samples(int width, int height, Vec2 filter_radius, EyePixels* pixels);

// Samples of direct light per iteration at a pixel's last diffuse vertex, by the same balance:
// V_direct is the mean sample variance of direct light at one vertex (what more samples there
// average away), V_rest what remains of the variance of the pixel's estimate per iteration (its
// sample variance over its `estimates` estimates, less V_direct times the mean of 1 / the samples
// it took). Within [1, max_samples]: 2 (at most max_samples) until the statistics and the cost
// ratio are known; max_samples where nothing but direct light varies.
int direct_sample_count(const SampleStats<double>& s, double estimates, double estimate_variance,
                        double cost_ratio, int max_samples);

// The probability q = 2^-level with which the pixel's eye paths go on from last vertices whose
// gathered lobes are not glossy (CombineAt::kChosen), by the same balance: the level l whose
// (V_fixed + r V_l) (C + r q_l c) is least, where r is the share of the iterations that met such
// a vertex, V_l the second moment a continuation met would add with q_l (with the merges' on its
// paths, which the weights hand back to them as q falls: EyeContinuation), c its rays, C an
// iteration's rays per pixel (`base_rays`, the light pass's included) and V_fixed the rest of the
// estimate's variance (its variance less r times the second moment the continuations added at the
// probabilities they were taken with; at least 2% of it). Levels 0 to kMaxContinueLevel, or
// kNeverContinue (q = 0, cost C) where no continuation measured found light that the merge cannot
// find; of equal products the cheaper. 1 until two continuations and two estimates are known. At
// least 1/16 but for q = 0: once a round (a quarter of the iterations before it) has 16
// iterations, a pixel still takes a continuation about once a round, and what it measures keeps
// up with the radii as they shrink. Where q = 0 wins in every pixel, no backward photon is
// combined and the photons carry no densities: the partition's cost.
int continue_level(const SampleStats<double>& s, double estimates, double estimate_variance,
                   double base_rays);

// Pixel p's statistics (of a width x height image) with those of its direct light's variance and
// of its continuations (with the iterations counted) summed over it and its eight neighbours, for
// direct_sample_count and continue_level; the rest its own. What these measure is often rare: the
// light a continuation finds (a wall that BSDF samples from an open floor seldom reach), a shadow's
// edge that one of a pixel's direct samples crosses now and then. A pixel's own few samples tend to
// miss it, so that its figure reads too small, and the rule then gives it fewer samples still (one
// direct sample measures no variance at all). Its neighbours see nearly the same scene around them:
// nine pixels' samples (six at an edge, four at a corner) estimate it from that many times as many.
// Pooled are the sums themselves, so that a pooled variance also holds the spread between the
// pixels' means.
SampleStats<double> with_neighbours_rare(const std::vector<SampleStats<double>>& stats, int width,
                                         int height, size_t p);

// What the eye pass leaves per pixel for the accumulation (stage 4) and the masks.
struct EyePixels {
  std::vector<Spectrum> radiance;    // the eye pass's own part of the pixel's estimate
  std::vector<float> filter_weight;  // of the pixel's camera sample
  std::vector<float> cost_ns;        // time spent on the pixel, to rebuild the masks
  std::vector<uint8_t> sampled;      // whether this iteration samples the pixel
  // Whether a sample of the pixel in an earlier round (integrator/control.h) saw emission before
  // its first diffuse vertex; saw_emission marks those of this round, merged at its end.
  std::vector<uint8_t> sees_emission, saw_emission;
  // Camera samples per iteration for the pixel's emission (emission_sample_count, set at the end
  // of each round), and the part of this iteration's estimate that is their mean (over the
  // wavelengths).
  std::vector<uint16_t> emission_samples;
  std::vector<float> emission_part;
  // Samples of direct light per iteration at the pixel's last vertex (direct_sample_count, set
  // at the end of each round; at most EyePassParams::direct_samples of them are taken).
  std::vector<uint16_t> direct_samples;
  // With CombineAt::kChosen, the level of the probability 2^-level that the pixel's paths go on
  // from a last vertex whose gathered lobes are not glossy (continue_level, set at the end of each
  // round).
  std::vector<uint8_t> continue_level;
  // Under RadiusPolicy::kPerPixel, the shares of the pixel's iterations so far in which its small
  // and its other discs received photons (SampleStats::lit_share, set at the end of each round).
  std::vector<std::array<float, 2>> lit_share;
  // The pixels' statistics for their extra samples (the emission ones only of pixels that see
  // emission): of every round so far, and of this round (summed over processes at its end).
  std::vector<SampleStats<double>> sample_stats;
  std::vector<SampleStats<double>> round_stats;
  explicit EyePixels(size_t n)
      : radiance(n),
        filter_weight(n),
        cost_ns(n),
        sampled(n, 0),
        sees_emission(n, 0),
        saw_emission(n, 0),
        emission_samples(n, 1),
        emission_part(n, 0.0f),
        direct_samples(n, 2),
        continue_level(n, 0),
        lit_share(n, {1.0f, 1.0f}),
        sample_stats(n),
        round_stats(n) {}
};

// Per-thread state the eye pass fills.
struct EyeThreadData {
  tbb::enumerable_thread_specific<ObjectPhotonLists>& lists;
  tbb::enumerable_thread_specific<EyeCounters>& counters;
};

// Runs the eye pass of pass `pass` (random streams keyed by `pass_index`) over every pixel the
// control samples. Returns false when control.cut(pass) left pixels out: the backward photons are
// then dropped.
bool run_eye_pass(const RenderScene& scene, const EyePassParams& params,
                  const CameraSampler& camera, const PixelMasks& masks,
                  const RenderControl& control, int pass, int pass_index, EyePixels* pixels,
                  EyeThreadData threads);

}  // namespace bpm
