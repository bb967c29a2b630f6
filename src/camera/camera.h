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

// The pixels a camera renders: width x height of its full_width x full_height raster, from pixel
// (x0, y0) (a crop: pbrt-v4's "cropwindow" and "pixelbounds").
struct Raster {
  int width = 0, height = 0, full_width = 0, full_height = 0, x0 = 0, y0 = 0;
};

class PerspectiveCamera {
 public:
  PerspectiveCamera(const CameraSettings& s, const Raster& raster);
  PerspectiveCamera(const CameraSettings& s, int width, int height)
      : PerspectiveCamera(s, Raster{width, height, width, height, 0, 0}) {}
  // p_raster in pixels of the image rendered ((0,0) is the top-left corner of the crop); u_lens in
  // [0,1)^2.
  Ray generate_ray(Vec2 p_raster, Vec2 u_lens) const {
    return generate_ray_full({p_raster.x + crop_x0_, p_raster.y + crop_y0_}, u_lens);
  }
  // The same with p in pixels of the full raster.
  Ray generate_ray_full(Vec2 p_full, Vec2 u_lens) const;
  Vec3 position() const { return world_from_camera_.point(Vec3(0, 0, 0)); }
  // Solid angle one pixel subtends at the image centre (steradians).
  float pixel_solid_angle() const { return pixel_solid_angle_; }

 private:
  Transform world_from_camera_;
  float lens_radius_, focal_distance_;
  float x0_, x1_, y0_, y1_;  // screen window
  float tan_half_;
  int width_, height_;  // the full raster
  float crop_x0_, crop_y0_;
  float pixel_solid_angle_;
};

}  // namespace bpm
