// pbrt-v4's cameras: perspective, orthographic, spherical and realistic (a lens system,
// camera/lens_system.h). Raster y grows downward, and camera space looks down +z with +x to the
// right of the image (the spherical cameras: +y is up; the equirectangular image's left edge looks
// down +x, a quarter across down +z).
#pragma once
#include <memory>
#include <optional>

#include "base/ray.h"
#include "base/transform.h"
#include "camera/lens_system.h"

namespace bpm {

enum class Projection {
  kPerspective,
  kOrthographic,
  kSphericalEqualArea,        // pbrt-v4's default "spherical" mapping: an octahedral map
  kSphericalEquirectangular,  // latitude (rows) and longitude (columns)
  kRealistic
};

struct CameraSettings {
  Transform world_from_camera;
  Projection projection = Projection::kPerspective;
  float fov_degrees = 90;
  float lens_radius = 0;
  float focal_distance = 1e6f;
  float frame_aspect_ratio = 0;            // 0: the raster's
  float screen_window[4] = {0, 0, 0, 0};   // x0 x1 y0 y1; all zero means pbrt-v4's default
  std::shared_ptr<const LensSystem> lens;  // realistic: focused for the film's full raster
  int medium = -1;                         // the scene medium the camera sits in (-1: none)
};

// The pixels a camera renders: width x height of its full_width x full_height raster, from pixel
// (x0, y0) (a crop: pbrt-v4's "cropwindow" and "pixelbounds").
struct Raster {
  int width = 0, height = 0, full_width = 0, full_height = 0, x0 = 0, y0 = 0;
};

// The footprint of one pixel along its camera ray: `width` across at the camera, growing by
// `spread` per unit of distance (a pinhole's pixel has no width and spreads by its angle, an
// orthographic one keeps its width). A flat specular surface keeps the pencil growing the same,
// so at eye path length l the footprint is width + spread * l (world units).
struct PixelFootprint {
  float width = 0, spread = 0;
  float at(float length) const { return width + spread * length; }
};

class Camera {
 public:
  Camera(const CameraSettings& s, const Raster& raster);
  Camera(const CameraSettings& s, int width, int height)
      : Camera(s, Raster{width, height, width, height, 0, 0}) {}
  // p_raster in pixels of the image rendered ((0,0) is the top-left corner of the crop); u_lens in
  // [0,1)^2.
  // Every camera but the realistic one gives rays of weight 1.
  CameraRay generate_ray(Vec2 p_raster, Vec2 u_lens) const {
    return generate_ray_full({p_raster.x + crop_x0_, p_raster.y + crop_y0_}, u_lens);
  }
  // The same with p in pixels of the full raster.
  CameraRay generate_ray_full(Vec2 p_full, Vec2 u_lens) const;
  // The footprint of the pixel about p_full (pixels of the full raster). Perspective and
  // realistic: the angle the image centre's pixel subtends, for every pixel (lens ignored).
  PixelFootprint footprint(Vec2 p_full) const;
  // The width of a pixel's footprint at world point p seen directly.
  float footprint_at(Vec3 p) const;
  // Where world point p lands on a pinhole perspective camera's image: its position in pixels of
  // the image rendered (the crop's), the image's area in square pixels per unit of solid angle
  // about the ray to p (du/domega), and the pinhole. Nothing for the other cameras (a lens, a
  // non-rigid camera transform included), behind the camera, or more than `margin` pixels off the
  // image (light tracing to the camera, bpm/camera_connections.h).
  struct ProjectedPoint {
    Vec2 raster;
    float pixels_per_solid_angle;
    Vec3 pinhole;
  };
  std::optional<ProjectedPoint> project(Vec3 p, float margin) const;
  bool projects() const { return projects_; }
  Projection projection() const { return projection_; }
  int medium() const { return medium_; }  // the scene medium the camera sits in (-1: none)

 private:
  Vec3 camera_direction(Vec2 p_full) const;  // spherical cameras
  Transform world_from_camera_, camera_from_world_;
  Projection projection_;
  float lens_radius_, focal_distance_;
  float x0_, x1_, y0_, y1_;  // screen window
  float tan_half_;
  int width_, height_;  // the full raster
  float crop_x0_, crop_y0_, crop_width_, crop_height_;
  bool projects_ = false;  // project() applies: a pinhole perspective camera, rigid transform
  float pixel_angle_ = 0;  // sqrt of the pixel's solid angle (perspective, equal-area)
  float pixel_width_ = 0;  // sqrt of the pixel's area in world units (orthographic)
  std::shared_ptr<const LensSystem> lens_;
  int medium_;
};

}  // namespace bpm
