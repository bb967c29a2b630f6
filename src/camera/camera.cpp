#include "camera/camera.h"

#include <cmath>

#include "base/sampling.h"

namespace bpm {

PerspectiveCamera::PerspectiveCamera(const CameraSettings& s, const Raster& r)
    : world_from_camera_(s.world_from_camera),
      lens_radius_(s.lens_radius),
      focal_distance_(s.focal_distance),
      width_(r.full_width),
      height_(r.full_height),
      crop_x0_(float(r.x0)),
      crop_y0_(float(r.y0)) {
  const int width = r.full_width, height = r.full_height;
  float aspect = float(width) / float(height);
  if (s.screen_window[0] == 0 && s.screen_window[1] == 0 && s.screen_window[2] == 0 &&
      s.screen_window[3] == 0) {
    if (aspect > 1) {
      x0_ = -aspect, x1_ = aspect, y0_ = -1, y1_ = 1;
    } else {
      x0_ = -1, x1_ = 1, y0_ = -1 / aspect, y1_ = 1 / aspect;
    }
  } else {
    x0_ = s.screen_window[0], x1_ = s.screen_window[1], y0_ = s.screen_window[2],
    y1_ = s.screen_window[3];
  }
  tan_half_ = std::tan(s.fov_degrees * kPi / 360);
  float px = (x1_ - x0_) / width * tan_half_, py = (y1_ - y0_) / height * tan_half_;
  pixel_solid_angle_ = px * py;
}

Ray PerspectiveCamera::generate_ray_full(Vec2 p, Vec2 u_lens) const {
  float sx = x0_ + (p.x / width_) * (x1_ - x0_);
  float sy = y1_ - (p.y / height_) * (y1_ - y0_);
  Vec3 dir = normalize(Vec3(sx * tan_half_, sy * tan_half_, 1));
  Vec3 origin(0, 0, 0);
  if (lens_radius_ > 0) {
    Vec2 l = sample_uniform_disk_concentric(u_lens);
    Vec3 p_lens(l.x * lens_radius_, l.y * lens_radius_, 0);
    Vec3 p_focus = dir * (focal_distance_ / dir.z);
    origin = p_lens;
    dir = normalize(p_focus - p_lens);
  }
  return Ray{world_from_camera_.point(origin), normalize(world_from_camera_.vector(dir)), kInf};
}

}  // namespace bpm
