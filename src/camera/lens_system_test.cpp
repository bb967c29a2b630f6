// The realistic camera's lens system against closed forms: the irradiance a stop passes, the
// plane it focuses, the angle of a pixel, the orientation of the image.
#include "camera/lens_system.h"

#include <gtest/gtest.h>

#include <cmath>

#include "base/error.h"
#include "base/rng.h"

namespace bpm {
namespace {

// lens-file rows in mm: curvature radius, thickness, index, aperture diameter.
std::vector<LensInterface> lens(std::initializer_list<std::array<float, 4>> rows) {
  std::vector<LensInterface> out;
  for (const auto& r : rows) out.push_back({r[0] / 1000, r[1] / 1000, r[2], r[3] / 2000});
  return out;
}

// A biconvex singlet 5 mm behind a front stop of radius `stop_mm` (f about 51 mm).
LensSettings front_stop_singlet(float stop_mm, float focus) {
  LensSettings s;
  s.interfaces = lens({{0, 5, 0, 2 * stop_mm}, {51.68f, 6, 1.5168f, 24}, {-51.68f, 45, 1, 24}});
  s.focus_distance = focus;
  return s;
}

// The same glass with the stop behind it, nearest the film: the stop is then its own exit pupil.
LensSettings rear_stop_singlet(float stop_mm) {
  LensSettings s;
  s.interfaces = lens({{60, 5, 1.5168f, 30}, {-60, 5, 1, 30}, {0, 45, 0, 2 * stop_mm}});
  return s;
}

struct MeanWeight {
  double mean, sigma;
};
MeanWeight mean_weight(const LensSystem& lens, Vec2 film, int n) {
  Rng rng(7);
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    const double w = lens.generate(film, {rng.uniform(), rng.uniform()}).weight;
    sum += w, sum2 += w * w;
  }
  const double mean = sum / n;
  return {mean, std::sqrt((sum2 / n - mean * mean) / n)};
}

// Light of radiance 1 from every direction gives the film centre the projected solid angle of the
// exit pupil: pi a^2 / (a^2 + z^2) for a stop of radius a at distance z. The camera ray's weight is
// that irradiance's estimate.
TEST(LensSystem, MeanWeightAtTheFilmCentreIsTheStopsProjectedSolidAngle) {
  for (float a_mm : {2.0f, 5.0f}) {
    const LensSystem lens(rear_stop_singlet(a_mm), 64, 64);
    const double a = a_mm / 1000.0, z = lens.rear_z();
    const double expected = kPi * a * a / (a * a + z * z);
    const MeanWeight m = mean_weight(lens, {0.5f, 0.5f}, 200000);
    EXPECT_NEAR(m.mean, expected, 5 * m.sigma) << a_mm << " mm, z " << z;
    EXPECT_LT(m.sigma, 0.003 * expected);
  }
}

// A diaphragm shape is scaled to pass what a circular stop does (pbrt-v4's normalisation): with a
// stop small against its distance, the centre's irradiance is the circle's whatever the shape.
TEST(LensSystem, ApertureShapesPassTheLightOfACircle) {
  LensSettings s = rear_stop_singlet(1);
  const int n = 64;
  s.aperture = ApertureMask{n, n, std::vector<float>(size_t(n) * n, 0)};
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)  // a square of half the stop's width: pi over (1/2)^2 of the area
      if (i >= n / 4 && i < 3 * n / 4 && j >= n / 4 && j < 3 * n / 4)
        s.aperture.values[size_t(j) * n + size_t(i)] = kPi;
  const LensSystem square(s, 64, 64), circle(rear_stop_singlet(1), 64, 64);
  const MeanWeight a = mean_weight(square, {0.5f, 0.5f}, 200000),
                   b = mean_weight(circle, {0.5f, 0.5f}, 200000);
  EXPECT_NEAR(a.mean, b.mean, 5 * std::hypot(a.sigma, b.sigma) + 1e-3 * b.mean);
}

// Rays from the film centre meet the axis again at the focus distance (the thick-lens focusing is
// paraxial; a stop of 0.25 mm keeps the singlet's spherical aberration, which grows with the
// square of the ray's height, below the tolerance: at a radius of 1 mm, rays meet 2% short of
// 2.5 m).
TEST(LensSystem, RaysFromTheFilmCentreMeetAtTheFocusDistance) {
  for (float focus : {1.0f, 2.5f, 10.0f}) {
    const LensSystem lens(front_stop_singlet(0.25f, focus), 64, 64);
    Rng rng(3);
    int traced = 0;
    for (int i = 0; i < 64; ++i) {
      const CameraRay r = lens.generate({0.5f, 0.5f}, {rng.uniform(), rng.uniform()});
      if (r.weight == 0) continue;
      ++traced;
      const Vec3 o = r.ray.o, d = r.ray.d;
      const float t = -(o.x * d.x + o.y * d.y) / (d.x * d.x + d.y * d.y);
      EXPECT_NEAR(o.z + t * d.z, focus, 0.01f * focus) << "focus " << focus;
    }
    EXPECT_GT(traced, 32);
  }
}

// Focused far away, a pixel subtends its width over the focal length; the image is upside down
// on the film, so the raster's left and top see the scene's left (-x) and top (+y).
TEST(LensSystem, PixelAngleAndImageOrientation) {
  const LensSystem lens(front_stop_singlet(4, 1000), 320, 240);
  const float pitch = 0.035f * 0.8f / 320;  // a 4:3 film of 35 mm diagonal is 28 mm wide
  EXPECT_NEAR(lens.pixel_spread() * lens.effective_focal_length(), pitch, 0.02f * pitch);
  EXPECT_NEAR(lens.effective_focal_length(), 0.051f, 0.002f);
  const CameraRay left = lens.generate({0.1f, 0.5f}, {0.5f, 0.5f}),
                  top = lens.generate({0.5f, 0.1f}, {0.5f, 0.5f});
  ASSERT_GT(left.weight, 0);
  ASSERT_GT(top.weight, 0);
  EXPECT_LT(left.ray.d.x, -0.1f);
  EXPECT_NEAR(left.ray.d.y, 0, 1e-4f);
  EXPECT_GT(top.ray.d.y, 0.1f);
  EXPECT_GT(left.ray.o.z, 0.05f);  // rays leave from the front of the lens
}

TEST(LensSystem, FocusingCloserThanTheFocalLengthIsAnError) {
  EXPECT_THROW(LensSystem(front_stop_singlet(4, 0.03f), 64, 64), Error);
}

TEST(ApertureMask, BilinearBetweenTexelCentresAndBlackOutside) {
  const ApertureMask m{2, 1, {1, 3}};
  EXPECT_FLOAT_EQ(m.at(0.25f, 0.5f), 1);
  EXPECT_FLOAT_EQ(m.at(0.5f, 0.5f), 2);
  EXPECT_FLOAT_EQ(m.at(0.75f, 0.5f), 3);
  EXPECT_FLOAT_EQ(m.at(0.75f, 1.0f), 1.5f);  // half way to the black beyond the top row
  EXPECT_FLOAT_EQ(m.at(1.5f, 0.5f), 0);
}

}  // namespace
}  // namespace bpm
