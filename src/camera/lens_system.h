// pbrt-v4's "realistic" camera: a system of spherical lens interfaces and an aperture stop between
// the film and the scene, as in a lens file (pbrt-v4's cameras.cpp, RealisticCamera; pbrt-v3's
// book, section 6.4). Camera space has the film in the plane z = 0 and the scene toward +z; all
// lengths are in metres.
#pragma once
#include <vector>

#include "base/ray.h"

namespace bpm {

// One interface, from the scene side to the film: a sphere of signed curvature radius (positive:
// centred toward the film), or the aperture stop (radius 0); the distance to the next interface
// (the last one's: to the film); the refractive index behind it (toward the film; 0 or 1: air);
// the radius of its clear aperture.
struct LensInterface {
  float curvature_radius = 0, thickness = 0, eta = 0, aperture_radius = 0;
  bool is_stop() const { return curvature_radius == 0; }
};

// A diaphragm shape over the stop: values on a grid across the stop's square [-r, r]^2, rows from
// -y up, scaled so that their mean over the square is pi/4 (a circular stop's), as pbrt-v4 does.
// Empty: the stop is a circle.
struct ApertureMask {
  int width = 0, height = 0;
  std::vector<float> values;
  bool empty() const { return values.empty(); }
  float at(float u, float v) const;  // bilinear between texel centres, 0 outside
};

struct LensSettings {
  std::vector<LensInterface> interfaces;  // front (scene side) to rear
  float focus_distance = 10;              // metres from the film
  float film_diagonal = 0.035f;           // metres
  ApertureMask aperture;
};

class LensSystem {
 public:
  // Focuses the system on settings.focus_distance (a thick-lens approximation moves the rear
  // interface) and bounds the exit pupil over the film. Throws Error (no location) where the
  // lens cannot focus there or passes no light.
  LensSystem(LensSettings settings, int full_width, int full_height);

  // The ray from film position s ([0, 1]^2 over the full raster, y down) through a point of the
  // exit pupil chosen by u, in camera space. Its weight is pbrt-v4's: cos^4 of the ray's angle on
  // the film over the pupil sample's pdf and the squared distance to the rear interface, times
  // the aperture mask. Weight 0: the lens stops this ray (the ray is then the optical axis).
  CameraRay generate(Vec2 s, Vec2 u) const;
  // The angle one pixel subtends in the scene, about the optical axis.
  float pixel_spread() const { return pixel_spread_; }
  float effective_focal_length() const { return focal_length_; }
  // The rear interface's distance from the film, once focused.
  float rear_z() const { return interfaces_.back().thickness; }

  // Exposed for tests: the ray leaving the front of the lens for one leaving the film (camera
  // space), and its aperture-mask weight; 0 when the lens stops it.
  float trace_from_film(const Ray& r, Ray* out) const;

 private:
  struct PupilBox {
    float x0 = 1, y0 = 1, x1 = -1, y1 = -1;  // empty
    bool empty() const { return !(x1 > x0 && y1 > y0); }
  };
  float trace_from_scene(const Ray& r, Ray* out) const;
  float front_z() const;
  void focus(float distance);
  PupilBox bound_exit_pupil(float film_x0, float film_x1) const;
  PupilBox bound_exit_pupil(float film_x0, float film_x1, const PupilBox& search, int n) const;

  std::vector<LensInterface> interfaces_;
  ApertureMask aperture_;
  float film_diagonal_, extent_x_, extent_y_;  // the film's physical size
  std::vector<PupilBox> pupil_;                // by distance from the film centre
  float pixel_spread_ = 0, focal_length_ = 0;
};

}  // namespace bpm
