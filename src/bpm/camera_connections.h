// Light tracing to the camera for caustic light seen directly (docs/METHOD.md, "Camera
// connections"). A photon that reached a surface through traced lobes only (a caustic photon) and
// landed where the pinhole camera sees it is joined to the camera by a shadow ray and spread over
// the pixels whose filters reach that point. The same light paths are those that each such pixel's
// eye path merges at its first vertex, over the disc that accepts caustic photons there; each
// pixel weighs the two by the balance heuristic. Per photon emitted, the merge makes the path
// camera - y with the density of its eye sample landing within r of y,
//   p_e(y) pi r^2 P,   p_e(y) = filter density(u - pixel centre) (du/domega) |cos_y| / d^2
// (u the point's place on the image, d its distance from the pinhole, cos_y at its geometric
// normal; P the probability that the camera's ray gets across the scattering media between, 1
// without them or where it crosses them for certain), times the chance that the eye path gathered
// at y (1 where it took both parts of a material, or the material has one); the connection makes it
// with density 1 (its shadow ray gets across for certain, its transmittance a weight). With the
// pixel's radius r = a d (a: its caustic disc's radius per unit of distance), d cancels. The
// connection's value for the pixel is its weight times normalized filter(u - centre) (du/domega)
// |cos_y| / d^2 times f(y, wi, toward the camera) times the photon's flux over its hit's cosine (as
// a merge's entry, photons/density.h).
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "base/spectrum.h"
#include "bpm/backward_photon.h"
#include "bpm/settings.h"
#include "camera/camera.h"
#include "film/filter.h"
#include "materials/material.h"
#include "scene/render_scene.h"

namespace bpm {

// What the light pass needs to connect photons to the camera in one iteration.
struct CameraConnections {
  ConnectionMode mode = ConnectionMode::kOff;
  const Camera* camera = nullptr;
  const Filter* filter = nullptr;
  int width = 0, height = 0;  // the image rendered
  // Per pixel, the radius of its disc that accepts caustic photons at a first vertex seen
  // directly: per unit of distance from the camera, or in world units with `world`.
  std::vector<float> caustic_radius;
  bool world = false;
  // The eye path chose by chance between the parts of a material at its first vertex (with
  // probability 1 - bsdf_traced_part_probability of gathering); false where it takes both.
  bool gather_by_chance = false;
  int camera_medium = -1;  // the medium the camera sits in
  // The number of pieces through scattering media nearest the camera that its rays cross for
  // certain, where they split there (EyePassParams::split_in_media at D = 0: kMaxMediumSplits); P
  // leaves them out.
  int certain_pieces = 0;
  bool on() const { return mode != ConnectionMode::kOff; }
};

// A caustic photon joined to the camera, before it is spread over the pixels (spread_to_pixels).
struct CameraHit {
  Vec2 raster;     // where it lands on the image
  float merge;     // the merge's density against the connection's, without the filter's density
  Spectrum value;  // per photon emitted (before 1 / N), without the filter's share and the weight
  bool odd;        // a photon of odd index in its chunk (LightPassResult::flux_odd)
};

// Joins a caustic photon's hit at sp (on a surface of material m, not a curve) to the camera:
// appends it to `out` if the camera sees the point. hero_only: the photon keeps its hero
// wavelength alone; at a dispersive material the connection does (as the eye path does there,
// keep_hero_wavelength_at). Counts its shadow ray in *rays.
void connect_to_camera(const RenderScene& scene, const CameraConnections& cc, const Material& m,
                       const SurfacePoint& sp, Vec3 wi, const Spectrum& flux, bool hero_only,
                       bool odd, const Wavelengths& wl, uint64_t* rays,
                       std::vector<CameraHit>& out);

// The rows of the image a hit's filter reaches: [first, last].
std::pair<int, int> rows_reached(const CameraConnections& cc, const CameraHit& hit);

// Adds hit's share of each pixel whose filter reaches it, in rows [row0, row1), to sums (and to
// odd_sums for an odd photon's), both per pixel of the image.
void spread_to_pixels(const CameraConnections& cc, const CameraHit& hit, int row0, int row1,
                      Spectrum* sums, Spectrum* odd_sums);

// Whether backward photon bp's merges of caustic photons compete with the connections: a disc
// that accepts them at a first vertex seen directly, on a surface.
inline bool merges_against_camera(const CameraConnections& cc, const BackwardPhoton& bp) {
  return cc.on() && (bp.accepts & kAcceptsCaustic) && bp.eye_depth == 1 && bp.diffuse_index == 0 &&
         bp.medium < 0;
}

// The weight of a merge of a caustic photon at bp (merges_against_camera) against the
// connection: p_e pi r^2 P / (p_e pi r^2 P + 1) at bp's point, pixel and radius, P the probability
// that the camera's ray got across the scattering media on its way (PathState::pass; the
// connection's shadow ray gets across for certain); 0 with kAlone. m is bp's material.
float merge_weight_against_camera(const RenderScene& scene, const CameraConnections& cc,
                                  const BackwardPhoton& bp, const Material& m,
                                  const Wavelengths& wl);

}  // namespace bpm
