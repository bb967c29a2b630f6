// What both photon methods share in their settings: integration radii in pixel footprints, how
// they shrink over iterations, photons per batch and the normal test. Filled from the scene file's
// Integrator line and the command line, and printed in the run's JSON record.
#pragma once
#include <optional>
#include <string>

#include "scene/parsed_scene.h"

namespace bpm {

// How radii shrink over the iterations: not at all; all pixels alike, by Knaus and Zwicker's
// schedule; or each pixel by that schedule counted in the iterations whose photons reached it
// (bpm only: EyePixels::lit_share).
enum class RadiusPolicy { kFixed, kProgressive, kPerPixel };

// Where bpm combines its photon merges with the eye path's continuation (photons/merge_weights.h):
// nowhere (the partition), at last diffuse vertices whose gathered lobes include a glossy one
// (bsdf_gathers_glossy), at every last diffuse vertex, or at the glossy ones always and at the
// others with a probability each pixel chooses from its own statistics (bpm/eye_pass.h,
// continue_level). As the file and the flag name them: "partition", "glossy", "combined", "auto".
enum class CombineAt { kNowhere, kGlossy, kEverywhere, kChosen };

// How the bias of a radius-r density estimate is estimated from the same photons gathered over
// nested discs (PhotonSettings::bias_model).
enum class BiasModel {
  // Two radii: the bias as the leading r^2 term of a smooth density, 2 (L(r) - L(r / sqrt 2)).
  kSquare,
  // Three radii: a r^2 + b r fitted per estimate from L(r), L(r / sqrt 2) and L(r / 2), which also
  // covers the r term of edges and caustic boundaries (where the density jumps).
  kSquareAndLinear,
};

inline const char* to_string(BiasModel m) { return m == BiasModel::kSquare ? "r2" : "r2+r"; }

struct PhotonSettings {
  // Integration radii in pixel footprints (the side of one pixel seen at the vertex): k0 for
  // caustic photons before the last diffuse vertex (bpm) or in the caustic map (fpm), k1 for the
  // last diffuse vertex (bpm) or the global map (fpm). k1 4.5: docs/MEASUREMENTS.md,
  // "Leave-one-out".
  float k0 = 1, k1 = 4.5f;
  RadiusPolicy radius_policy = RadiusPolicy::kProgressive;
  // Knaus & Zwicker 2011: r_(i+1)^2 = r_i^2 (i + alpha) / (i + 1).
  float alpha = 2.0f / 3.0f;
  // Photons emitted per iteration: a fixed count, never one that depends on what they hit. 0 (the
  // default): by the image's size, photons_for().
  int photons_per_iteration = 0;
  // Photons count only where the normals of the photon's surface and of the gathering point agree
  // to within this cosine.
  float normal_cos = 0.5f;
  // Divide each estimate by the share of its disc where photons can land, measured by probe rays
  // near edges (photons/disc_probes.h), instead of by the whole disc.
  bool disc_probes = true;
  // Record the photon estimates less their bias estimate (2 L(r / sqrt 2) - L(r) under kSquare;
  // film.h, add_bias): noisier, and without a bias estimate of its own.
  bool debias = false;
  BiasModel bias_model = BiasModel::kSquare;
};

inline const char* to_string(RadiusPolicy p) {
  switch (p) {
    case RadiusPolicy::kFixed:
      return "fixed";
    case RadiusPolicy::kProgressive:
      return "progressive";
    case RadiusPolicy::kPerPixel:
      break;
  }
  return "perpixel";
}
inline std::optional<RadiusPolicy> parse_radius_policy(const std::string& s) {
  for (RadiusPolicy p : {RadiusPolicy::kFixed, RadiusPolicy::kProgressive, RadiusPolicy::kPerPixel})
    if (s == to_string(p)) return p;
  return std::nullopt;
}

inline const char* to_string(CombineAt c) {
  switch (c) {
    case CombineAt::kNowhere:
      return "partition";
    case CombineAt::kGlossy:
      return "glossy";
    case CombineAt::kEverywhere:
      return "combined";
    case CombineAt::kChosen:
      break;
  }
  return "auto";
}
inline std::optional<CombineAt> parse_combine_at(const std::string& s) {
  for (CombineAt c :
       {CombineAt::kNowhere, CombineAt::kGlossy, CombineAt::kEverywhere, CombineAt::kChosen})
    if (s == to_string(c)) return c;
  return std::nullopt;
}

// Photons per iteration for an image of `pixels` pixels: the count set, or by default 100000 per
// 256x256 pixels and at least 100000. A backward photon's radius is a few pixel footprints, so
// this keeps the photons one finds per iteration, and with them the balance of eye and light
// work, the same at every resolution (docs/MEASUREMENTS.md, "Photons per iteration").
int photons_for(const PhotonSettings& s, size_t pixels);

// Radius scale (not squared) of iteration i (0-based) under the policy: 1 for the first. The
// per-pixel policy's pixels follow the progressive schedule at a fractional iteration
// (radius_scale_at); its value for the image as a whole is the progressive one.
float radius_scale(const PhotonSettings& s, int iteration);
// The progressive schedule at iteration t >= 0, not necessarily whole: its squared scale
// interpolated linearly between the whole iterations around t (radius_scale's at whole t).
float radius_scale_at(const PhotonSettings& s, double t);

// Reads k0, k1, radiuspolicy, alpha, discprobes and photonsperiteration (pbrt-v4 sppm's name) from
// an Integrator line; a bad value is an error at its place in the file.
void read_photon_settings(const SceneEntity& integrator, PhotonSettings* s);

}  // namespace bpm
