// Settings of forward photon mapping: the photon settings it shares with bpm (k0 for the caustic
// map, k1 for the global map, photons_per_iteration) and its own.
#pragma once
#include <nlohmann/json.hpp>

#include "photons/settings.h"
#include "scene/parsed_scene.h"

namespace bpm {

struct FpmSettings : PhotonSettings {
  bool final_gather = false;  // read indirect light one diffuse bounce later
  int knn = 0;                // > 0: radius from the knn nearest photons (capped by the k radius)
};

// fpm's parameters on the file's Integrator line; defaults for any other integrator. A bad value
// is an error at its place in the file.
FpmSettings fpm_settings_from_file(const SceneEntity& integrator);

// The settings as the JSON record prints them (also a checkpoint's identity).
nlohmann::json settings_json(const FpmSettings& s);

// The radius policy fpm runs: bpm's per-pixel one (which both methods read from one set of photon
// settings) is the shared schedule here, since fpm keeps no statistics per pixel.
inline RadiusPolicy fpm_radius_policy(RadiusPolicy p) {
  return p == RadiusPolicy::kPerPixel ? RadiusPolicy::kProgressive : p;
}

}  // namespace bpm
