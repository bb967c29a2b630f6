// Settings of the backward photon mapping integrator, filled from the scene file's Integrator
// line and the command line, and printed in the run's JSON record.
#pragma once
#include <string>

namespace bpm {

enum class RadiusPolicy { kFixed, kProgressive };

struct BpmSettings {
  // D of DESIGN.md: diffuse vertices an eye path passes before its last backward photon (0..3).
  int diffuse_depth = 1;
  // Integration radii in pixel footprints (the side of one pixel seen at the vertex): k0 for the
  // caustic-only photons before the last diffuse vertex, k1 for the last one.
  float k0 = 1, k1 = 3;
  RadiusPolicy radius_policy = RadiusPolicy::kProgressive;
  // Knaus & Zwicker 2011: r_(i+1)^2 = r_i^2 (i + alpha) / (i + 1).
  float alpha = 2.0f / 3.0f;
  int photons_per_batch = 100000;
  // A photon phase ends when this fraction of the backward photons that accept indirect light
  // has been hit at least once, or after max_batches batches.
  float coverage = 0.9f;
  int max_batches = 16;
  // Photons count only where the normals of the photon's surface and of the backward photon's
  // agree to within this cosine.
  float normal_cos = 0.5f;
  // Use the kd-tree over sphere centres (range search with the largest radius) instead of the
  // kd-tree over whole integration spheres; for measuring the paper's claim (section 2).
  bool centre_tree = false;
};

// Forward photon mapping's own settings; its radii (k0 for the caustic map, k1 for the global
// map), their policy and its photons per iteration (photons_per_batch) are BpmSettings'.
struct FpmSettings {
  bool final_gather = false;  // read indirect light one diffuse bounce later
  int knn = 0;                // > 0: radius from the knn nearest photons (capped by the k radius)
};

inline const char* to_string(RadiusPolicy p) { return p == RadiusPolicy::kFixed ? "fixed" : "progressive"; }

// Radius scale (not squared) of iteration i (0-based) under the policy: 1 for the first.
float radius_scale(const BpmSettings& s, int iteration);

}  // namespace bpm
