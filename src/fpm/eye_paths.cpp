#include "fpm/eye_paths.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "integrator/direct_light.h"
#include "integrator/path_vertex.h"
#include "photons/density.h"
#include "photons/disc_probes.h"

namespace bpm {
namespace {

// Radiance reflected at v toward wo from the map's photons of the accepted classes, eq. (2):
// sum f dPhi / (pi r^2 N), and the estimate of its bias (radius_bias). With knn > 0
// the radius is the distance to the knn-th nearest photon within `radius` (Jensen's estimate),
// else `radius`. probe(r) measures the share of the disc of radius r where photons can land
// (photons/disc_probes.h), which the sums are divided by, and where it looked, a photon cut off
// from the point is not gathered (the photon maps do not depend on the threads, so neither do the
// probes made).
struct Estimate {
  Spectrum L, bias;
};
template <class Accept, class Probe>
Estimate estimate(const RenderScene& scene, const PhotonMap& map, const PathVertex& v,
                  bool eye_hero_only, float radius, int eye_depth, const FpmEyeParams& prm,
                  Accept&& accept, Probe&& probe, FpmEyeCounters& c) {
  ++c.lookups;
  const SurfacePoint& sp = v.sp;
  auto usable = [&](const ForwardPhoton& ph) {
    return accept(ph.cls) && eye_depth + int(ph.bounces) <= prm.max_depth &&
           dot(ph.ng, sp.ng) >= prm.fpm->normal_cos;
  };
  float r = radius;
  if (prm.fpm->knn > 0) {
    std::vector<float> d2;
    map.tree.query_within(sp.p, radius, [&](uint32_t i) {
      if (usable(map.photons[i])) d2.push_back(length_squared(map.photons[i].p - sp.p));
    });
    if (int(d2.size()) > prm.fpm->knn) {
      std::nth_element(d2.begin(), d2.begin() + prm.fpm->knn - 1, d2.end());
      r = std::sqrt(d2[size_t(prm.fpm->knn - 1)]) * 1.0001f;
    }
  }
  // The photons found are probed for only when there are some; where other geometry is near
  // (DiscProbes::looked), each is then gathered only where nothing cuts it off from the point
  // (photon_cut_off).
  thread_local std::vector<uint32_t> found;
  found.clear();
  map.tree.query_within(sp.p, r, [&](uint32_t i) {
    if (usable(map.photons[i])) found.push_back(i);
  });
  if (found.empty()) return {};
  const DiscProbes d = probe(r);
  const Vec3 n = dot(sp.ng, v.wo) >= 0 ? sp.ng : -sp.ng;
  NestedSums sums;
  for (uint32_t i : found) {
    const ForwardPhoton& ph = map.photons[i];
    if (d.looked &&
        photon_cut_off(scene, sp.p, n, ph.p, v.object(), r, prm.fpm->normal_cos, c.rays))
      continue;
    ++c.photons_used;
    sums.add(photon_contribution(v.m(), ph.ng, sp.ns, v.wo, ph.wi, ph.flux) *
                 hero_join_factor(eye_hero_only, ph.hero_only),
             length_squared(ph.p - sp.p), r * r);
  }
  divide_by_disc_shares(&sums, d.found, d.cut);
  const float norm = float(1.0 / (kPi * double(r) * r * prm.emitted));
  return {sums.all * norm, radius_bias(sums, norm, prm.fpm->bias_model)};
}

bool any_class(PhotonClass) { return true; }
bool caustic_class(PhotonClass k) { return k == PhotonClass::kCaustic; }
bool indirect_class(PhotonClass k) { return k == PhotonClass::kIndirect; }
bool not_direct_class(PhotonClass k) { return k != PhotonClass::kDirect; }

// The light that the phase function gathers at the medium point v toward v.wo (the integral of p
// L over directions) from the volume map's photons of its medium and of the accepted classes:
// sum p(cos) dPhi / (4/3 pi r^3 N sigma_s) (Jensen and Christensen 1998; the photons are stored
// where they collide, with the weight sigma_s / sigma_t of the free flight, so their density is
// sigma_s times the fluence's, and the eye path's own weight has its sigma_s; in a grid medium
// each photon's flux is divided by the density (or an rgbgrid's sigma_s) where it collided), with
// the
// Henyey-Greenstein phase function of asymmetry g; and the estimate of its bias from the photons
// within the radius that holds half the sphere's volume, r 2^(-1/3): for a bias a r^2 it is
// (L(r) - L(r 2^(-1/3))) / (1 - 2^(-2/3)).
template <class Accept>
Estimate volume_estimate(const PhotonMap& map, const PathVertex& v, bool eye_hero_only, float r,
                         int eye_depth, const FpmEyeParams& prm, float g, const Spectrum& sigma_s,
                         Accept&& accept, FpmEyeCounters& c) {
  ++c.lookups;
  constexpr float kHalfR2 = 0.62996052f;  // 2^(-2/3)
  Spectrum all, half;
  map.tree.query_within(v.sp.p, r, [&](uint32_t i) {
    const ForwardPhoton& ph = map.photons[i];
    if (ph.medium != v.medium || !accept(ph.cls) || eye_depth + int(ph.bounces) > prm.max_depth)
      return;
    ++c.photons_used;
    const Spectrum value = ph.flux * (henyey_greenstein(dot(-v.wo, ph.wi), g) *
                                      hero_join_factor(eye_hero_only, ph.hero_only));
    all += value;
    if (length_squared(ph.p - v.sp.p) < kHalfR2 * r * r) half += value;
  });
  const float norm = float(1.0 / (4.0 / 3.0 * kPi * double(r) * r * r * prm.emitted));
  for (int k = 0; k < Spectrum::kChannels; ++k) {
    const float inv = sigma_s[k] > 0 ? norm / sigma_s[k] : 0.0f;
    all[k] *= inv;
    half[k] *= 2 * inv;
  }
  return {all, (all - half) * (1 / (1 - kHalfR2))};
}

// What every vertex of one eye path shares.
struct FpmPath {
  const RenderScene& scene;
  const ForwardMaps& maps;
  const FpmEyeParams& prm;
  PixelFootprint footprint;
  Rng& rng;
  FpmEyeCounters& c;
  uint8_t near_edge;
};

// Direct light at v by next-event estimation, shared by MIS with the BSDF sample that goes on.
inline Spectrum direct_light_at(const FpmPath& path, const PathVertex& v, const PathState& s,
                                BsdfPart part) {
  return s.beta * sample_direct_light(path.scene, v.sp, v.object(), s.medium, v.m(), v.frame,
                                      v.wo_local, true, *path.prm.materials, path.rng, path.c.rays,
                                      part);
}

// A diffuse vertex: x1 (`gathering` false) or, with final gathering, x2. Returns whether the path
// ends here; sets `gathering` when a final gather leaves x1.
inline bool gather_at_diffuse_vertex(const FpmPath& path, const PathVertex& v, const PathState& s,
                                     const EyeVertexChoice& choice, int depth, bool& gathering,
                                     Spectrum& L, Spectrum& bias) {
  const FpmEyeParams& prm = path.prm;
  // The discs about v are probed where they may be cut: at a vertex seen straight from the
  // camera, where the screen around the pixel shows an edge (near_bit of near_edge). A disc no
  // larger than one found whole is whole too.
  const bool seen_directly = depth == 1;
  float whole_radius = 0;
  bool whole_looked = false;  // the whole disc's probes looked: its photons were tested
  auto gather = [&](const PhotonMap& map, float radius, uint8_t near_bit, auto accept) {
    auto probe = [&](float r) {
      if (r <= whole_radius) return DiscProbes{0, 0, whole_looked};
      if (!prm.fpm->disc_probes || (seen_directly && !(path.near_edge & near_bit)) ||
          !may_cut_discs(path.scene.objects[size_t(v.object())].shape))
        return DiscProbes{};
      const DiscProbes d =
          probe_disc(path.scene, v.sp, v.wo, v.object(), PhotonSurfaces::kAnyObject, r,
                     prm.fpm->normal_cos, path.rng, path.c.rays, v.hit.primitive);
      if (!d.cut) {
        whole_radius = r;
        whole_looked = d.looked;
      }
      return d;
    };
    const Estimate e =
        estimate(path.scene, map, v, s.hero_only, radius, depth, prm, accept, probe, path.c);
    L += s.beta * e.L;
    bias += s.beta * e.bias;
  };
  const float footprint = path.footprint.at(s.length);
  const float r1 = footprint * prm.k1;
  if (gathering) {
    // x2: everything the global map holds, direct photons included.
    gather(path.maps.global, r1, 1, any_class);
    return true;
  }
  // x1: direct light by next-event estimation, shared by MIS with the BSDF sample that leaves
  // x1 (points and directions, which no BSDF sample finds, in full); caustics from the
  // caustic map.
  L += direct_light_at(path, v, s, choice.part);
  // Without final gathering the larger disc first (r1 > r0 by default): where it is whole,
  // the caustic map's is too. The path ends here: its BSDF sample only looks for the light.
  if (!prm.fpm->final_gather) {
    gather(path.maps.global, r1, 1, indirect_class);
    gather(path.maps.caustic, footprint * prm.k0, 2, caustic_class);
    L += direct_light_by_bsdf(path.scene, *prm.materials, v, s, choice.part, path.rng, path.c.rays);
    return true;
  }
  gather(path.maps.caustic, footprint * prm.k0, 2, caustic_class);
  gathering = true;
  return false;
}

// A point where the eye path scatters in a medium, where it ends. At x1: direct light by
// next-event estimation through the phase function and a phase sample that only looks for the
// light (by MIS), the rest from the volume map; at x2 of a final gather, everything from it.
inline void gather_in_medium(const FpmPath& path, const PathVertex& v, const PathState& s,
                             int depth, bool gathering, Spectrum& L, Spectrum& bias) {
  const Medium& medium = path.scene.media[size_t(v.medium)];
  const float g = medium.g;
  const Spectrum sigma_s = medium.sigma_s.sample(path.prm.materials->wl);
  const float r = path.footprint.at(std::max(s.length, path.prm.medium_min_length)) * path.prm.k1;
  auto gather = [&](auto accept) {
    const Estimate e = volume_estimate(path.maps.volume, v, s.hero_only, r, depth, path.prm, g,
                                       sigma_s, accept, path.c);
    L += s.beta * e.L;
    bias += s.beta * e.bias;
  };
  if (gathering) return gather(any_class);
  L += s.beta *
       sample_direct_light_in_medium(path.scene, v, g, *path.prm.materials, path.rng, path.c.rays);
  gather(not_direct_class);
  L += emission_by_phase(path.scene, *path.prm.materials, v, s, sample_phase(v, g, path.rng),
                         path.c.rays);
  ++path.c.rays.bounce_rays;
}

// Samples the BSDF at v and leaves the vertex along the sample; sets the weight of the emission
// the next vertex sees. Returns false where the path ends (no sample, no throughput left).
inline bool scatter(const FpmPath& path, const PathVertex& v, const EyeVertexChoice& choice,
                    bool direct_here, bool gathering, PathState& s, EmitterWeight& emitter) {
  Vec2 u{path.rng.uniform(), path.rng.uniform()};  // drawn before uc
  float uc = path.rng.uniform();
  auto bs = sample_bsdf(v, uc, u, TransportMode::kRadiance, choice.part);
  if (!bs) return false;
  s.beta *= bs->f * (std::fabs(bs->wi.z) / bs->pdf_solid_angle);
  if (s.beta.is_black()) return false;
  if (!gathering)
    emitter = direct_here && !bs->is_specular() ? EmitterWeight::mis(bs->mis_pdf, v.sp.p)
                                                : EmitterWeight::full();
  else if (choice.gather && !bs->is_specular())  // the final gather's ray leaving x1
    emitter = EmitterWeight::mis(bs->mis_pdf, v.sp.p);
  else
    emitter = EmitterWeight::none();
  leave_vertex(path.scene, v, v.frame.to_world(bs->wi), s);
  ++path.c.rays.bounce_rays;
  return true;
}

}  // namespace

FpmEyeRadiance fpm_eye_radiance(const RenderScene& scene, const ForwardMaps& maps,
                                const FpmEyeParams& prm, CameraRay ray, PixelFootprint footprint,
                                Rng& rng, FpmEyeCounters& c, uint8_t near_edge) {
  if (ray.weight == 0) return {};
  const FpmPath path{scene, maps, prm, footprint, rng, c, near_edge};
  PathState s{ray.ray, Spectrum(ray.weight), ray.medium};
  s.rng = &rng;
  Spectrum L, bias;
  int depth = 0;
  // Emission found by the ray that leaves x1 is direct light at x1, shared by MIS with next-event
  // estimation there; past that ray's first surface (a final gather through specular vertices) it
  // is not counted: light that reaches x1 through specular vertices is a caustic, x1's caustic
  // map's.
  EmitterWeight emitter = EmitterWeight::full();
  bool gathering = false;
  ++c.rays.camera_rays;
  for (int guard = 0; guard < 10000; ++guard) {
    PathVertex v;
    // Direct light along the pieces in media that lead to x1 (its next-event estimation's share).
    const bool along = prm.equiangular && !gathering && depth < prm.max_depth;
    const StepEnd end = next_eye_vertex(scene, *prm.materials, s, v, c.rays, emitter, L, false,
                                        along ? &L : nullptr);
    if (end != StepEnd::kVertex && end != StepEnd::kMedium) break;
    if (depth++ == prm.max_depth) break;
    if (end == StepEnd::kMedium) {
      gather_in_medium(path, v, s, depth, gathering, L, bias);
      break;
    }
    if (v.wo_local.z == 0) break;
    keep_hero_wavelength_at(v, s);
    // A diffuse vertex gathers; a specular one (delta or sharp glossy lobes) is gone through.
    const EyeVertexChoice choice = choose_eye_vertex(v, rng, s);
    const bool is_diffuse = choice.gather;
    if (is_diffuse && gather_at_diffuse_vertex(path, v, s, choice, depth, gathering, L, bias))
      break;
    // A glossy specular vertex seen through specular ones only (a highlight): direct light by
    // next-event estimation, shared by MIS with the BSDF sample that goes on.
    const bool direct_here =
        !is_diffuse && !gathering && bsdf_part_has_nondelta(v.m(), choice.part);
    if (direct_here) L += direct_light_at(path, v, s, choice.part);
    if (!scatter(path, v, choice, direct_here, gathering, s, emitter)) break;
  }
  return {L, bias};
}

}  // namespace bpm
