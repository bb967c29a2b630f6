#include "bpm/disc_shares.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "base/rng.h"
#include "photons/disc_probes.h"

namespace bpm {

namespace {
constexpr uint64_t kProbeStream = 0x70726f626573ull;
}  // namespace

void probe_lit_discs(const RenderScene& scene, const LightPassResult& light, float normal_cos,
                     uint64_t seed, int iteration, BackwardMaps* maps,
                     tbb::enumerable_thread_specific<EyeCounters>* counters) {
  const std::vector<uint32_t>& begin = maps->object_begin;
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, maps->photons.size(), 1024),
      [&](const tbb::blocked_range<size_t>& r) {
        PathCounters& rays = counters->local().rays;
        for (size_t g = r.begin(); g < r.end(); ++g) {
          BackwardPhoton& bp = maps->photons[g];
          if (!bp.probes_pending || !light.reached[g] || light.flux[g].is_black()) continue;
          const int object =
              int(std::upper_bound(begin.begin(), begin.end(), g) - begin.begin()) - 1;
          SurfacePoint sp;
          sp.p = bp.p;
          sp.ng = bp.ng;
          sp.ns = bp.ns;
          sp.error = bp.error();
          Rng rng(stream_key(seed ^ kProbeStream, uint64_t(iteration), bp.pixel, bp.place));
          const DiscProbes probes =
              cast_disc_probes(scene, sp, bp.wo, object, PhotonSurfaces::kOwnObject, bp.radius,
                               normal_cos, rng, rays);
          bp.disc_found = probes.found;
          bp.disc_cut = probes.cut;
        }
      });
}

}  // namespace bpm
