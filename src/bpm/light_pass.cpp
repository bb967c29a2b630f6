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
  // A backward photon adds at least one eye vertex; direct photons are never used (next-event
  // estimation counts direct light).
  trace_light_path(scene, prm.max_depth, 1, rng, counters, [&](const PhotonHit& h) {
    if (h.cls != PhotonClass::kDirect && maps.has_photons(h.object))
      gather_at_hit(scene, maps, prm, owner, h.object, h.sp, h.wi, h.flux, h.cls, h.bounces, out, counters);
  });
}

}  // namespace bpm
