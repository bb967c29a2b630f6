#include "integrator/path_radiance.h"

#include <cmath>

#include "base/sampling.h"
#include "integrator/path_vertex.h"

namespace bpm {

namespace {

// Scattering at a point inside a medium: next-event estimation through the phase function, then
// a direction drawn from it (exactly: the throughput is unchanged), whose emitters count by the
// power heuristic against that estimate.
void scatter_in_medium(const RenderScene& scene, const WavelengthMaterials& materials,
                       const PathVertex& v, PathState& s, Rng& rng, PathCounters& counters,
                       EmitterWeight& emitter, Spectrum& L) {
  const Medium& m = scene.media[size_t(v.medium)];
  L += s.beta * sample_direct_light_in_medium(scene, v, m.g, materials, rng, counters);
  const PhaseSample ps = sample_phase(v, m.g, rng);
  emitter = ps.emitter;
  s.ray = Ray{v.sp.p, ps.wi, kInf};
  ++counters.bounce_rays;
}

// Scattering at a surface vertex: direct light and a BSDF sample (false: the path ends).
bool scatter_at_surface(const RenderScene& scene, const WavelengthMaterials& materials,
                        PathVertex& v, PathState& s, Rng& rng, PathCounters& counters,
                        EmitterWeight& emitter, bool& all_traced, float& eta_scale, Spectrum& L) {
  if (v.wo_local.z == 0) return false;
  keep_hero_wavelength_at(v, s);
  if (all_traced) {
    // Light reaching v and leaving it through a gathered lobe, then traced lobes to the origin.
    if (!v.on_curve && bsdf_part_has_nondelta(v.m(), BsdfPart::kGathered)) {
      L += s.beta * sample_direct_light(scene, v.sp, v.object(), s.medium, v.m(), v.frame,
                                        v.wo_local, true, materials, rng, counters,
                                        BsdfPart::kGathered);
      L += direct_light_by_bsdf(scene, materials, v, s, BsdfPart::kGathered, rng, counters);
    }
  } else if (!bsdf_is_specular(v.m())) {
    L += s.beta * sample_direct_light(scene, v.sp, v.object(), s.medium, v.m(), v.frame, v.wo_local,
                                      true, materials, rng, counters);
  }
  float uc = rng.uniform();
  Vec2 u{rng.uniform(), rng.uniform()};
  auto bs = sample_bsdf(v, uc, u, TransportMode::kRadiance);
  if (!bs) return false;
  s.beta *= bs->f * (std::fabs(bs->wi.z) / bs->pdf_solid_angle);
  emitter = bs->is_specular() ? EmitterWeight::full() : EmitterWeight::mis(bs->mis_pdf, v.sp.p);
  // Past a vertex of the traced-only path the emission found is counted elsewhere: through a
  // traced lobe by the photons, through a gathered one by that vertex's direct light above.
  if (all_traced) emitter = EmitterWeight::none();
  all_traced = all_traced && (bs->is_traced() || v.on_curve);
  if (bs->is_transmission()) eta_scale *= bs->eta * bs->eta;
  leave_vertex(scene, v, v.frame.to_world(bs->wi), s);
  ++counters.bounce_rays;
  return true;
}

}  // namespace

Spectrum path_radiance(const RenderScene& scene, Ray ray, const PathSettings& settings,
                       const Wavelengths& wl, Rng& rng, PathCounters& counters,
                       const EmitterWeight& first, int medium) {
  const WavelengthMaterials materials = WavelengthMaterials::resolved_per_point(scene, wl);
  PathState s{ray, Spectrum(1.0f), medium};
  s.rng = &rng;
  Spectrum L;
  EmitterWeight emitter = first;
  float eta_scale = 1;
  int depth = 0;
  bool all_traced = settings.caustics_elsewhere;  // every vertex so far sampled a traced lobe
  ++counters.camera_rays;
  for (int guard = 0; guard < 10000; ++guard) {
    PathVertex v;
    // Media emit toward the path before its last scattering event (pbrt-v4's volpath), and
    // direct light is sampled along the pieces in media where a vertex would estimate it.
    const bool more = depth < settings.max_depth;
    const StepEnd end = next_eye_vertex(scene, materials, s, v, counters, emitter, L, more,
                                        more && settings.equiangular ? &L : nullptr);
    if (end != StepEnd::kVertex && end != StepEnd::kMedium) break;
    if (depth++ == settings.max_depth) break;
    if (end == StepEnd::kMedium) {
      all_traced = false;  // light scattered in a medium is never a photon method's caustic
      scatter_in_medium(scene, materials, v, s, rng, counters, emitter, L);
    } else if (!scatter_at_surface(scene, materials, v, s, rng, counters, emitter, all_traced,
                                   eta_scale, L)) {
      break;
    }
    if (s.beta.is_black()) break;
    // Russian roulette on the throughput without the radiance scaling of refraction
    // (pbrt-v4's etaScale), after the first two bounces.
    Spectrum rr_beta = s.beta * eta_scale;
    if (rr_beta.max_component() < 1 && depth > 1) {
      float q = std::fmax(0.0f, 1 - rr_beta.max_component());
      if (rng.uniform() < q) break;
      s.beta /= 1 - q;
    }
  }
  return L;
}

}  // namespace bpm
