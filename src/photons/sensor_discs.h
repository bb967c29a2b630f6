// Illuminance sensors (integrator/sensors.h) as the photon methods estimate them: a sensor is a
// backward photon of transmittance 1 with no camera, where the caustics come from photons and the
// rest from paths traced from the sensor, as at the first diffuse vertex of an eye path that goes
// on (DESIGN.md's D = 1). The paths are the path tracer's (sensor_irradiance) without the light
// that reaches the sensor through traced lobes only; that light, a caustic, comes from the
// iteration's caustic photons that reach a disc of radius r at the sensor's point, facing its
// normal, that blocks no light: their flux over the disc's area and the photons emitted. A sensor
// in mid-air counts the photons whose paths cross its disc from its front; a sensor on a surface
// (one that its point lies on) counts the photons that land on a surface within r of it whose
// normal agrees with its own (as a backward photon gathers: a disc in its tangent plane would
// miss a concave surface's photons). Either counts a photon only where the sensor's point sees it
// (a shadow ray), so that light beside an object standing on the sensor's plane does not reach a
// sensor under it. Light through glass from a point or a distant light, which no path from the
// sensor can find, is found so; light that paths find well (direct, diffuse interreflection) is
// left to them.
//
// A disc's radius is a backward photon's at that point: k1 pixel footprints at the sensor's
// distance from the camera, at most half the side of its grid cell (so that neighbouring cells do
// not share photons), shrinking with the iterations as the backward photons' radii do. The photons
// within r / sqrt 2 and r / 2 of the centre give the bias estimate (photons/density.h).
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "camera/camera.h"
#include "film/film.h"
#include "integrator/sensors.h"
#include "photons/light_path.h"
#include "photons/settings.h"
#include "photons/sphere_kdtree.h"

namespace bpm {

// A photon's crossing of a sensor's disc: the luminance of its flux there (per photon emitted,
// before the division by pi r^2 N), and whether it lies within r / sqrt 2 (inner) and r / 2
// (quarter) of the centre.
struct SensorCrossing {
  uint32_t sensor;
  bool inner, quarter;
  float value;
};

class SensorDiscs {
 public:
  // base_radius: per sensor, its radius in the first iteration; normal_cos: the least cosine
  // between a sensor's normal and that of a surface whose photons it counts.
  SensorDiscs(const RenderScene& scene, const std::vector<Sensor>& sensors,
              std::vector<float> base_radius, float normal_cos);
  ~SensorDiscs();
  SensorDiscs(const SensorDiscs&) = delete;
  SensorDiscs& operator=(const SensorDiscs&) = delete;

  size_t size() const { return sensors_.size(); }
  const Sensor& sensor(size_t i) const { return sensors_[i]; }
  float radius(size_t i) const { return base_radius_[i] * scale_; }
  // Whether sensor i lies on a surface (it counts the photons landing there).
  bool on_surface(size_t i) const { return on_surface_[i] != 0; }
  // The radii of an iteration: base radius times `scale` (radius_scale); rebuilds the tree.
  void set_scale(float scale);
  // Appends the sensors a caustic photon's segment reaches (other photons reach none).
  void cross(const RenderScene& scene, const Wavelengths& wl, const PhotonSegment& segment,
             std::vector<SensorCrossing>* out) const;

 private:
  struct Tree;
  // Appends sensor i's record of a photon at x with `flux` (before any medium between) at
  // distance t along the segment, if the sensor sees x.
  void reach(const RenderScene& scene, const Wavelengths& wl, const PhotonSegment& seg, uint32_t i,
             float t, std::vector<SensorCrossing>* out) const;
  std::vector<Sensor> sensors_;
  std::vector<float> base_radius_;
  std::vector<uint8_t> on_surface_;
  std::vector<uint32_t> in_air_;  // the mid-air sensors, in the order of the disc tree's primitives
  float normal_cos_;
  float scale_ = 1;
  std::unique_ptr<Tree> tree_;
};

// The segments of trace_light_path that a photon's crossings of the discs are recorded from: every
// piece after up to max_depth bounces (a sensor adds no vertex), none without sensors.
struct SensorSegments {
  const RenderScene& scene;
  const SensorDiscs* discs;  // null: no sensors, no segments asked for
  const Wavelengths& wl;
  std::vector<SensorCrossing>& out;
  int depth;
  SensorSegments(const RenderScene& scene, const SensorDiscs* discs, const Wavelengths& wl,
                 std::vector<SensorCrossing>& out, int max_depth)
      : scene(scene), discs(discs), wl(wl), out(out), depth(discs ? max_depth : -1) {}
  void operator()(const PhotonSegment& s) const { discs->cross(scene, wl, s, &out); }
};

// The sensors of a render (none: null), with the first iteration's radii (see the top of this
// file): k1 footprints of a pixel of `camera` seen directly, at most half a grid
// cell; at least a millionth of the scene's bounding radius.
std::unique_ptr<SensorDiscs> make_sensor_discs(const RenderScene& scene,
                                               const std::vector<Sensor>& sensors,
                                               const Camera& camera,
                                               const PhotonSettings& settings);

// One iteration of the sensors: the photons' crossings summed per sensor in a fixed order, then
// with each sensor's direct light added to the film as that iteration's estimate and bias.
class SensorIteration {
 public:
  explicit SensorIteration(size_t sensors) : all_(sensors), half_(sensors), quarter_(sensors) {}
  void clear();
  void add(const std::vector<SensorCrossing>& crossings);
  // The estimates of iteration `it` once `emitted` photons crossed the discs: the paths of
  // kSensorSamplesPerPass samples (streams keyed by seed, it, sensor) plus the caustic photons'
  // density, kept until record() adds them to the film.
  void finish(const RenderScene& scene, const SensorDiscs& discs, int max_depth, BiasModel model,
              uint64_t seed, int it, uint64_t emitted);
  void record(Film* film) const;

 private:
  std::vector<double> all_, half_, quarter_;
  std::vector<double> estimate_, bias_;
};

}  // namespace bpm
