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
      camera_from_world_(s.world_from_camera.inverse()),
      projection_(s.projection),
      lens_radius_(s.lens_radius),
      focal_distance_(s.focal_distance),
      width_(r.full_width),
      height_(r.full_height),
      crop_x0_(float(r.x0)),
      crop_y0_(float(r.y0)),
      crop_width_(float(r.width)),
      crop_height_(float(r.height)),
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
  // Rigid (a mirror allowed): solid angles in camera space are the world's.
  const Vec3 ax = world_from_camera_.vector(Vec3(1, 0, 0)),
             ay = world_from_camera_.vector(Vec3(0, 1, 0)),
             az = world_from_camera_.vector(Vec3(0, 0, 1));
  const bool rigid = std::fabs(length(ax) - 1) < 1e-4f && std::fabs(length(ay) - 1) < 1e-4f &&
                     std::fabs(length(az) - 1) < 1e-4f && std::fabs(dot(ax, ay)) < 1e-4f &&
                     std::fabs(dot(ay, az)) < 1e-4f && std::fabs(dot(az, ax)) < 1e-4f;
  projects_ = projection_ == Projection::kPerspective && lens_radius_ == 0 && rigid;
}

std::optional<Camera::ProjectedPoint> Camera::project(Vec3 p, float margin) const {
  if (!projects_) return std::nullopt;
  const Vec3 c = camera_from_world_.point(p);
  if (!(c.z > 0)) return std::nullopt;
  // The point on the plane z = 1, and the screen coordinates generate_ray_full inverts.
  const float qx = c.x / c.z, qy = c.y / c.z;
  const float sx = qx / tan_half_, sy = qy / tan_half_;
  const Vec2 full{(sx - x0_) / (x1_ - x0_) * float(width_),
                  (y1_ - sy) / (y1_ - y0_) * float(height_)};
  const Vec2 raster{full.x - crop_x0_, full.y - crop_y0_};
  if (!(raster.x > -margin && raster.y > -margin && raster.x < crop_width_ + margin &&
        raster.y < crop_height_ + margin))
    return std::nullopt;
  // A pixel is dx tan_half by dy tan_half on the plane z = 1 (pixel_angle_ squared), and a patch
  // of the plane at q subtends its area times cos^3 of the angle to the axis: 1 / |q|^3.
  const float q2 = 1 + qx * qx + qy * qy;
  const float per_solid_angle = q2 * std::sqrt(q2) / (pixel_angle_ * pixel_angle_);
  return ProjectedPoint{raster, per_solid_angle, world_from_camera_.point(Vec3(0, 0, 0))};
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
