#include "bpm/light_pass.h"

#include <cmath>

namespace bpm {
namespace {

// Adds the entries of one diffuse hit: the photon arrives at sp along -wi with `flux`.
void gather_at_hit(const RenderScene& scene, const BackwardMaps& maps, const LightPassParams& prm,
                   const std::vector<uint16_t>& owner, int object, const SurfacePoint& sp, Vec3 wi,
                   const Spectrum& flux, PhotonClass cls, int bounces, std::vector<std::vector<PhotonEntry>>& out,
                   LightCounters& counters) {
  ++counters.queries;
  maps.query(object, sp.p, [&](uint32_t g) {
    const BackwardPhoton& bp = maps.photons[g];
    if (!bp.accepts_class(cls) || int(bp.eye_depth) + bounces > prm.max_depth) return;
    if (dot(bp.ng, sp.ng) < prm.normal_cos) return;
    Frame frame = Frame::from_z(bp.ns);
    Vec3 wo_local = frame.to_local(bp.wo), wi_local = frame.to_local(wi);
    Spectrum f = bsdf_f(scene.materials[bp.material], wo_local, wi_local, TransportMode::kRadiance);
    if (f.is_black()) return;
    // The density estimate gives irradiance on the geometric surface; the BSDF wants it on the
    // shading one.
    float cos_g = std::fabs(dot(wi, bp.ng));
    if (cos_g == 0) return;
    float cos_ratio = std::fabs(wi_local.z) / cos_g;
    out[owner[bp.pixel]].push_back({g, flux * f * cos_ratio});
    ++counters.entries;
  });
}

}  // namespace

void trace_photon(const RenderScene& scene, const BackwardMaps& maps, const LightPassParams& prm,
                  const std::vector<uint16_t>& owner, Rng& rng, std::vector<std::vector<PhotonEntry>>& out,
                  LightCounters& counters) {
  ++counters.photons;
  if (scene.lights.empty() || prm.max_depth < 2) return;  // a photon needs a bounce and an eye vertex
  float pmf;
  int li = scene.light_distribution.sample(rng.uniform(), &pmf);
  const Light& light = scene.lights[li];
  Vec2 u_pos{rng.uniform(), rng.uniform()}, u_dir{rng.uniform(), rng.uniform()};
  auto le = light_sample_le(light, scene.light_shape(light), u_pos, u_dir, scene.bounds_info);
  if (!le || le->flux.is_black() || pmf == 0) return;
  Spectrum beta = le->flux / pmf;
  bool has_surface = length_squared(le->n_light) > 0;
  Ray ray{has_surface ? offset_origin(le->origin, le->n_light, le->direction) : le->origin, le->direction, kInf};
  int bounces = 0;  // scattering events so far
  bool all_specular = true;
  ++counters.light_rays;
  for (int guard = 0; guard < 10000; ++guard) {
    Hit hit;
    if (counters.log) counters.log->closest_hit.push_back(ray);
    if (!scene.intersect(ray, &hit)) break;
    SurfacePoint sp = scene.surface(ray, hit);
    const Material& m = scene.materials[scene.objects[hit.object].material];
    if (std::holds_alternative<InterfaceMaterial>(m)) {
      ray = spawn_ray(sp, ray.d);
      ++counters.light_rays;
      continue;
    }
    Vec3 wo = -ray.d;  // toward where the photon came from
    bool is_diffuse = !bsdf_is_specular(m);
    if (is_diffuse) {
      ++counters.diffuse_hits;
      // Direct photons are never used: next-event estimation counts direct light.
      if (bounces > 0 && maps.has_photons(hit.object)) {
        PhotonClass cls = all_specular ? PhotonClass::kCaustic : PhotonClass::kIndirect;
        gather_at_hit(scene, maps, prm, owner, hit.object, sp, wo, beta, cls, bounces, out, counters);
      }
    }
    // Scattering makes bounces + 1; a backward photon adds at least one eye vertex.
    if (bounces + 2 > prm.max_depth) break;
    Frame frame = Frame::from_z(sp.ns);
    Vec3 wo_local = frame.to_local(wo);
    if (wo_local.z == 0) break;
    auto bs = bsdf_sample(m, wo_local, rng.uniform(), {rng.uniform(), rng.uniform()}, TransportMode::kImportance);
    if (!bs) break;
    Vec3 wi = frame.to_world(bs->wi);
    // Adjoint BSDF with shading normals (Veach 1997, 5.3): |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|)
    // times the usual f |wi.ns| / pdf.
    float cos_o_g = std::fabs(dot(wo, sp.ng));
    if (cos_o_g == 0) break;
    Spectrum bnew = beta * bs->f * (std::fabs(wo_local.z) * std::fabs(dot(wi, sp.ng)) / (cos_o_g * bs->pdf_solid_angle));
    // Russian roulette on the change of power (pbrt-v4's SPPM photon pass).
    float q = std::fmax(0.0f, 1 - bnew.max_component() / beta.max_component());
    if (rng.uniform() < q) break;
    beta = bnew / (1 - q);
    if (beta.is_black() || !beta.is_finite()) break;
    ++bounces;
    all_specular = all_specular && bs->is_specular();
    ray = spawn_ray(sp, wi);
    ++counters.light_rays;
  }
}

}  // namespace bpm
