#include "bpm/eye_pass.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include "integrator/direct_light.h"
#include "integrator/path_vertex.h"
#include "photons/disc_probes.h"
#include "photons/medium_cuts.h"
#include "photons/merge_weights.h"

namespace bpm {
namespace {

// A backward photon at diffuse vertex v (the diffuse-th of its path) that accepts `accepts`.
// Caustic light at the first diffuse vertex is gathered over the small radius (k0); everything
// gathered at a later vertex, and indirect light anywhere, over the large one (k1); each times the
// pixel's scale for its kind.
BackwardPhoton backward_photon_at(const PathVertex& v, const PathState& s, const EyePassParams& prm,
                                  PixelFootprint footprint, DiscScales scales, uint32_t pixel,
                                  int depth, int diffuse, uint8_t accepts) {
  BackwardPhoton bp;
  bp.p = v.sp.p;
  const bool small = diffuse == 1 && accepts == kAcceptsCaustic;
  const float length = v.medium >= 0 ? std::max(s.length, prm.medium_min_length) : s.length;
  bp.radius =
      (prm.world_radius > 0 ? prm.world_radius : footprint.at(length) * (small ? prm.k0 : prm.k1)) *
      (small ? scales.small : scales.large);
  bp.ng = v.sp.ng;
  bp.ns = v.sp.ns;
  bp.uv = v.sp.uv;
  bp.wo = v.wo;
  bp.tau = s.beta;
  bp.pixel = pixel;
  bp.material = v.medium >= 0 ? 0 : uint32_t(v.material_index);
  bp.medium = int16_t(v.medium);
  bp.eye_depth = uint16_t(std::min(depth, 65535));
  bp.accepts = accepts;
  bp.diffuse_index = uint8_t(diffuse - 1);
  bp.hero_only = s.hero_only;
  return bp;
}

// What every vertex of one eye path shares: where its backward photons go, and its counters.
struct EyePath {
  const RenderScene& scene;
  const EyePassParams& prm;
  PixelFootprint footprint;
  DiscScales scales;
  uint32_t pixel;
  uint8_t near_edge;
  Rng& rng;
  ObjectPhotonLists& out;
  EyeCounters& counters;
  int& stored;              // backward photons stored so far (BackwardPhoton::place)
  int& splits;              // medium vertices drawn where the path splits (gather_forced_in_medium)
  int direct_samples;       // at the last diffuse vertex of a surface
  double& direct_variance;  // of those samples, where there are two or more (EyeRadiance)
  int continue_level;       // EyePixels::continue_level
  EyeContinuation& continued;
  bool& targeted;  // a backward photon of this path is the vertex connections' target
};

// Direct light at v by next-event estimation, shared by MIS with the BSDF sample that goes on.
inline Spectrum direct_light_at(const EyePath& path, const PathVertex& v, const PathState& s,
                                BsdfPart part) {
  return s.beta * sample_direct_light(path.scene, v.sp, v.object(), s.medium, v.m(), v.frame,
                                      v.wo_local, true, *path.prm.materials, path.rng,
                                      path.counters.rays, part);
}

// The surface that cuts the discs about a point in a medium (photons/medium_cuts.h), found for the
// first radius stored there and kept for any smaller one.
struct MediumCut {
  float radius = 0;
  Vec3 offset;
};

// Stores one backward photon at diffuse vertex v. Where its disc may be cut (disc_probes.h) and
// is not whole on plain sight, it is probed after the light pass, if it gathers light
// (bpm/disc_shares.h); where a larger disc about the same point was whole on plain sight
// (`larger`), so is this one. (A larger disc left to its probes tells this one nothing: it is
// looked at, and probed, on its own.) Returns what was found of the disc (nothing: not looked
// at). With merge_density, the eye path goes on from the vertex (combined estimators): the
// backward photon is marked so, and *merge_density set to its pi r^2 N (0 where none is stored).
// In a medium, `cut` keeps the surface that cuts the discs about v (MediumCut).
inline DiscProbes store_backward_photon(const EyePath& path, const PathVertex& v,
                                        const PathState& s, int depth, int diffuse,
                                        bool seen_directly, uint8_t accepts,
                                        const DiscProbes& larger, double* merge_density,
                                        uint8_t continue_level, MediumCut& cut) {
  const EyePassParams& prm = path.prm;
  BackwardPhoton bp = backward_photon_at(v, s, prm, path.footprint, path.scales, path.pixel, depth,
                                         diffuse, accepts);
  if (bp.radius <= 0 || s.beta.is_black()) return {};
  bp.combined = merge_density != nullptr;
  bp.continue_level = merge_density ? continue_level : 0;
  bp.place = uint8_t(path.stored++);
  // The vertex connections' target: the path's first backward photon for indirect light where
  // paths are combined (vertex_connections.h).
  if (prm.vertex_pixels > 0 && !path.targeted && (accepts & kAcceptsIndirect) && v.medium < 0 &&
      combinable_vertex(v))
    bp.vertex_target = path.targeted = true;
  if (v.medium >= 0) {  // after the objects' lists, one per medium
    if (prm.disc_probes && cut.radius < bp.radius) {
      cut.offset = medium_cut(path.scene, v.sp.p, v.piece.ray.d, v.piece.length - v.piece.t,
                              v.piece.t, bp.radius, path.counters.rays);
      cut.radius = bp.radius;
    }
    bp.ng = cut.offset;
    path.out[path.scene.objects.size() + size_t(v.medium)].push_back(bp);
    ++path.counters.backward_photons;
    return {};
  }
  const uint8_t near_bit = diffuse == 1 && accepts == kAcceptsCaustic ? 2 : 1;
  DiscProbes probes;
  // A larger disc about the same point was whole on plain sight: so is this one.
  const bool larger_whole = larger.found && !larger.cut;
  if (!larger_whole && prm.disc_probes && (!seen_directly || (path.near_edge & near_bit)) &&
      may_cut_discs(path.scene.objects[size_t(v.object())].shape)) {
    if (disc_plainly_whole(path.scene, v.sp, v.object(), v.hit.primitive, bp.radius,
                           prm.normal_cos)) {
      probes.found = bp.disc_found = 0xff;
    } else {
      probes.looked = true;
      bp.cut_off_tested = 1;
      bp.probes_pending = 1;
      bp.set_error(v.sp.error);
    }
  }
  if (merge_density) *merge_density = kPi * double(bp.radius) * bp.radius * prm.merge_photons;
  path.out[size_t(v.object())].push_back(bp);
  ++path.counters.backward_photons;
  return probes;
}

// Caustic light at x_1..x_(D+1), indirect light at x_(D+1) only. With D = 0 the first vertex is
// also the last: two backward photons, one per radius. With merge_density, the one that accepts
// indirect light is combined with the eye path's continuation (store_backward_photon), which goes
// on with the probability 2^-continue_level.
inline void store_backward_photons(const EyePath& path, const PathVertex& v, const PathState& s,
                                   int depth, int diffuse, bool last,
                                   double* merge_density = nullptr, uint8_t continue_level = 0) {
  const EyePassParams& prm = path.prm;
  // Seen straight from the camera: the screen around the pixel says whether its discs may be
  // cut (disc_probes.h).
  const bool seen_directly = diffuse == 1 && depth == 1;
  MediumCut cut;
  auto store = [&](uint8_t accepts, const DiscProbes& larger) {
    return store_backward_photon(path, v, s, depth, diffuse, seen_directly, accepts, larger,
                                 accepts & kAcceptsIndirect ? merge_density : nullptr,
                                 continue_level, cut);
  };
  if (!prm.caustics) {
    if (last) store(kAcceptsIndirect, {});
  } else if (!last) {
    store(kAcceptsCaustic, {});
  } else if (diffuse > 1 || prm.world_radius > 0 || prm.k0 == prm.k1) {
    store(kAcceptsCaustic | kAcceptsIndirect, {});
  } else {
    // The disc of r1 first (the larger, unless the pixel's scales make r0 larger).
    const DiscProbes larger = store(kAcceptsIndirect, {});
    const bool smaller = prm.k0 * path.scales.small < prm.k1 * path.scales.large;
    store(kAcceptsCaustic, smaller ? larger : DiscProbes{});
  }
}

// Direct light at the last diffuse vertex, where the path ends: the mean of path.direct_samples
// samples, each next-event estimation and a BSDF sample that only looks for the light, shared by
// MIS (none where every light is a point or a direction: those next-event estimation counts in
// full). Where the eye path went on from v, its first BSDF sample is the first sample's
// (`first_found`: the light it found, weighed so). The samples beyond the first are counted
// apart, and the sample variance of two or more goes to path.direct_variance.
inline Spectrum direct_light_at_last(const EyePath& path, const PathVertex& v, const PathState& s,
                                     BsdfPart part, const Spectrum* first_found) {
  const int n = path.direct_samples;
  uint64_t first_rays = 0;  // the rays counted after the first sample
  Spectrum sum;
  double mean = 0, m2 = 0;  // Welford's running mean and squared deviations
  for (int k = 0; k < n; ++k) {
    if (k == 1) first_rays = path.counters.rays.total();
    const Spectrum d =
        direct_light_at(path, v, s, part) +
        (k == 0 && first_found ? *first_found
                               : direct_light_by_bsdf(path.scene, *path.prm.materials, v, s, part,
                                                      path.rng, path.counters.rays));
    sum += d;
    const double x = d.average(), delta = x - mean;
    mean += delta / (k + 1);
    m2 += delta * (x - mean);
  }
  if (n < 2) return sum;
  path.counters.direct_samples += uint64_t(n - 1);
  path.counters.direct_rays += path.counters.rays.total() - first_rays;
  path.direct_variance = m2 / (n - 1);
  return sum / float(n);
}

// Where the eye path goes on past its last diffuse vertex x (combined estimators,
// photons/merge_weights.h): a vertex e_j, j from 1, with the running ratio of the merge's density
// to the continuation's for the path so far (merge_density times A of x .. e_(j-2), over B of
// e_1 .. e_j), the vertex before (e_0 = x; on a surface or in a medium) and the eye's BSDF (or
// phase) density there of the way to e_j.
struct Continuation {
  double ratio;
  DensityEnd here;  // the vertex the path is at (x, then e_j: density_end)
  DensityEnd prev;
  double pdf_prev = 0;  // for a delta lobe the probability of choosing it
  // The vertex before has traced lobes only (no next-event estimation there); one of e_1 ..
  // e_(j-1) has gathered lobes (else the light found is a caustic at x, the merge's alone).
  bool prev_traced = false, gathered = false;
  // |cos| (sigma in a medium: DensityEnd) at the vertex before toward e_j; their squared distance
  double cos_prev = 0, d2 = 1;
  // The probability that a free flight gets across the media between the vertex before and e_j
  // (PathState::pass), which next-event estimation's density is divided by there: its
  // shadow ray gets across for certain, where the BSDF sample and the photon get across with it.
  double pass = 1;
  // Where x is the vertex connections' target: 1 / (pi r^2 P), so that their density over the
  // merge's is vertex_scale / A(x) (vertex_connections.h), with A(x) the photon's density of x
  // from e_1 times the first segment's pass probability (a_x, known from j = 2 on; infinite where
  // e_1 is traced or in a medium: no connection joins it); else 0.
  double vertex_scale = 0, a_x = 0;
  // The path leaves e_(j-1) = v (traced: its lobes are all traced) by the sample bs of `lobes`.
  void leave(const PathVertex& v, const BsdfSample& bs, BsdfPart lobes, bool traced, int j) {
    const float delta = delta_choice_probability(bs);
    pdf_prev =
        delta > 0 ? delta : bsdf_pdf(v.m(), v.wo_local, bs.wi, TransportMode::kRadiance, lobes);
    prev_traced = traced;
    gathered = gathered || (j > 1 && !traced);
    prev = here;
  }
  // It leaves the medium vertex it is at by a phase sample of density `phase`.
  void leave_medium(float phase) {
    pdf_prev = phase;
    prev_traced = false;
    gathered = true;
    prev = here;
  }
};

// The merge's term of a continued path's weight with the vertex connections' added: both over the
// continuation's density, a_x the photon's density of x from e_1.
inline double merge_and_connection(double merge, const Continuation& c, double a_x) {
  return c.vertex_scale > 0 && a_x > 0 ? merge * (1 + c.vertex_scale / a_x) : merge;
}

// A continued path's weight, and the share of its denominator that the merge at x (with the
// vertex connection) holds (EyeContinuation::found).
struct ContinuedWeight {
  double w = 0, merge_share = 0;
  static ContinuedWeight of(double own, double continued, double others) {
    const double sum = continued + others;
    return {own / sum, others / sum};
  }
};

// The weight of light found by the BSDF sample that left e_(j-1) (c.prev): the point y of
// light `li` (normal n; for a light at infinity, a point far along the sample's direction),
// weighed against next-event estimation there and the merge at x.
inline ContinuedWeight found_light_weight(const RenderScene& scene, const Continuation& c, int li,
                                          Vec3 y, Vec3 n) {
  const Light& light = scene.lights[size_t(li)];
  const Vec3 d = y - c.prev.p;
  const float len = length(d);
  if (!(len > 0)) return {};
  const double b_bsdf = light_end_density(light, c.pdf_prev, c.prev.p, y, n);
  if (!(c.pass > 0)) return {};
  const double b_light =
      c.prev_traced ? 0.0 : light_sample_density(scene, li, c.prev.p, y, n) / c.pass;
  const double merge = c.ratio * emission_density(scene, li, y, n, -d / len, c.prev);
  return ContinuedWeight::of(b_bsdf, b_bsdf + b_light, merge_and_connection(merge, c, c.a_x));
}

// Light Le (before its weight) found by the continuation with the throughput beta: its weighed
// light, noted for the pixel's choice of q.
inline Spectrum found_light(const EyePath& path, const Spectrum& beta, const Spectrum& Le,
                            ContinuedWeight cw) {
  if (!std::isfinite(cw.w) || !(cw.w > 0)) return {};
  const Spectrum L = beta * Le * float(cw.w);
  path.continued.found(L.average(), cw.w, cw.merge_share);
  return L;
}

// The environment lights found by the BSDF sample that left e_(j-1) and escaped along dir, weighed
// as found_light_weight says.
inline Spectrum found_environment(const EyePath& path, const Continuation& c, Vec3 dir,
                                  const Spectrum& beta) {
  const RenderScene& scene = path.scene;
  Spectrum L;
  const Vec3 far = c.prev.p + dir * (2 * scene.bounds_info.radius);
  for (const int li : scene.infinite_lights) {
    const Spectrum Le = environment_radiance(scene.lights[size_t(li)], dir, path.prm.materials->wl);
    if (!Le.is_black()) L += found_light(path, beta, Le, found_light_weight(scene, c, li, far, {}));
  }
  return L;
}

// The weight of next-event estimation's sample of a light at e_j (`at`), against the BSDF (or
// phase) sample that could find it (an area or environment light), of density eye_pdf there, and
// the merge at x, whose photon leaves e_j toward e_(j-1) with the density photon_pdf.
inline ContinuedWeight continued_light_weight(const RenderScene& scene, const Continuation& c,
                                              const LightSampleAt& sample, const DensityEnd& at,
                                              double eye_pdf, double photon_pdf) {
  const int li = sample.light;
  const LightLiSample& ls = sample.ls;
  // A delta light: next-event estimation's density and the emission's without their delta, and
  // none for the BSDF sample.
  const double b_light =
      light_sample_density(scene, li, at.p, ls.p_light, ls.n_light) / double(sample.pass);
  const double b_bsdf =
      light_end_density(scene.lights[size_t(li)], eye_pdf, at.p, ls.p_light, ls.n_light);
  // The photon's densities: the light's point and direction, e_j from there, e_(j-1) from e_j.
  const double a_prev = photon_pdf * c.cos_prev / c.d2;
  const double merge =
      c.ratio * a_prev * emission_density(scene, li, ls.p_light, ls.n_light, -ls.wi, at);
  // At e_1, A(x) is the photon's density from here, with the first segment's pass probability
  // (PhotonMis::arrival_density); no connection joins a point in a medium to x.
  const double a_x = c.a_x > 0      ? c.a_x
                     : at.sigma > 0 ? std::numeric_limits<double>::infinity()
                                    : a_prev * c.pass;
  return ContinuedWeight::of(b_light, b_light + b_bsdf, merge_and_connection(merge, c, a_x));
}

// The light of next-event estimation's sample with its weight, f its BSDF (or phase) times
// transmittance.
inline Spectrum weighted_light_sample(const EyePath& path, const PathState& s,
                                      const LightSampleAt& sample, const Spectrum& f,
                                      ContinuedWeight cw) {
  if (!std::isfinite(cw.w)) return {};
  if (sample.pass < 1) ++path.counters.continued_through_media;
  return found_light(
      path, s.beta,
      f * sample.ls.radiance * float(1 / (double(sample.pmf) * sample.ls.pdf_solid_angle)), cw);
}

// At e_j (v, on a surface), next-event estimation of a light (continued_light_weight).
inline Spectrum continued_light_sample(const EyePath& path, const PathVertex& v, const PathState& s,
                                       const Continuation& c) {
  const RenderScene& scene = path.scene;
  const auto sample = sample_light_at(scene, v.sp, v.object(), s.medium, v.m(), v.frame, v.wo_local,
                                      *path.prm.materials, path.rng, path.counters.rays);
  if (!sample || !(sample->pass > 0)) return {};
  const Vec3 wi_local = sample->wi_local;
  // The share a photon from the light would draw through v's gathered part (merge_weights.h).
  const float g =
      bsdf_gathered_probability(v.m(), wi_local, v.wo_local, TransportMode::kImportance);
  if (!(g > 0)) return {};
  const ContinuedWeight w = continued_light_weight(
      scene, c, *sample, c.here, bsdf_pdf(v.m(), v.wo_local, wi_local, TransportMode::kRadiance),
      double(g) * bsdf_pdf(v.m(), wi_local, v.wo_local, TransportMode::kImportance));
  return weighted_light_sample(path, s, *sample, sample->f * g, w);
}

// At e_j (v, in a medium), next-event estimation of a light (continued_light_weight; the phase
// function's density is the same both ways).
inline Spectrum continued_light_sample_in_medium(const EyePath& path, const PathVertex& v,
                                                 const PathState& s, const Continuation& c) {
  const RenderScene& scene = path.scene;
  const float g = scene.media[size_t(v.medium)].g;
  const auto sample =
      sample_light_in_medium(scene, v, g, *path.prm.materials, path.rng, path.counters.rays);
  if (!sample || !(sample->pass > 0)) return {};
  const double phase = henyey_greenstein(dot(-v.wo, sample->ls.wi), g);
  const ContinuedWeight w = continued_light_weight(scene, c, *sample, c.here, phase, phase);
  return weighted_light_sample(path, s, *sample, sample->f, w);
}

// Past e_1 (j > 1), at e_(j-1) = v (traced: its lobes are all traced) left by the sample bs with
// the throughput `beta`: the photons' gathered share at v, arriving from e_j (all of it where
// traced), then Russian roulette on the change of throughput; false where the path ends, else
// s.beta and c updated (c.ratio times A of e_(j-2), x at j = 2, from v).
inline bool survives_past(const PathVertex& v, bool traced, const BsdfSample& bs, Spectrum beta,
                          int j, Rng& rng, PathState& s, Continuation& c) {
  const float g =
      traced ? 1.0f
             : bsdf_gathered_probability(v.m(), bs.wi, v.wo_local, TransportMode::kImportance);
  if (!(g > 0)) return false;
  beta *= g;
  const float q = std::fmax(0.0f, 1 - beta.max_component() / s.beta.max_component());
  if (rng.uniform() < q) return false;
  s.beta = beta / (1 - q);
  const double a = combined_density(v, bs.wi, v.wo_local, TransportMode::kImportance,
                                    delta_choice_probability(bs)) *
                   c.cos_prev / c.d2;
  c.ratio *= a;
  // A(x) counts the first segment's pass probability, as PhotonMis::arrival_density does.
  if (j == 2) c.a_x = traced ? std::numeric_limits<double>::infinity() : a * c.pass;
  return true;
}

// Past e_1, at e_(j-1) = v in a medium, reached with the throughput beta_flight before its free
// flight: Russian roulette on the change since (the medium's albedo), as a photon's there, then a
// phase sample (its weight is 1; its density the same both ways, which is also the photon's of
// e_(j-2) from v). False where the path ends, else s and c updated.
inline bool leave_medium_vertex(const RenderScene& scene, const PathVertex& v,
                                const Spectrum& beta_flight, int j, Rng& rng, PathState& s,
                                Continuation& c) {
  const float q = std::fmax(0.0f, 1 - s.beta.max_component() / beta_flight.max_component());
  if (rng.uniform() < q) return false;
  s.beta /= 1 - q;
  const PhaseSample ps = sample_phase(v, scene.media[size_t(v.medium)].g, rng);
  const float phase = ps.emitter.pdf_bsdf;
  if (!(phase > 0)) return false;
  const double a = double(phase) * c.cos_prev / c.d2;
  c.ratio *= a;
  if (j == 2) c.a_x = std::numeric_limits<double>::infinity();  // no connection joins e_1 to x
  c.leave_medium(phase);
  s.ray = Ray{v.sp.p, ps.wi, kInf};
  return true;
}

// The continuation's first BSDF sample, which is also the first of x's direct samples
// (continue_eye_path): the light it finds, and whether that sample would have cast its ray.
struct FirstSample {
  Spectrum found;
  bool shared = false;
};

// At e_(j-1) = v on a surface (x where j = 1), the BSDF sample that leaves it toward e_j of the
// lobes x gathers with (part) or of all, Russian roulette past x (survives_past), s.ray and c
// updated. `found` is how the ray weighs the light it finds (at x: as the direct sample's), and
// `look_only` whether the ray only looks for the light (a traced lobe at x). False where the path
// ends.
inline bool leave_surface_vertex(const EyePath& path, const PathVertex& v, int j, BsdfPart part,
                                 PathState& s, Continuation& c, FirstSample& first,
                                 EmitterWeight& found, bool& look_only) {
  const RenderScene& scene = path.scene;
  const float uc = path.rng.uniform();
  const Vec2 u{path.rng.uniform(), path.rng.uniform()};
  const BsdfPart lobes = j == 1 ? part : BsdfPart::kAll;
  const auto bs = sample_bsdf(v, uc, u, TransportMode::kRadiance, lobes);
  // Past x a delta lobe is followed where every lobe is traced (not a coat's alone).
  const bool traced = j > 1 && bsdf_all_traced(v.m());
  if (!bs || (bs->is_specular() && !traced)) return false;
  // At x a traced lobe's sample only looks for the light, as the direct sample's would.
  look_only = j == 1 && bs->is_traced();
  if (look_only && !scene.bsdf_finds_lights) return false;
  const Spectrum beta = s.beta * bs->f * (std::fabs(bs->wi.z) / bs->pdf_solid_angle);
  if (j == 1)
    s.beta = beta;
  else if (!survives_past(v, traced, *bs, beta, j, path.rng, s, c))
    return false;
  if (s.beta.is_black() || !s.beta.is_finite()) return false;
  c.leave(v, *bs, lobes, traced, j);
  leave_vertex(scene, v, v.frame.to_world(bs->wi), s);
  if (j == 1 && scene.bsdf_finds_lights) {
    found = EmitterWeight::mis(bs->mis_pdf, v.sp.p);
    first.shared = scene.may_reach_emitter(s.ray);
    if (look_only && !first.shared) return false;  // it can find no light: no ray, as the direct's
  }
  return true;
}

// At e_j (e), where the continuation's ray ended (end), having left the vertex before (c.prev):
// the light it found, weighed; then, where the path may go on from e_j (`vertices` scattering
// events from the camera within maxdepth, a combinable vertex), B of e_j in c.ratio and
// next-event estimation there. False where the path ends.
inline bool arrive_at(const EyePath& path, const PathVertex& e, StepEnd end, int vertices,
                      PathState& s, Continuation& c, Spectrum& L) {
  const RenderScene& scene = path.scene;
  const Wavelengths& wl = path.prm.materials->wl;
  if (c.pass < 1 && (end == StepEnd::kVertex || end == StepEnd::kEscaped))
    ++path.counters.continued_through_media;
  if (end == StepEnd::kEscaped && c.gathered) L += found_environment(path, c, s.ray.d, s.beta);
  const bool in_medium = end == StepEnd::kMedium;
  if (end != StepEnd::kVertex && !in_medium) return false;
  c.here = density_end(scene, e, wl);
  const Vec3 d = e.sp.p - c.prev.p;
  c.d2 = double(length_squared(d));
  if (!(c.d2 > 0)) return false;
  const double len = std::sqrt(c.d2);
  c.cos_prev = c.prev.factor(d, len);
  // Emission found by the BSDF sample of e_(j-1) (x's own is its direct light): a path of j - 1
  // vertices between the light and x.
  const int li = in_medium ? -1 : scene.light_of_hit(e.hit);
  if (c.gathered && li >= 0) {
    const Spectrum Le = area_light_radiance(std::get<AreaLight>(scene.lights[size_t(li)]), e.sp.ng,
                                            e.sp.uv, -s.ray.d, wl);
    if (!Le.is_black())
      L += found_light(path, s.beta, Le, found_light_weight(scene, c, li, e.sp.p, e.sp.ng));
  }
  // Paths of j vertices between the light and x: within the merge's depth.
  if (vertices > path.prm.max_depth || !combinable_vertex(e)) return false;
  if (!in_medium) {
    if (e.wo_local.z == 0) return false;
    keep_hero_wavelength_at(e, s);
  }
  c.ratio /= c.pdf_prev * c.here.factor(d, len) / c.d2;  // B of e_j
  if (!std::isfinite(c.ratio)) return false;
  if (in_medium) {
    ++path.counters.continued_in_media;
    L += continued_light_sample_in_medium(path, e, s, c);
  } else if (bsdf_all_traced(e.m()))
    ++path.counters.continued_traced;
  else
    L += continued_light_sample(path, e, s, c);
  return true;
}

// Indirect light at the last diffuse vertex x by the eye path's continuation (combined
// estimators, photons/merge_weights.h): BSDF samples from x on, through combinable vertices, each
// finding lights by next-event estimation (but where its lobes are all traced) and by its BSDF
// sample, every path weighed against the merge at x's backward photon, whose density is
// merge_density (pi r^2 N; 0: none). The continuation goes on by Russian roulette on its change
// of throughput. depth: x's scattering events, as the backward photon's eye_depth; part: the lobes
// x gathers with (EyeVertexChoice). Past x each path is weighed by the share of it that photons
// draw through gathered lobes (bsdf_gathered_probability: 1 but at split coats). Its first BSDF
// sample is also the first of x's direct samples: the light it finds goes to first.found, weighed
// as direct_light_by_bsdf weighs it, and first.shared says whether that sample would have cast
// the ray itself (the ray is then the direct light's, not the continuation's, in its cost).
inline Spectrum continue_eye_path(const EyePath& path, const PathVertex& x, BsdfPart part,
                                  PathState s, int depth, double merge_density, double vertex_scale,
                                  FirstSample& first) {
  const RenderScene& scene = path.scene;
  const WavelengthMaterials& wm = *path.prm.materials;
  PathCounters& rays = path.counters.rays;
  const uint64_t rays_before = rays.total();
  ++path.counters.continued;
  Continuation c{merge_density, DensityEnd{x.sp.p, x.sp.ng}, {}};
  c.vertex_scale = vertex_scale;
  Spectrum L;
  const PathVertex* at = &x;
  PathVertex vertices[2];  // e_j and e_(j-1) in turn (a vertex is not copied)
  Spectrum beta_flight;    // the throughput before the free flight that reached e_(j-1)
  for (int j = 1;; ++j) {
    const PathVertex& v = *at;
    bool look_only = false;
    EmitterWeight found = EmitterWeight::none();
    if (v.medium >= 0) {
      if (!leave_medium_vertex(scene, v, beta_flight, j, path.rng, s, c)) break;
    } else if (!leave_surface_vertex(path, v, j, part, s, c, first, found, look_only)) {
      break;
    }
    ++rays.bounce_rays;
    PathVertex& e = vertices[j & 1];
    Spectrum none;
    beta_flight = s.beta;
    const StepEnd end = next_eye_vertex(scene, wm, s, e, rays, found, j == 1 ? first.found : none);
    c.pass = s.pass;
    if (look_only || !arrive_at(path, e, end, depth + j, s, c, L)) break;
    at = &e;
  }
  path.counters.continuation_rays += rays.total() - rays_before;
  return L;
}

// The diffuse-th diffuse vertex: its direct light and backward photons. Returns whether the path
// ends here (at the last one), where with combined estimators it may go on for indirect light
// (continue_eye_path).
inline bool gather_at_diffuse_vertex(const EyePath& path, const PathVertex& v, const PathState& s,
                                     const EyeVertexChoice& choice, int depth, int diffuse,
                                     Spectrum& L) {
  bool last = diffuse == path.prm.diffuse_depth + 1;
  // Direct light: before the last vertex shared by MIS with the BSDF sample that continues the
  // path; at the last, once it is known whether the path goes on (the first direct sample's BSDF
  // sample is then the continuation's).
  if (!last) L += direct_light_at(path, v, s, choice.part);
  FirstSample first;
  bool continued = false;
  const auto direct_at_last = [&] {
    if (last)
      L += direct_light_at_last(path, v, s, choice.part, continued ? &first.found : nullptr);
    return last;
  };
  const CombineAt at = path.prm.combine;
  bool go_on = last && at != CombineAt::kNowhere && combinable_vertex(v);
  // Where the gathered lobes are not glossy: with kChosen the pixel's probability
  // (EyePixels::continue_level), with kGlossy never.
  int level = 0;
  bool chosen_here = false;
  if (go_on && at != CombineAt::kEverywhere && !bsdf_gathers_glossy(v.m(), choice.part)) {
    go_on = chosen_here = at == CombineAt::kChosen;
    level = path.continue_level;
    if (chosen_here && level == kNeverContinue) {
      path.continued.at_vertex = true;  // met, for the share of the iterations that do
      go_on = false;
    }
  }
  double merge_density = 0;
  const bool targeted_before = path.targeted;
  store_backward_photons(path, v, s, depth, diffuse, last, go_on ? &merge_density : nullptr,
                         uint8_t(level));
  if (!go_on) return direct_at_last();
  // The target of the vertex connections stored here: their density over the merge's is
  // 1 / (pi r^2 P A(x)), pi r^2 = merge_density / N.
  const double vertex_scale =
      path.targeted && !targeted_before && merge_density > 0
          ? path.prm.merge_photons / (merge_density * path.prm.vertex_pixels)
          : 0.0;
  if (chosen_here) path.continued.at_vertex = true;
  // Taken with the probability q: its density q B against the merge's, its light over q.
  const double q = std::ldexp(1.0, -level);
  if (level > 0 && !(path.rng.uniform() < q)) return direct_at_last();
  const uint64_t rays = path.counters.rays.total();
  path.continued.start(q, chosen_here);
  const Spectrum c =
      continue_eye_path(path, v, choice.part, s, depth, merge_density / q, vertex_scale, first);
  continued = true;
  L += c / float(q);
  if (chosen_here) path.continued.add(path.counters.rays.total() - rays - (first.shared ? 1 : 0));
  return direct_at_last();
}

// The diffuse-th diffuse vertex, inside a scattering medium: direct light by next-event
// estimation (shared by MIS with phase sampling), backward photons whose spheres gather photon
// beams, and a phase-function sample (its weight is 1): the path goes on along it, or at the last
// vertex it only looks for the light, as direct_light_by_bsdf does at a surface. Returns whether
// the path ends here.
inline bool gather_in_medium(const EyePath& path, const PathVertex& v, PathState& s, int depth,
                             int diffuse, EmitterWeight& emitter, Spectrum& L) {
  const float g = path.scene.media[size_t(v.medium)].g;
  L += s.beta * sample_direct_light_in_medium(path.scene, v, g, *path.prm.materials, path.rng,
                                              path.counters.rays);
  const bool last = diffuse == path.prm.diffuse_depth + 1;
  store_backward_photons(path, v, s, depth, diffuse, last);
  const PhaseSample ps = sample_phase(v, g, path.rng);
  ++path.counters.rays.bounce_rays;
  if (last) {
    L += emission_by_phase(path.scene, *path.prm.materials, v, s, ps, path.counters.rays);
    return true;
  }
  emitter = ps.emitter;
  s.ray = Ray{v.sp.p, ps.wi, kInf};
  return false;
}

// The last diffuse vertex drawn on a piece of the eye path's ray through a scattering medium,
// which the path itself crosses (PathState::cross_media): every ray through the medium gathers
// there, where a free flight would have scattered with the probability 1 - exp(-sigma_t tau) alone.
// What it gathers goes to `out` (never emission: it is direct light and the photons'). `along`:
// direct light was sampled along the piece too.
inline void gather_forced_in_medium(const EyePath& path, PathState& s, const Ray& ray, float length,
                                    const Spectrum& beta, int depth, int diffuse, bool along,
                                    Spectrum& out) {
  // The last piece allowed: the path draws its own vertices past it.
  if (++path.splits == kMaxMediumSplits) s.cross_media = false;
  PathState f = s;
  s.flight_u = -1;  // the path's preset uniform number, if any, goes to the vertex drawn here
  f.beta = beta;
  f.cross_media = false;
  const float t = sample_forced_medium_distance(
      path.scene, s.medium, ray, length, path.prm.materials->wl, path.rng, f.flight_u, f.beta);
  if (t < 0 || f.beta.is_black()) return;
  f.length = s.length + t;
  PathVertex v;
  v.medium = s.medium;
  v.sp.p = ray.o + ray.d * t;
  v.wo = -ray.d;
  v.piece = MediumPiece{ray, length, t, along, true};
  EmitterWeight unused;
  gather_in_medium(path, v, f, depth + 1, diffuse + 1, unused, out);
}

// Samples the BSDF at v and leaves the vertex along the sample; sets the weight of the emission
// the next vertex sees. Returns false where the path ends (no sample, no throughput left).
inline bool scatter(const EyePath& path, const PathVertex& v, const EyeVertexChoice& choice,
                    bool direct_here, int diffuse, PathState& s, EmitterWeight& emitter) {
  float uc = path.rng.uniform();
  Vec2 u{path.rng.uniform(), path.rng.uniform()};
  // Radiance-mode sampling; for a non-reciprocal BSDF the lobe drawn is the light-direction one
  // and the weight carries the ratio of the two BSDF values (the paper's Helmholtz
  // compensation, section 2; see PhongMaterial).
  auto bs = sample_bsdf(v, uc, u, TransportMode::kRadiance, choice.part);
  if (!bs) return false;
  s.beta *= bs->f * (std::fabs(bs->wi.z) / bs->pdf_solid_angle);
  if (s.beta.is_black()) return false;
  if (choice.gather || (direct_here && !bs->is_specular()))
    emitter = EmitterWeight::mis(bs->mis_pdf, v.sp.p);
  else
    emitter = diffuse == 0 ? EmitterWeight::full() : EmitterWeight::none();
  leave_vertex(path.scene, v, v.frame.to_world(bs->wi), s);
  ++path.counters.rays.bounce_rays;
  return true;
}

// The choice at surface vertex v (choose_eye_vertex), except where its material has both parts
// and gathering would end the path (EyePassParams::split_coats; once per path, `split`): then the
// path takes both, its gathered part ending here (what it counts goes to `gathered`; nothing for
// an emission_only path), its traced part going on.
inline EyeVertexChoice choose_or_split(const EyePath& path, const PathVertex& v, PathState& s,
                                       int depth, int diffuse, bool emission_only, bool& split,
                                       Spectrum& gathered) {
  if (!path.prm.split_coats || split || diffuse != path.prm.diffuse_depth || vertex_all_traced(v) ||
      bsdf_traced_part_probability(v.m(), v.wo_local) == 0)
    return choose_eye_vertex(v, path.rng, s);
  split = true;
  if (!emission_only)
    gather_at_diffuse_vertex(path, v, s, {true, BsdfPart::kGathered}, depth, diffuse + 1, gathered);
  return {false, BsdfPart::kTraced};
}

}  // namespace

// Out of line: GCC 12 would inline the whole path, its steps included, into the eye pass's pixel
// loop, which then runs 1.2% more instructions (callgrind, caustic-sphere).
[[gnu::noinline]] EyeRadiance trace_eye_path(const RenderScene& scene, const EyePassParams& prm,
                                             CameraRay ray, PixelFootprint footprint,
                                             uint32_t pixel, Rng& rng, ObjectPhotonLists& out,
                                             EyeCounters& counters, bool emission_only,
                                             uint8_t near_edge, float flight_u, int direct_samples,
                                             int continue_level, DiscScales scales) {
  int stored = 0, splits = 0;
  double direct_variance = -1;
  EyeContinuation continued;
  bool targeted = false;
  const int direct = std::clamp(direct_samples, 1, std::max(1, prm.direct_samples));
  const EyePath path{
      scene,    prm,    footprint, scales, pixel,           near_edge,      rng,       out,
      counters, stored, splits,    direct, direct_variance, continue_level, continued, targeted};
  if (ray.weight == 0) return {};
  PathState s{ray.ray, Spectrum(ray.weight), ray.medium};
  s.rng = &rng;
  s.flight_u = flight_u;
  Spectrum L;
  // L up to the first diffuse vertex (its own emission included); until then L is all emission.
  std::optional<Spectrum> emission;
  int diffuse = 0;  // diffuse vertices so far (j of DESIGN.md)
  int depth = 0;    // scattering events so far, as the path integrator counts them
  // Emitters are counted here when seen through specular vertices only, and when the BSDF sample
  // of a diffuse vertex before the last finds them through interfaces only: that is direct light
  // at the vertex, shared with next-event estimation by MIS (at the last vertex,
  // direct_light_by_bsdf does the same).
  EmitterWeight emitter = EmitterWeight::full();
  // Direct light sampled along the pieces of rays in media that lead to a diffuse vertex that
  // estimates it (the next one, while it is not past the last): never emission.
  Spectrum along;
  // What the gathered part of a split vertex counts, and whether the path has split.
  Spectrum gathered;
  bool split = false;
  ++counters.rays.camera_rays;
  for (int guard = 0; guard < 10000; ++guard) {
    PathVertex v;
    const bool sample_along =
        prm.equiangular && !emission_only && depth < prm.max_depth && diffuse <= prm.diffuse_depth;
    // Toward the last diffuse vertex the path splits in media: it scatters on every piece and
    // crosses it too (gather_forced_in_medium).
    s.cross_media = prm.split_in_media && !emission_only && depth < prm.max_depth &&
                    diffuse == prm.diffuse_depth && splits < kMaxMediumSplits;
    auto on_piece = [&](const Ray& piece, float length, const Spectrum& beta) {
      if (s.cross_media)
        gather_forced_in_medium(path, s, piece, length, beta, depth, diffuse, sample_along, along);
    };
    const StepEnd end = next_eye_vertex(scene, *prm.materials, s, v, counters.rays, emitter, L,
                                        false, sample_along ? &along : nullptr, on_piece);
    s.cross_media = false;
    if (end != StepEnd::kVertex && end != StepEnd::kMedium) break;
    if (depth++ == prm.max_depth) break;
    if (end == StepEnd::kMedium) {  // a diffuse vertex in a medium
      if (!emission) {
        emission = L;
        if (emission_only) break;
      }
      if (gather_in_medium(path, v, s, depth, ++diffuse, emitter, L)) break;
      continue;
    }
    if (v.wo_local.z == 0) break;
    keep_hero_wavelength_at(v, s);
    // A diffuse vertex gathers; a specular one (delta or sharp glossy lobes) is gone through.
    const EyeVertexChoice choice =
        choose_or_split(path, v, s, depth, diffuse, emission_only, split, gathered);
    const bool is_diffuse = choice.gather;
    if (is_diffuse && !emission) {
      emission = L;
      if (emission_only) break;
    }
    if (is_diffuse) {
      ++diffuse;
      if (gather_at_diffuse_vertex(path, v, s, choice, depth, diffuse, L)) break;
    }
    // A glossy specular vertex seen through specular ones only (a highlight): direct light by
    // next-event estimation, shared by MIS with the BSDF sample that goes on. After a diffuse
    // vertex the backward photons there count such light as a caustic.
    const bool direct_here =
        !is_diffuse && diffuse == 0 && bsdf_part_has_nondelta(v.m(), choice.part);
    if (direct_here) L += direct_light_at(path, v, s, choice.part);
    if (!scatter(path, v, choice, direct_here, diffuse, s, emitter)) break;
  }
  return {L + along + gathered, emission ? *emission : L, direct_variance, continued};
}

namespace {

// The mean of the first sample's emission and count - 1 more camera samples' of the pixel, each
// counted by its filter weight relative to the first one's, so that the film's weighted sums stay
// those of unbiased estimates (the extra samples have their own streams). Each sample's value
// goes to *stats, when given.
Spectrum mean_emission(const RenderScene& scene, const EyePassParams& prm,
                       const CameraSampler& camera, int pass_index, uint32_t pixel, int count,
                       float first_weight, const Spectrum& first_emission, ObjectPhotonLists& lists,
                       EyeCounters& ec, SampleStats<double>* stats) {
  if (stats) stats->add_emission(first_emission.average());
  if (count <= 1 || first_weight == 0) return first_emission;
  Spectrum sum = first_emission;
  const uint64_t rays_before = ec.rays.total();
  for (int k = 1; k < count; ++k) {
    CameraSample cs = camera.sample(pass_index, pixel, uint32_t(k));
    EyeRadiance e =
        trace_eye_path(scene, prm, cs.camera_ray(), cs.footprint, pixel, cs.rng, lists, ec, true);
    const Spectrum v = e.emission * (cs.filter_weight / first_weight);
    if (stats) stats->add_emission(v.average());
    sum += v;
  }
  ec.emission_samples += uint64_t(count - 1);
  ec.emission_rays += ec.rays.total() - rays_before;
  return sum / float(count);
}

}  // namespace

int emission_sample_count(const SampleStats<double>& s, double cost_ratio, int max_samples) {
  if (max_samples <= 1) return 1;
  if (s.emission_n() < 2 || s.rest_n() < 2) return 1;
  if (cost_ratio < 0) return max_samples;
  const double v_emission = s.variance(s.kEmission), v_rest = s.variance(s.kRest);
  if (!(v_rest > 0)) return v_emission > 0 ? max_samples : 1;
  const double e = std::sqrt(cost_ratio * v_emission / v_rest);
  if (!std::isfinite(e)) return max_samples;
  return int(std::clamp(std::round(e), 1.0, double(max_samples)));
}

int at_asked_rate(int count, float asked, float floor, bool emission_alone) {
  if (!(asked >= 0)) return count;
  if (emission_alone) return int(std::clamp(std::round(asked), 1.0f, float(std::max(count, 1))));
  if (!(floor > 0) || asked >= floor) return count;
  return int(std::max(1.0f, std::round(float(count) * asked / floor)));
}

void lend_emission_samples(int w, int h, Vec2 filter_radius, EyePixels* px) {
  const int rx = int(std::ceil(2 * filter_radius.x)), ry = int(std::ceil(2 * filter_radius.y));
  // Each pixel's own count where it has its statistics (as emission_sample_count: both parts have
  // two samples), else 0.
  const size_t n = size_t(w) * size_t(h);
  std::vector<uint16_t> own(n, 0), lent(n, 0);
  for (size_t p = 0; p < n; ++p) {
    const SampleStats<double>& s = px->sample_stats[p];
    if (px->sees_emission[p] && s.emission_n() >= 2 && s.rest_n() >= 2)
      own[p] = px->emission_samples[p];
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y < r.end(); ++y)
      for (int x = 0; x < w; ++x) {
        const size_t p = size_t(y) * size_t(w) + size_t(x);
        if (own[p]) continue;
        uint16_t most = 0;
        for (int v = std::max(0, y - ry); v <= std::min(h - 1, y + ry); ++v)
          for (int u = std::max(0, x - rx); u <= std::min(w - 1, x + rx); ++u)
            most = std::max(most, own[size_t(v) * size_t(w) + size_t(u)]);
        lent[p] = most;
      }
  });
  for (size_t p = 0; p < n; ++p)
    if (lent[p] > 1) px->emission_samples[p] = lent[p];
}

int direct_sample_count(const SampleStats<double>& s, double estimates, double estimate_variance,
                        double cost_ratio, int max_samples) {
  if (max_samples <= 1) return 1;
  if (estimates < 2 || s.direct_n() < 1 || cost_ratio < 0) return 2;
  const double v_direct = s.direct_variance();
  if (!(v_direct > 0)) return 1;
  const double v_rest = estimate_variance - v_direct * double(s.v[s.kInverseSamples]) / estimates;
  if (!(v_rest > 0)) return max_samples;
  const double k = std::sqrt(cost_ratio * v_direct / v_rest);
  if (!std::isfinite(k)) return max_samples;
  return int(std::clamp(std::round(k), 1.0, double(max_samples)));
}

int continue_level(const SampleStats<double>& s, double estimates, double estimate_variance,
                   double base_rays) {
  using S = SampleStats<double>;
  const double met = s.v[S::kContinued], taken = s.v[S::kContinued + 1], iterations = s.v[S::kLit];
  if (estimates < 2 || met < 2 || taken < 2 || !(base_rays > 0) || !(iterations > 0)) return 0;
  const double r = std::min(1.0, met / iterations), rays = s.v[S::kContinued + 2] / taken;
  if (!(rays > 0)) return kMaxContinueLevel;
  // What the continuations met would add at level l (with the merges' on their paths).
  const bool never = s.v[S::kContinuedNever + 1] == 0;
  const auto added = [&](int l) {
    return r * s.v[size_t(l == kNeverContinue ? S::kContinuedNever : S::kContinuedLevels + l)] /
           taken;
  };
  const double fixed =
      std::max(estimate_variance - r * s.v[S::kContinued + 3] / taken, 0.02 * estimate_variance);
  // From the cheapest up, so that of equal products the cheaper stays.
  int best = 0;
  double best_product = std::numeric_limits<double>::infinity();
  const auto consider = [&](int l, double cost) {
    const double product = (fixed + added(l)) * cost;
    if (product < best_product) {
      best = l;
      best_product = product;
    }
  };
  if (never) consider(kNeverContinue, base_rays);
  for (int l = kMaxContinueLevel; l >= 0; --l) consider(l, base_rays + r * std::ldexp(rays, -l));
  return best;
}

SampleStats<double> with_neighbours_rare(const std::vector<SampleStats<double>>& stats, int width,
                                         int height, size_t p) {
  using S = SampleStats<double>;
  // The direct variances' count and sum, the continuations' values and the iterations they
  // were met in.
  constexpr auto pooled = [] {
    std::array<size_t, 3 + S::kLit - S::kContinued> k{S::kDirect, S::kDirect + 1, S::kLit};
    for (size_t i = 3; i < k.size(); ++i) k[i] = S::kContinued + i - 3;
    return k;
  }();
  S s = stats[p];
  for (size_t k : pooled) s.v[k] = 0;
  const int px = int(p % size_t(width)), py = int(p / size_t(width));
  for (int y = std::max(0, py - 1); y <= std::min(height - 1, py + 1); ++y)
    for (int x = std::max(0, px - 1); x <= std::min(width - 1, px + 1); ++x) {
      const S& n = stats[size_t(y) * size_t(width) + size_t(x)];
      for (size_t k : pooled) s.v[k] += n.v[k];
    }
  return s;
}

// The pixel's level of going on in this iteration: kMaxContinueLevel in place of q = 0 in every
// kContinueExploreEvery-th iteration.
int continue_level_now(const EyePassParams& prm, const EyePixels* px, uint32_t pixel) {
  const int level = px->continue_level[pixel];
  return level == kNeverContinue && prm.iteration % kContinueExploreEvery == 0 ? kMaxContinueLevel
                                                                               : level;
}

bool run_eye_pass(const RenderScene& scene, const EyePassParams& prm, const CameraSampler& camera,
                  const PixelMasks& masks, const RenderControl& control, int pass, int pass_index,
                  EyePixels* px, EyeThreadData threads) {
  using Clock = std::chrono::steady_clock;
  const int slots = masks.slots();
  // The stratified number of the camera ray's first free flight, only where one can scatter.
  const bool flights = scene.has_scattering_media();
  std::atomic<bool> skipped{false};
  tbb::parallel_for(
      tbb::blocked_range<int>(0, masks.block_count() * slots, 1),
      [&](const tbb::blocked_range<int>& r) {
        ObjectPhotonLists& lists = threads.lists.local();
        EyeCounters& ec = threads.counters.local();
        for (int task = r.begin(); task < r.end(); ++task) {
          if (control.cut(pass)) {
            skipped = true;
            return;
          }
          // One clock reading per pixel: a pixel's cost runs from the end of the one before (a
          // skipped pixel's few instructions go to the next).
          auto t0 = Clock::now();
          for (uint32_t pixel : masks.pixels(task / slots, task % slots)) {
            px->sampled[pixel] = control.sample_pixel(pass, pixel);
            if (!px->sampled[pixel]) {
              px->cost_ns[pixel] = 0;
              continue;
            }
            ++ec.pixels;
            CameraSample cs = camera.sample(pass_index, pixel);
            const DiscScales scales =
                prm.pixel_radii ? DiscScales::of(*prm.pixel_radii, prm.iteration,
                                                 prm.first_iteration, px->lit_share[pixel])
                                : DiscScales{};
            // Where the camera's ray scatters in a medium, stratified over the pixel's iterations.
            EyeRadiance r = trace_eye_path(
                scene, prm, cs.camera_ray(), cs.footprint, pixel, cs.rng, lists, ec, false,
                prm.near_edges ? prm.near_edges->at(pixel) : 3,
                flights ? camera.stream_uniform(pass_index, pixel) : -1.0f,
                px->direct_samples[pixel], continue_level_now(prm, px, pixel), scales);
            px->round_stats[pixel].add_direct_variance(r.direct_variance);
            px->round_stats[pixel].add_continuation(r.continued);
            px->filter_weight[pixel] = cs.filter_weight;
            const Spectrum emission =
                mean_emission(scene, prm, camera, pass_index, pixel,
                              std::min<int>(prm.emission_samples, px->emission_samples[pixel]),
                              cs.filter_weight, r.emission, lists, ec,
                              px->sees_emission[pixel] ? &px->round_stats[pixel] : nullptr);
            px->radiance[pixel] = r.total + (emission - r.emission);
            px->emission_part[pixel] = emission.average();
            if (!r.emission.is_black() || !emission.is_black()) px->saw_emission[pixel] = 1;
            const auto t1 = Clock::now();
            px->cost_ns[pixel] = float(std::chrono::duration<double, std::nano>(t1 - t0).count());
            t0 = t1;
          }
        }
      });
  if (!skipped) return true;
  for (ObjectPhotonLists& l : threads.lists)
    for (auto& v : l) v.clear();
  return false;
}

}  // namespace bpm
