// Settings of the backward photon mapping integrator, filled from the scene file's Integrator
// line and the command line, and printed in the run's JSON record.
#pragma once
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "photons/settings.h"
#include "scene/parsed_scene.h"

namespace bpm {

// Light tracing to the camera for caustic light seen directly (bpm/camera_connections.h), and
// vertex connections (bpm/vertex_connections.h). kOn: the connections and the merges that make
// the same paths, each path weighed between them; kAlone: the connections count those paths in
// full (the merges' share included) and the merges not at all (a check of the connections'
// estimate: the image must not change); kOff: the merges alone (the paper's method).
enum class ConnectionMode : uint8_t { kOff, kOn, kAlone };
const char* to_string(ConnectionMode m);
std::optional<ConnectionMode> parse_connection_mode(const std::string& s);

struct BpmSettings : PhotonSettings {
  // bpm's radii shrink per pixel, with the iterations that brought its discs photons (DiscScales,
  // bpm/eye_pass.h; docs/MEASUREMENTS.md, "Radii per pixel").
  BpmSettings() { radius_policy = RadiusPolicy::kPerPixel; }
  // D of DESIGN.md: diffuse vertices an eye path passes before its last backward photon (0..3).
  // 0 by default: at equal time its error is lower than with 1 on every scene of bench/equal_time
  // (docs/MEASUREMENTS.md, "Diffuse depth").
  int diffuse_depth = 0;
  // Use the kd-tree over sphere centres (range search with the largest radius) instead of the
  // kd-tree over whole integration spheres; for measuring the paper's claim (section 2).
  bool centre_tree = false;
  // Guide photon emission toward what the camera sees (photons/emission_guide.h).
  bool guide_emission = true;
  // Camera samples per iteration for emission seen before the first diffuse vertex, in pixels
  // that show any (EyePassParams::emission_samples): emitter edges and lights seen through glass
  // converge with these, not with the iterations.
  int emission_samples = 8;
  // The most samples of direct light per iteration at an eye path's last diffuse vertex
  // (EyePassParams::direct_samples): each pixel takes what its measured variance pays for
  // (direct_sample_count).
  int direct_samples = 8;
  // When positive, the initial radius of every backward photon in world units (pbrt-v4 sppm's
  // "radius"), in place of k0 and k1; it shrinks with the radius policy like them.
  float radius = 0;
  // Eye paths toward their last diffuse vertex split in scattering media: each piece of their
  // ray through one gets a medium vertex, and the path also goes on past it
  // (sample_forced_medium_distance), where a free flight would pick one of the two. Off by
  // default: at equal time it halves the error in open fog and doubles it in a thick grid medium
  // (docs/MEASUREMENTS.md).
  bool split_in_media = false;
  // Combined estimators (photons/merge_weights.h): indirect light at the last diffuse vertex is
  // both gathered from the photons and found by the eye path going on from there, each path
  // weighed between the two by multiple importance sampling, instead of the photons' alone. By
  // default always where that vertex's gathered lobes include a glossy one, over which a photon
  // estimate is noisy, and elsewhere with a probability each pixel chooses from its own variance
  // and cost (docs/MEASUREMENTS.md, "Combined estimators").
  CombineAt combine = CombineAt::kChosen;
  // At the first vertex of a material with both parts (a sharp coat over a diffuse base, BsdfPart)
  // where gathering would end the eye path, the path takes both parts, instead of one by chance
  // with its weight divided by the chance (EyePassParams::split_coats): a coated floor seen from
  // the camera no longer carries the noise of that choice.
  bool split_coats = true;
  // Caustic photons joined to the camera where it sees them (ConnectionMode).
  ConnectionMode camera_connections = ConnectionMode::kOn;
  // Photons' vertices joined to the last diffuse vertex of a pixel's eye path drawn at random
  // (vertex connection, bpm/vertex_connections.h), each path weighed between that, the merge and
  // the continuation.
  ConnectionMode vertex_connections = ConnectionMode::kOff;
};

// bpm's parameters on the file's Integrator line (an "fpm" line takes the same ones; an "sppm"
// line gives diffuse depth 0, its radius and its photons per iteration); defaults for any other
// integrator. A bad value is an error at its place in the file.
BpmSettings bpm_settings_from_file(const SceneEntity& integrator);

// The settings as the JSON record prints them (also a checkpoint's identity).
nlohmann::json settings_json(const BpmSettings& s);

}  // namespace bpm
