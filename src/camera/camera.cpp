#include "camera/camera.h"

#include <algorithm>
#include <cmath>

#include "base/error.h"
#include "base/sampling.h"

namespace bpm {
namespace {

// The solid angle of a pixel of the equirectangular row about raster y.
float equirectangular_pixel_solid_angle(float y, int width, int height) {
  const int row = std::clamp(int(std::floor(y)), 0, height - 1);
  return float(latlong_cell_solid_angle(row, width, height));
}

}  // namespace

Camera::Camera(const CameraSettings& s, const Raster& r)
    : world_from_camera_(s.world_from_camera),
      projection_(s.projection),
      lens_radius_(s.lens_radius),
      focal_distance_(s.focal_distance),
      width_(r.full_width),
      height_(r.full_height),
      crop_x0_(float(r.x0)),
      crop_y0_(float(r.y0)),
      lens_(s.lens),
      medium_(s.medium) {
  const int width = r.full_width, height = r.full_height;
  const float aspect =
      s.frame_aspect_ratio > 0 ? s.frame_aspect_ratio : float(width) / float(height);
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
  const float dx = std::fabs(x1_ - x0_) / float(width), dy = std::fabs(y1_ - y0_) / float(height);
  switch (projection_) {
    case Projection::kPerspective:
      pixel_angle_ = std::sqrt(dx * tan_half_ * dy * tan_half_);
      break;
    case Projection::kOrthographic:
      pixel_width_ = std::sqrt(length(world_from_camera_.vector(Vec3(dx, 0, 0))) *
                               length(world_from_camera_.vector(Vec3(0, dy, 0))));
      break;
    case Projection::kSphericalEqualArea:
      pixel_angle_ = std::sqrt(4 * kPi / (float(width) * float(height)));
      break;
    case Projection::kSphericalEquirectangular:
      break;  // per row
    case Projection::kRealistic:
      BPM_CHECK(lens_);
      pixel_angle_ = lens_->pixel_spread();
      break;
  }
}

// pbrt-v4's spherical directions, with its y and z swapped: +y up.
Vec3 Camera::camera_direction(Vec2 p) const {
  Vec2 uv{p.x / float(width_), p.y / float(height_)};
  Vec3 d;
  if (projection_ == Projection::kSphericalEquirectangular) {
    const float theta = kPi * uv.y, phi = 2 * kPi * uv.x;
    d = Vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  } else {
    d = equal_area_square_to_sphere(wrap_equal_area_square(uv));
  }
  return Vec3(d.x, d.z, d.y);
}

CameraRay Camera::generate_ray_full(Vec2 p, Vec2 u_lens) const {
  if (projection_ == Projection::kSphericalEqualArea ||
      projection_ == Projection::kSphericalEquirectangular)
    return {Ray{world_from_camera_.point(Vec3(0, 0, 0)),
                normalize(world_from_camera_.vector(camera_direction(p))), kInf},
            1, medium_};
  if (projection_ == Projection::kRealistic) {
    CameraRay r = lens_->generate({p.x / float(width_), p.y / float(height_)}, u_lens);
    r.ray = Ray{world_from_camera_.point(r.ray.o), normalize(world_from_camera_.vector(r.ray.d))};
    r.medium = medium_;
    return r;
  }
  const float sx = x0_ + (p.x / float(width_)) * (x1_ - x0_);
  const float sy = y1_ - (p.y / float(height_)) * (y1_ - y0_);
  Vec3 origin(0, 0, 0), dir;
  if (projection_ == Projection::kOrthographic) {
    origin = Vec3(sx, sy, 0);
    dir = Vec3(0, 0, 1);
  } else {
    dir = normalize(Vec3(sx * tan_half_, sy * tan_half_, 1));
  }
  if (lens_radius_ > 0) {
    // As pbrt-v4: the lens is about the camera's origin for both projections.
    const Vec2 l = sample_uniform_disk_concentric(u_lens);
    const Vec3 p_lens(l.x * lens_radius_, l.y * lens_radius_, 0);
    const Vec3 p_focus = origin + dir * (focal_distance_ / dir.z);
    origin = p_lens;
    dir = normalize(p_focus - p_lens);
  }
  return {Ray{world_from_camera_.point(origin), normalize(world_from_camera_.vector(dir)), kInf}, 1,
          medium_};
}

PixelFootprint Camera::footprint(Vec2 p_full) const {
  switch (projection_) {
    case Projection::kOrthographic:
      return {pixel_width_, 0};
    case Projection::kSphericalEquirectangular:
      return {0, std::sqrt(equirectangular_pixel_solid_angle(p_full.y, width_, height_))};
    default:
      return {0, pixel_angle_};
  }
}

float Camera::footprint_at(Vec3 p) const {
  const Vec3 o = world_from_camera_.point(Vec3(0, 0, 0));
  const float distance = length(p - o);
  switch (projection_) {
    case Projection::kOrthographic:
      return pixel_width_;
    case Projection::kSphericalEquirectangular: {
      if (!(distance > 0)) return 0;
      const Vec3 d = world_from_camera_.inverse().vector(p - o);
      const float theta = std::acos(std::clamp(d.y / length(d), -1.0f, 1.0f));
      const float y = theta / kPi * float(height_);
      return std::sqrt(equirectangular_pixel_solid_angle(y, width_, height_)) * distance;
    }
    default:
      return pixel_angle_ * distance;
  }
}

}  // namespace bpm
