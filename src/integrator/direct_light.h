// Direct light, shared by every integrator: next-event estimation at a non-specular vertex, and
// the emission a path finds by BSDF sampling, weighted so that each light path is counted once
// (Veach 1997, 9.2.4: the power heuristic between the two strategies).
#pragma once
#include <optional>

#include "base/rng.h"
#include "integrator/counters.h"
#include "integrator/path_vertex.h"
#include "scene/render_scene.h"

namespace bpm {

// The fraction of light that reaches `target` from `origin` (in `medium`) along the straight
// segment: 0 when a surface that is not an interface stands between; through interface surfaces,
// which shadow rays cross as pbrt-v4's cross medium boundaries, the product of each stretch's
// medium transmittance, the medium changing at each. `infinite`: the target stands for a
// direction, the last stretch infinitely long. With `pass`, *pass is the probability that a free
// flight gets across the whole way (as PathState::pass: the product over the stretches in
// scattering media of their mean transmittance); the last `certain_last` of those stretches (the
// ones nearest target, at most 8), which a path from target crosses for certain
// (PathState::cross_media), are left out of it.
Spectrum shadow_transmittance(const RenderScene& scene, Vec3 origin, Vec3 target, int medium,
                              bool infinite, const Wavelengths& wl, float* pass = nullptr,
                              int certain_last = 0);

// One sample for next-event estimation at sp: a light chosen by power (light, pmf), a point on it
// by its own sampling (ls), and f, the BSDF of `part` times |cos| times the shadow ray's
// transmittance (wi_local: the light's direction in `frame`). None where the light sends nothing
// there or f is black; pass: the probability that a free flight would have got across the shadow
// ray's way (shadow_transmittance), which bpm's continuation weighs next-event estimation by.
// sample_direct_light weighs it; bpm's continuation weighs it otherwise.
struct LightSampleAt {
  int light;
  float pmf;
  LightLiSample ls;
  Vec3 wi_local;
  Spectrum f;
  float pass = 1;
};
std::optional<LightSampleAt> sample_light_at(const RenderScene& scene, const SurfacePoint& sp,
                                             int object, int medium, const Material& m,
                                             const Frame& frame, Vec3 wo_local,
                                             const WavelengthMaterials& wm, Rng& rng,
                                             PathCounters& counters,
                                             BsdfPart part = BsdfPart::kAll);

// Direct light at a non-specular vertex by sampling one light chosen by power, with the power
// heuristic against BSDF sampling when use_mis (the caller then weights the emitters its BSDF
// samples hit by EmitterWeight::mis), else with full weight. sp lies on `object`, reached by a
// ray in `medium`: the shadow ray crosses interfaces (shadow_transmittance).
// Only the lobes of `part` reflect it (BsdfPart).
Spectrum sample_direct_light(const RenderScene& scene, const SurfacePoint& sp, int object,
                             int medium, const Material& m, const Frame& frame, Vec3 wo_local,
                             bool use_mis, const WavelengthMaterials& wm, Rng& rng,
                             PathCounters& counters, BsdfPart part = BsdfPart::kAll);

// A medium at distance t along a unit ray from where the ray enters it: the transmittance up to
// there, sigma_s there, and the density per unit length with which t is drawn: by next_vertex's
// free flight (sample_medium_distance, sample_rgb_grid_flight: the mixture over wavelengths), or
// where forced_length >= 0, by sample_forced_medium_distance on a piece of that length.
struct MediumAtDistance {
  Spectrum T, sigma_s;
  float flight_pdf = 0;
};
MediumAtDistance medium_at_distance(const RenderScene& scene, int medium, const Ray& unit, float t,
                                    const Wavelengths& wl, float forced_length = -1);

// A point where a ray scatters in a medium on a piece of `length` along the unit ray, drawn on the
// piece whatever happens past it: one wavelength's free flight conditioned to end on the piece
// (the wavelength drawn uniformly), beta weighted by sigma_s T over the mixture of all
// wavelengths' densities. Paired with crossing the piece at full weight exp(-sigma_t tau)
// (PathState::cross_media), it splits a path in two where a free flight picks one or the other,
// and every ray through a thin medium then scatters. Returns the distance, or negative where
// nothing could be drawn. The distance's uniform number is preset_u when set (flight_uniform).
float sample_forced_medium_distance(const RenderScene& scene, int medium, const Ray& unit,
                                    float length, const Wavelengths& wl, Rng& rng, float& preset_u,
                                    Spectrum& beta);

// Direct light at a medium vertex v (StepEnd::kMedium) that scatters by a Henyey-Greenstein phase
// function of asymmetry g: one light chosen by power, attenuated by the media up to it (the shadow
// ray crosses interfaces, shadow_transmittance), by the power heuristic against phase sampling;
// where the path also sampled direct light along v's piece (v.piece.equiangular), that share is
// split with sample_direct_light_along by the balance heuristic.
Spectrum sample_direct_light_in_medium(const RenderScene& scene, const PathVertex& v, float g,
                                       const WavelengthMaterials& wm, Rng& rng,
                                       PathCounters& counters);
// Its sample, unweighted (sample_light_at's at a medium vertex): wi_local is the light's world
// direction, f the phase function's value times the shadow ray's transmittance.
std::optional<LightSampleAt> sample_light_in_medium(const RenderScene& scene, const PathVertex& v,
                                                    float g, const WavelengthMaterials& wm,
                                                    Rng& rng, PathCounters& counters);

// Direct light scattered toward the origin of a unit ray from anywhere on its first `length`
// (kInf: without end) inside `medium`, per unit throughput at the ray's origin: a point drawn on a
// light chosen by power (light_sample_point), then a distance by equiangular sampling about that
// point (Kulla and Fajardo 2012, "Importance sampling techniques for path tracing in
// participating media"), whose density falls as 1 / r^2 from the light as the light itself does:
// beside a small light in fog, next-event estimation from free-flight points alone has unbounded
// variance. A light path x_light - x_t - origin that a free flight and next-event estimation at
// x_t also draw is shared with it by the balance heuristic on the two densities of x_t (the
// power heuristic against phase sampling as sample_direct_light_in_medium's), so a path that
// samples along every piece where its next medium vertex would estimate direct light stays
// unbiased. Distant and environment lights are not sampled so.
// `forced`: a medium vertex on the piece would be drawn by sample_forced_medium_distance.
Spectrum sample_direct_light_along(const RenderScene& scene, int medium, const Ray& ray,
                                   float length, bool forced, const WavelengthMaterials& wm,
                                   Rng& rng, PathCounters& counters);

// How emission found by the next ray of a path counts: in full (seen from the camera or through
// specular vertices only), by the power heuristic against next-event estimation at the previous
// vertex p_prev whose BSDF sample had density pdf_bsdf, or not at all (counted elsewhere).
struct EmitterWeight {
  enum Kind { kFull, kMis, kNone } kind = kFull;
  float pdf_bsdf = 0;  // MIS density of the BSDF sample (BsdfSample::mis_pdf)
  Vec3 p_prev;
  static EmitterWeight full() { return {}; }
  static EmitterWeight none() { return {kNone, 0, {}}; }
  static EmitterWeight mis(float pdf_bsdf, Vec3 p_prev) { return {kMis, pdf_bsdf, p_prev}; }
};

// beta times the emission of the area light at a surface hit (nothing if the surface does not
// emit), weighted as w says; `ray` is the ray that found it.
Spectrum weighted_surface_emission(const RenderScene& scene, const Ray& ray, const Hit& hit,
                                   const SurfacePoint& sp, const Wavelengths& wl,
                                   const Spectrum& beta, const EmitterWeight& w);

// Adds to L beta times the radiance of every environment light seen along an escaping ray,
// weighted as w says.
void add_environment_emission(const RenderScene& scene, const Ray& ray, const Wavelengths& wl,
                              const Spectrum& beta, const EmitterWeight& w, Spectrum& L);

// The next vertex of a camera path (next_vertex), adding to L the emission found on the way:
// surfaces reached and, when the ray escapes, environment lights, weighted as `emitter` says
// (next-event estimation's shadow rays cross interfaces as these rays do), and where
// `medium_light` says, the emission of the media crossed (in full: no other strategy finds it).
// Where `along` is given, the direct light scattered along each piece crossed in a scattering
// medium (sample_direct_light_along) is added to it: the caller passes it exactly where a medium
// vertex drawn on the way would estimate direct light. on_piece(ray, length, beta) is then called
// for each such piece (with s.cross_media, where the caller draws the medium vertices itself).
template <class OnPiece = NoMediumPieces>
StepEnd next_eye_vertex(const RenderScene& scene, const WavelengthMaterials& materials,
                        PathState& s, PathVertex& v, PathCounters& counters,
                        const EmitterWeight& emitter, Spectrum& L, bool medium_light = false,
                        Spectrum* along = nullptr, OnPiece&& on_piece = {}) {
  const Wavelengths& wl = materials.wl;
  StepEnd end = next_vertex(
      scene, materials, s, v, counters.bounce_rays, counters.observer,
      [&](const Hit& hit, const SurfacePoint& sp) {
        L += weighted_surface_emission(scene, s.ray, hit, sp, wl, s.beta, emitter);
      },
      [&](const Ray& ray, float distance, const Spectrum& beta) {
        if (medium_light) L += beta * medium_emission(scene, s.medium, ray, distance, wl, s.rng);
        if (!scene.media[size_t(s.medium)].scatters()) return;
        if (along)
          *along += beta * sample_direct_light_along(scene, s.medium, ray, distance, s.cross_media,
                                                     materials, *s.rng, counters);
        on_piece(ray, distance, beta);
      });
  if (end == StepEnd::kEscaped) add_environment_emission(scene, s.ray, wl, s.beta, emitter, L);
  if (end == StepEnd::kMedium) v.piece.equiangular = along != nullptr;
  return end;
}

// A phase-function sample at the medium point v (its weight is 1), and how the emission its ray
// finds counts: by the power heuristic against next-event estimation at v.
struct PhaseSample {
  Vec3 wi;
  EmitterWeight emitter;
};
inline PhaseSample sample_phase(const PathVertex& v, float g, Rng& rng) {
  const Vec2 u{rng.uniform(), rng.uniform()};
  const Vec3 wi = sample_henyey_greenstein(-v.wo, g, u);
  return {wi, EmitterWeight::mis(henyey_greenstein(dot(-v.wo, wi), g), v.sp.p)};
}

// The emission that the ray of a phase sample at v finds before it scatters again, weighted as
// the sample says: at the last vertex in a medium of a photon method's camera path, the sample
// only looks for the light (as direct_light_by_bsdf at a surface).
inline Spectrum emission_by_phase(const RenderScene& scene, const WavelengthMaterials& materials,
                                  const PathVertex& v, PathState s, const PhaseSample& ps,
                                  PathCounters& counters) {
  s.ray = Ray{v.sp.p, ps.wi, kInf};
  PathVertex next;
  Spectrum L;
  next_eye_vertex(scene, materials, s, next, counters, ps.emitter, L);
  return L;
}

// The direct light that a BSDF sample at the last vertex of a photon method's camera path finds
// (next-event estimation alone has unbounded variance beside an area light: a lamp against a wall,
// where the light's density over directions falls to nothing and its contribution does not):
// one segment along a direction drawn from the `part` lobes, the emitter it reaches (through
// interfaces only) weighted by the power heuristic against next-event estimation at v. The
// path's other strategy for that light, next-event estimation with use_mis, is the caller's.
// The gathered lobes of a vertex where a path ends are never delta, so the sample is never
// specular (a specular one would find nothing here). Nothing, and no random number drawn, where
// every light is a point or a direction (RenderScene::bsdf_finds_lights).
Spectrum direct_light_by_bsdf(const RenderScene& scene, const WavelengthMaterials& materials,
                              const PathVertex& v, PathState s, BsdfPart part, Rng& rng,
                              PathCounters& counters);

}  // namespace bpm
