#include "bpm/light_pass.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "photons/density.h"

namespace bpm {
namespace {

// Adds the entries of one diffuse hit: the photon arrives at sp along -wi with `flux`.
void gather_at_hit(const BackwardMaps& maps, const LightPassParams& prm,
                   const std::vector<uint16_t>& owner, int object, const SurfacePoint& sp, Vec3 wi,
                   const Spectrum& flux, PhotonClass cls, int bounces, std::vector<std::vector<PhotonEntry>>& out,
                   LightCounters& counters) {
  ++counters.queries;
  maps.query(object, sp.p, [&](uint32_t g) {
    const BackwardPhoton& bp = maps.photons[g];
    if (!bp.accepts_class(cls) || int(bp.eye_depth) + bounces > prm.max_depth) return;
    if (dot(bp.ng, sp.ng) < prm.normal_cos) return;
    Material storage;
    const Material& m = prm.photon_materials.empty()
                            ? prm.materials->at(int(bp.material), TextureContext{bp.p, bp.uv}, storage)
                            : prm.photon_materials[g];
    Spectrum value = photon_contribution(m, bp.ng, bp.ns, bp.wo, wi, flux);
    if (value.is_black()) return;
    out[owner[bp.pixel]].push_back({g, value});
    ++counters.entries;
  });
}

}  // namespace

void resolve_photon_materials(const BackwardMaps& maps, LightPassParams* prm) {
  prm->photon_materials.clear();
  const WavelengthMaterials& wm = *prm->materials;
  if (std::none_of(wm.textured.begin(), wm.textured.end(), [](char t) { return t != 0; })) return;
  prm->photon_materials.resize(maps.photons.size());
  tbb::parallel_for(size_t(0), maps.photons.size(), [&](size_t g) {
    const BackwardPhoton& bp = maps.photons[g];
    Material storage;
    prm->photon_materials[g] = wm.at(int(bp.material), TextureContext{bp.p, bp.uv}, storage);
  });
}

void trace_photon(const RenderScene& scene, const BackwardMaps& maps, const LightPassParams& prm,
                  const std::vector<uint16_t>& owner, Rng& rng, std::vector<std::vector<PhotonEntry>>& out,
                  LightCounters& counters) {
  // A backward photon adds at least one eye vertex; direct photons are never used (next-event
  // estimation counts direct light).
  trace_light_path(scene, *prm.materials, prm.max_depth, 1, rng, counters, [&](const PhotonHit& h) {
    if (h.cls != PhotonClass::kDirect && maps.has_photons(h.object))
      gather_at_hit(maps, prm, owner, h.object, h.sp, h.wi, h.flux, h.cls, h.bounces, out, counters);
  });
}

}  // namespace bpm
