// Forward photon maps (Jensen 1996): the light pass of fpm stores one forward photon at every
// diffuse surface a photon reaches, in a global map, and also in a caustic map when the path so
// far was specular only; and one at every point where it scatters in a medium, in a volume map
// (Jensen and Christensen 1998); each map has a kd-tree over the photon centres.
#pragma once
#include <tbb/enumerable_thread_specific.h>

#include <cstdint>
#include <functional>
#include <vector>

#include "photons/light_path.h"
#include "photons/sensor_discs.h"
#include "photons/sphere_kdtree.h"
#include "scene/render_scene.h"

namespace bpm {

struct ForwardPhoton {
  Vec3 p;
  Vec3 wi;  // toward where the photon came from
  Vec3 ng;  // zero in a medium
  Spectrum flux;
  uint16_t bounces;
  PhotonClass cls;
  bool hero_only;       // the photon keeps its hero wavelength alone (PathState)
  int16_t medium = -1;  // the medium it scatters in (volume map), -1 on a surface
};

struct PhotonMap {
  std::vector<ForwardPhoton> photons;
  CentreKdTree tree;
  void build();
  size_t photon_bytes() const { return photons.size() * sizeof(ForwardPhoton); }
};

struct ForwardMaps {
  PhotonMap global, caustic, volume;
  // Per chunk of photons, the photons it stored: joined in chunk order, so that the maps do not
  // depend on the thread count.
  struct Chunk {
    std::vector<ForwardPhoton> global, caustic, volume;
    std::vector<SensorCrossing> crossings;  // of the illuminance sensors' discs, if any
  };
  std::vector<Chunk> chunks;
};

// Traces n_photons photons (streams keyed by seed, pass_index and photon index) at the wavelengths
// of wm and stores them. min_eye_vertices: the eye vertices the estimate adds (2 with final
// gathering), so that no stored photon makes a path longer than max_depth. `stop`, asked before
// each chunk of photons, may end the pass early (after its first chunk). Returns the photons
// emitted into the maps: N of the density estimate. With sensors, each chunk also records its
// photons' crossings of their discs.
uint64_t trace_forward_photons(const RenderScene& scene, const WavelengthMaterials& wm,
                               int max_depth, int min_eye_vertices, uint64_t n_photons,
                               uint64_t seed, int pass_index,
                               tbb::enumerable_thread_specific<LightCounters>& counters,
                               const std::function<bool()>& stop, ForwardMaps* maps,
                               const SensorDiscs* sensors = nullptr);

// Joins the chunks into the three maps and builds their trees.
void build_forward_maps(ForwardMaps* maps);

}  // namespace bpm
