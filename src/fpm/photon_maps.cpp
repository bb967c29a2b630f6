#include "fpm/photon_maps.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>

namespace bpm {
namespace {
constexpr uint64_t kPhotonStream = 0x66706d70686f74ull;
}  // namespace

void PhotonMap::build() {
  std::vector<SphereRef> points(photons.size());
  for (size_t i = 0; i < photons.size(); ++i) points[i] = {photons[i].p, 0};
  tree.build(points);
}

uint64_t trace_forward_photons(const RenderScene& scene, const WavelengthMaterials& wm,
                               int max_depth, int min_eye_vertices, uint64_t n_photons,
                               uint64_t seed, int pass_index,
                               tbb::enumerable_thread_specific<LightCounters>& counters,
                               const std::function<bool()>& stop, ForwardMaps* maps,
                               const SensorDiscs* sensors) {
  const int n_chunks = int((n_photons + kPhotonsPerChunk - 1) / kPhotonsPerChunk);
  maps->chunks.resize(size_t(n_chunks));
  auto stop_now = [&] { return stop && stop(); };
  const int kept = run_chunks_until(n_chunks, stop_now, [&](int c) {
    LightCounters& lc = counters.local();
    ForwardMaps::Chunk& ch = maps->chunks[size_t(c)];
    ch.global.clear();
    ch.caustic.clear();
    ch.volume.clear();
    ch.crossings.clear();
    uint64_t first = uint64_t(c) * kPhotonsPerChunk,
             last = std::min(first + kPhotonsPerChunk, n_photons);
    for (uint64_t k = first; k < last; ++k) {
      Rng rng(stream_key(seed ^ kPhotonStream, uint64_t(pass_index), k, 2));
      const EmissionDraw e = unguided_emission(scene, rng);
      auto store = [&](const PhotonHit& hit) {
        if (hit.bounces + min_eye_vertices > max_depth) return;
        ForwardPhoton ph{
            hit.sp.p, hit.wi,        hit.sp.ng,          hit.flux, uint16_t(hit.bounces),
            hit.cls,  hit.hero_only, int16_t(hit.medium)};
        ++lc.entries;
        if (hit.medium >= 0) {
          // Collisions are as dense as sigma_s = density sigma_s(unit density) times the fluence:
          // the density is divided out here, the rest where the map is gathered.
          const Spectrum relative =
              scene.media[size_t(hit.medium)].relative_scattering(hit.sp.p, wm.wl);
          if (relative.is_black()) return;
          ph.flux = ph.flux / relative;
          ch.volume.push_back(ph);
          return;
        }
        ch.global.push_back(ph);
        if (hit.cls == PhotonClass::kCaustic) ch.caustic.push_back(ph);
      };
      trace_light_path(scene, wm, max_depth, min_eye_vertices, e, rng, lc, store,
                       SensorSegments(scene, sensors, wm.wl, ch.crossings, max_depth));
    }
  });
  // The chunks past the kept ones leave the maps.
  maps->chunks.resize(size_t(kept));
  return std::min(n_photons, uint64_t(kept) * kPhotonsPerChunk);
}

void build_forward_maps(ForwardMaps* maps) {
  maps->global.photons.clear();
  maps->caustic.photons.clear();
  maps->volume.photons.clear();
  for (const ForwardMaps::Chunk& ch : maps->chunks) {
    maps->global.photons.insert(maps->global.photons.end(), ch.global.begin(), ch.global.end());
    maps->caustic.photons.insert(maps->caustic.photons.end(), ch.caustic.begin(), ch.caustic.end());
    maps->volume.photons.insert(maps->volume.photons.end(), ch.volume.begin(), ch.volume.end());
  }
  tbb::parallel_invoke([&] { maps->global.build(); }, [&] { maps->caustic.build(); },
                       [&] { maps->volume.build(); });
}

}  // namespace bpm
