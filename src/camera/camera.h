// pbrt-v4's perspective camera: the fov spans the shorter image axis, raster y grows downward,
// and camera space looks down +z with +x to the right of the image.
#pragma once
#include "base/ray.h"
#include "base/transform.h"

namespace bpm {

struct CameraSettings {
  Transform world_from_camera;
  float fov_degrees = 90;
  float lens_radius = 0;
  float focal_distance = 1e6f;
  float screen_window[4] = {0, 0, 0, 0};  // x0 x1 y0 y1; all zero means pbrt-v4's default
};

class PerspectiveCamera {
 public:
  PerspectiveCamera(const CameraSettings& s, int width, int height);
  // p_raster in pixels ((0,0) is the top-left corner of the image); u_lens in [0,1)^2.
  Ray generate_ray(Vec2 p_raster, Vec2 u_lens) const;
  Vec3 position() const { return world_from_camera_.point(Vec3(0, 0, 0)); }
  // Solid angle one pixel subtends at the image centre (steradians).
  float pixel_solid_angle() const { return pixel_solid_angle_; }

 private:
  Transform world_from_camera_;
  float lens_radius_, focal_distance_;
  float x0_, x1_, y0_, y1_;  // screen window
  float tan_half_;
  int width_, height_;
  float pixel_solid_angle_;
};

}  // namespace bpm
