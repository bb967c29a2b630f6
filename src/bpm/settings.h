// Settings of the backward photon mapping integrator, filled from the scene file's Integrator
// line and the command line, and printed in the run's JSON record.
#pragma once
#include "photons/settings.h"
#include "scene/parsed_scene.h"

namespace bpm {

struct BpmSettings : PhotonSettings {
  // D of DESIGN.md: diffuse vertices an eye path passes before its last backward photon (0..3).
  int diffuse_depth = 1;
  // A photon phase ends when this fraction of the backward photons that accept indirect light
  // has been hit at least once, or after max_batches batches.
  float coverage = 0.9f;
  int max_batches = 16;
  // Use the kd-tree over sphere centres (range search with the largest radius) instead of the
  // kd-tree over whole integration spheres; for measuring the paper's claim (section 2).
  bool centre_tree = false;
};

// bpm's parameters on the file's Integrator line (an "fpm" line takes the same ones); defaults
// for any other integrator. A bad value is an error at its place in the file.
BpmSettings bpm_settings_from_file(const SceneEntity& integrator);

}  // namespace bpm
