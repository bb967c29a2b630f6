// Rays and pixel footprints of the orthographic and spherical cameras.
#include "camera/camera.h"

#include <gtest/gtest.h>

#include <cmath>

#include "base/rng.h"

namespace bpm {
namespace {

CameraSettings settings(Projection p) {
  CameraSettings s;
  s.projection = p;
  return s;
}

// Default screen window of a 40 x 30 raster: x in [-4/3, 4/3], y in [-1, 1]; a pixel is 1/15 wide.
TEST(Camera, OrthographicRaysAreParallelAndOnePixelApart) {
  const Camera camera(settings(Projection::kOrthographic), 40, 30);
  const Ray a = camera.generate_ray({0.5f, 0.5f}, {0.5f, 0.5f}).ray;
  const Ray b = camera.generate_ray({1.5f, 0.5f}, {0.5f, 0.5f}).ray;
  const Ray c = camera.generate_ray({0.5f, 1.5f}, {0.5f, 0.5f}).ray;
  for (const Ray& r : {a, b, c}) {
    EXPECT_FLOAT_EQ(r.d.z, 1);
    EXPECT_FLOAT_EQ(r.o.z, 0);
  }
  EXPECT_NEAR(b.o.x - a.o.x, 1.0f / 15, 1e-6f);
  EXPECT_NEAR(a.o.y - c.o.y, 1.0f / 15, 1e-6f);  // raster y grows downward
  EXPECT_NEAR(a.o.x, -4.0f / 3 + 0.5f / 15, 1e-6f);
  const PixelFootprint f = camera.footprint({3, 4});
  EXPECT_NEAR(f.width, 1.0f / 15, 1e-6f);
  EXPECT_EQ(f.spread, 0);
  EXPECT_NEAR(camera.footprint_at(Vec3(0.3f, 0.2f, 7)), 1.0f / 15, 1e-6f);
}

// pbrt-v4's layout: longitude across (the left edge looks down +x, a quarter across down +z),
// latitude down from +y; the rows' solid angles add up to the sphere.
TEST(Camera, EquirectangularDirectionsAndSolidAngles) {
  constexpr int kW = 64, kH = 32;
  const Camera camera(settings(Projection::kSphericalEquirectangular), kW, kH);
  auto dir = [&](float x, float y) { return camera.generate_ray({x, y}, {}).ray.d; };
  const Vec3 x = dir(0, kH / 2.0f), z = dir(kW / 4.0f, kH / 2.0f), up = dir(5, 0);
  EXPECT_NEAR(x.x, 1, 1e-5f);
  EXPECT_NEAR(z.z, 1, 1e-5f);
  EXPECT_NEAR(up.y, 1, 1e-5f);
  double total = 0;
  for (int row = 0; row < kH; ++row) {
    const float spread = camera.footprint({0, row + 0.5f}).spread;
    total += double(kW) * spread * spread;
    // Seen directly, a point of that row at distance 3 has a footprint spread * 3.
    const Vec3 d = dir(7.5f, row + 0.5f);
    EXPECT_NEAR(camera.footprint_at(d * 3), 3 * spread, 1e-4f) << "row " << row;
  }
  EXPECT_NEAR(total, 4 * M_PI, 1e-3);
}

// Equal areas of the raster are equal solid angles: uniform raster points give uniform directions
// (each band of height h holds h / 2 of them); points just across an edge of the raster see
// about the same direction as those just inside (the octahedral map continues across it).
TEST(Camera, EqualAreaPixelsSubtendEqualSolidAngles) {
  constexpr int kW = 40, kH = 40, kN = 200000;
  const Camera camera(settings(Projection::kSphericalEqualArea), kW, kH);
  EXPECT_NEAR(double(kW) * kH * std::pow(camera.footprint({1, 1}).spread, 2), 4 * M_PI, 1e-4);
  Rng rng(7);
  int bands[4] = {0, 0, 0, 0};
  for (int i = 0; i < kN; ++i) {
    const Vec3 d = camera.generate_ray({rng.uniform() * kW, rng.uniform() * kH}, {}).ray.d;
    bands[std::min(3, int((d.y + 1) * 2))]++;
  }
  for (int b = 0; b < 4; ++b) {
    // Binomial, p = 1/4: sigma = sqrt(N p (1 - p)) ~ 194.
    EXPECT_NEAR(bands[b], kN / 4, 5 * 194) << "band " << b;
  }
  for (float t : {3.3f, 17.0f, 31.9f}) {
    const Vec3 a = camera.generate_ray({-0.01f, t}, {}).ray.d,
               b = camera.generate_ray({0.01f, t}, {}).ray.d;
    const Vec3 c = camera.generate_ray({t, kH + 0.01f}, {}).ray.d,
               e = camera.generate_ray({t, kH - 0.01f}, {}).ray.d;
    EXPECT_LT(length(a - b), 0.01f) << t;
    EXPECT_LT(length(c - e), 0.01f) << t;
  }
}

// A pinhole perspective camera (mirrored, turned and moved, a crop of a larger raster) projects
// points along its rays back to the raster positions they came from, with the pixel area per
// solid angle that neighbouring rays span; a lens, or a point behind it, does not project.
TEST(Camera, PerspectiveProjectionInvertsTheRaysAndTheirSolidAngles) {
  CameraSettings s = settings(Projection::kPerspective);
  s.fov_degrees = 50;
  s.world_from_camera = Transform::translate(Vec3(0.5f, -1, 2)) *
                        Transform::rotate(30, normalize(Vec3(1, 2, 0.5f))) *
                        Transform::scale(Vec3(-1, 1, 1));
  const Raster raster{30, 20, 64, 48, 10, 7};
  const Camera camera(s, raster);
  ASSERT_TRUE(camera.projects());
  Rng rng(41);
  for (int q = 0; q < 50; ++q) {
    const Vec2 u{rng.uniform() * 30, rng.uniform() * 20};
    const Ray r = camera.generate_ray(u, {0.5f, 0.5f}).ray;
    const auto p = camera.project(r.o + r.d * (0.5f + 5 * rng.uniform()), 0);
    ASSERT_TRUE(p);
    EXPECT_NEAR(p->raster.x, u.x, 2e-3f);
    EXPECT_NEAR(p->raster.y, u.y, 2e-3f);
    EXPECT_NEAR(length(p->pinhole - r.o), 0, 1e-5f);
    // The solid angle of the rays through a small square about u (two triangles of directions).
    const float h = 0.05f;
    auto dir = [&](float dx, float dy) {
      return camera.generate_ray({u.x + dx, u.y + dy}, {0.5f, 0.5f}).ray.d;
    };
    const Vec3 a = dir(-h, -h), b = dir(h, -h), c = dir(h, h), d = dir(-h, h);
    const double omega = 0.5 * (length(cross(b - a, c - a)) + length(cross(c - a, d - a)));
    EXPECT_NEAR(p->pixels_per_solid_angle * omega / (4 * h * h), 1.0, 1e-2);
  }
  const Ray centre = camera.generate_ray({15, 10}, {0.5f, 0.5f}).ray;
  EXPECT_FALSE(camera.project(centre.o - centre.d, 0));  // behind
  EXPECT_FALSE(camera.project(camera.generate_ray({-3, 10}, {0.5f, 0.5f}).ray.o +
                                  camera.generate_ray({-3, 10}, {0.5f, 0.5f}).ray.d,
                              2));  // 3 pixels off with a margin of 2
  EXPECT_TRUE(camera.project(camera.generate_ray({-1, 10}, {0.5f, 0.5f}).ray.o +
                                 camera.generate_ray({-1, 10}, {0.5f, 0.5f}).ray.d,
                             2));
  s.lens_radius = 0.01f;
  EXPECT_FALSE(Camera(s, raster).project(centre.o + centre.d, 0));
}

}  // namespace
}  // namespace bpm
