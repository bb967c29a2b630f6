// Curves: pbrt-v4's conversions to cubic Bezier segments, the surface frame of each curve type
// against its closed form, and Embree's intersection of a straight curve against its width.
#include "scene/curves.h"

#include <gtest/gtest.h>

#include <cmath>

#include "scene/render_scene.h"
#include "scene/shapes.h"

namespace bpm {
namespace {

Vec3 bezier(const Vec3 p[4], float u) {
  const float s = 1 - u;
  return p[0] * (s * s * s) + p[1] * (3 * s * s * u) + p[2] * (3 * s * u * u) + p[3] * (u * u * u);
}

void expect_near(Vec3 a, Vec3 b, float eps, const char* what) {
  EXPECT_NEAR(a.x, b.x, eps) << what;
  EXPECT_NEAR(a.y, b.y, eps) << what;
  EXPECT_NEAR(a.z, b.z, eps) << what;
}

// The cubic from a quadratic Bezier traces the same points; a uniform B-spline segment's cubic
// Bezier traces the spline's basis functions (checked at the ends and the middle).
TEST(Curves, ConversionsToCubicBezierKeepTheCurve) {
  const Vec3 q[3] = {{0, 0, 0}, {1, 2, 0}, {2, 0, 1}};
  Vec3 c[4];
  elevate_quadratic_bezier(q, c);
  for (float u : {0.0f, 0.3f, 0.5f, 1.0f}) {
    const float s = 1 - u;
    expect_near(bezier(c, u), q[0] * (s * s) + q[1] * (2 * s * u) + q[2] * (u * u), 1e-5f,
                "quadratic");
  }
  const Vec3 b[4] = {{0, 0, 0}, {1, 3, 0}, {2, -1, 1}, {4, 0, 2}};
  cubic_bspline_to_bezier(b, c);
  expect_near(bezier(c, 0), (b[0] + b[1] * 4 + b[2]) / 6, 1e-5f, "B-spline start");
  expect_near(bezier(c, 1), (b[1] + b[2] * 4 + b[3]) / 6, 1e-5f, "B-spline end");
  expect_near(bezier(c, 0.5f), (b[0] + b[1] * 23 + b[2] * 23 + b[3]) / 48, 1e-5f,
              "B-spline middle");
  quadratic_bspline_to_bezier(b, c);
  expect_near(bezier(c, 0), (b[0] + b[1]) / 2, 1e-5f, "quadratic B-spline start");
  expect_near(bezier(c, 0.5f), (b[0] + b[1] * 6 + b[2]) / 8, 1e-5f, "quadratic B-spline middle");
}

// A straight curve along +x of radius 0.1, seen down +z.
Curves straight(Curves::Type type) {
  Curves c;
  c.type = type;
  c.first = {0};
  for (int k = 0; k < 4; ++k) c.control.insert(c.control.end(), {-1 + 2 * k / 3.0f, 0, 0, 0.1f});
  if (type == Curves::Type::kRibbon) {
    c.end_normals = {normalize(Vec3(0, 1, -1)), normalize(Vec3(0, 1, -1))};
    c.control_normals.assign(5, c.end_normals[0]);
  }
  return c;
}

// pbrt-v4's frames: a flat curve's normal lies along the ray (perpendicular to the tangent); a
// cylinder's turns by 90 degrees times (2v - 1) about the tangent, away from the ray at v = 1/2
// and across it at the edges; a ribbon's is its given normal. v runs across the width.
TEST(Curves, SurfaceFrameOfEachType) {
  const Vec3 d(0, 0, 1);
  for (float offset : {-0.09f, -0.05f, 0.0f, 0.05f, 0.09f}) {
    const Vec3 p(0.2f, offset, 0);
    const float v = 0.5f + offset / 0.2f;
    const SurfacePoint flat = curve_point(straight(Curves::Type::kFlat), 0, 0.6f, p, d);
    expect_near(flat.ng, Vec3(0, 0, 1), 1e-5f, "flat");
    EXPECT_NEAR(flat.uv.x, 0.6f, 1e-6f);
    EXPECT_NEAR(flat.uv.y, v, 1e-5f);
    const SurfacePoint cyl = curve_point(straight(Curves::Type::kCylinder), 0, 0.6f, p, d);
    const float theta = kPi * (v - 0.5f);  // n = cos(theta) (along the ray) + sin(theta) (across)
    expect_near(cyl.ng, Vec3(0, std::sin(theta), std::cos(theta)), 1e-5f, "cylinder");
    expect_near(cyl.ns, cyl.ng, 0, "cylinder shading");
    const SurfacePoint rib = curve_point(straight(Curves::Type::kRibbon), 0, 0.6f, p, d);
    EXPECT_NEAR(std::fabs(dot(rib.ng, normalize(Vec3(0, 1, -1)))), 1, 1e-5f);
  }
  Curves flipped = straight(Curves::Type::kFlat);
  flipped.flip_normal = true;
  expect_near(curve_point(flipped, 0, 0.5f, Vec3(0, 0, 0), d).ng, Vec3(0, 0, -1), 1e-6f, "flip");
  // Lifted off by its width times |n|_1, as pbrt-v4's error bound lifts rays.
  EXPECT_NEAR(curve_point(straight(Curves::Type::kFlat), 0, 0.5f, Vec3(0, 0, 0), d).error, 0.2f,
              1e-6f);
}

// Embree's flat curve is as wide as the radius says, from any side; a ribbon seen edge-on
// narrows by the cosine between its normal and the ray.
TEST(Curves, EmbreeFindsTheCurveWithinItsWidth) {
  for (Curves::Type type : {Curves::Type::kFlat, Curves::Type::kRibbon}) {
    RenderScene scene;
    Object obj;
    obj.shape = straight(type);
    scene.objects.push_back(obj);
    scene.materials.push_back(MaterialDesc{});
    scene.commit();
    for (float angle : {0.0f, 20.0f, 75.0f}) {
      const float a = angle * kPi / 180;
      const Vec3 d(0, std::sin(a), std::cos(a));  // turning about the curve's axis
      const Vec3 across(0, std::cos(a), -std::sin(a));
      // A ribbon of normal (0, 1, -1)/sqrt 2 spans 0.1 |cos| to either side.
      const float half =
          type == Curves::Type::kFlat ? 0.1f : 0.1f * std::fabs(dot(d, normalize(Vec3(0, 1, -1))));
      for (float s : {0.0f, 0.9f, 1.1f}) {
        const Vec3 o = across * (s * half) - d * 3.0f + Vec3(0.3f, 0, 0);
        Hit h;
        const bool hit = scene.intersect(Ray{o, d, kInf}, &h);
        EXPECT_EQ(hit, s < 1) << int(type) << " angle " << angle << " offset " << s;
        if (hit) {
          EXPECT_NEAR(h.barycentric.x, (0.3f + 1) / 2, 0.02f);
        }
      }
    }
  }
}

}  // namespace
}  // namespace bpm
