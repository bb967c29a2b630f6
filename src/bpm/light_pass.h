// The light pass, phase one (section 3 of the paper): photons travel as photons/light_path.h
// says; at each diffuse hit the hit object's tree gives
// the backward photons whose spheres contain the hit, and each accepted pair is appended as
// (backward photon, contribution) to the caller's lists, one per mask slot, so that phase two can
// apply each slot's entries without locks.
#pragma once
#include <cstdint>
#include <vector>

#include "base/rng.h"
#include "bpm/backward_maps.h"
#include "photons/light_path.h"
#include "scene/render_scene.h"

namespace bpm {

struct PhotonEntry {
  uint32_t backward_photon;  // index into BackwardMaps::photons
  Spectrum value;            // flux * f * |cos_s| / |cos_g|, before 1 / (pi r^2 N)
};

struct LightPassParams {
  const WavelengthMaterials* materials = nullptr;  // this iteration's wavelengths
  int max_depth = 5;
  float normal_cos = 0.5f;
  // When the scene has textured materials: each backward photon's material, resolved once at its
  // point (resolve_photon_materials) instead of once per photon that reaches it; may be empty.
  std::vector<Material> photon_materials;
};

// Fills prm->photon_materials for the backward photons of maps when a material is textured.
void resolve_photon_materials(const BackwardMaps& maps, LightPassParams* prm);


// Traces one photon. owner[pixel] is the mask slot of the pixel; out has one list per slot.
void trace_photon(const RenderScene& scene, const BackwardMaps& maps, const LightPassParams& params,
                  const std::vector<uint16_t>& owner, Rng& rng, std::vector<std::vector<PhotonEntry>>& out,
                  LightCounters& counters);

}  // namespace bpm
