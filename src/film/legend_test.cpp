#include "film/legend.h"

#include <gtest/gtest.h>

#include <cmath>

namespace bpm {
namespace {

float brightness(Rgb c) { return c[0] + c[1] + c[2]; }

TEST(Legend, LogScaleSpansWholeDecadesAroundTheValues) {
  std::vector<float> v;
  for (int i = 0; i < 1000; ++i) v.push_back(0.03f + 0.3f * float(i) / 1000);  // 0.03 .. 0.33
  v.push_back(0);  // black pixels do not widen the scale
  const ColourScale s = log_scale(v, "luminance");
  EXPECT_TRUE(s.log);
  EXPECT_NEAR(s.lo, 0.01, 1e-12);
  EXPECT_NEAR(s.hi, 1, 1e-12);
  // At most six decades under the top, at least one.
  EXPECT_NEAR(log_scale({1e-9f, 5.0f, 6.0f}, "").lo, 1e-5, 1e-17);
  EXPECT_NEAR(log_scale({5.0f}, "").lo, 1, 1e-12);
}

TEST(Legend, LinearScaleEndsAtARoundNumber) {
  EXPECT_EQ(linear_scale({0.5f, 3.2f}, "").hi, 5);
  EXPECT_EQ(linear_scale({1.9f}, "").hi, 2);
  EXPECT_EQ(linear_scale({230}, "").hi, 250);
  EXPECT_EQ(linear_scale({1000}, "").hi, 1000);
  EXPECT_EQ(linear_scale({0.0f}, "").lo, 0);
}

TEST(Legend, HeatRampGrowsBrighterAlongTheScale) {
  ColourScale s;
  s.lo = 0;
  s.hi = 1;
  float last = -1;
  for (int k = 0; k <= 20; ++k) {
    const float b = brightness(s.colour(k / 20.0));
    EXPECT_GT(b, last) << k;
    last = b;
  }
  EXPECT_EQ(brightness(s.colour(-1)), 0);  // below the scale: its first colour
  EXPECT_EQ(brightness(s.colour(2)), 3);   // above: its last (white)
}

// The picture holds the values, then the legend; its title is drawn in black (the text module
// and a font are there, as scripts/install-deps.sh installs them).
TEST(Legend, PictureHasTheValuesAndALegendWithText) {
  const std::vector<float> values{0, 0.5f, 1, 0.25f};
  ColourScale s;
  s.title = "illuminance, lux, linear scale";
  std::string warning;
  const Image img = false_colour_picture({{&values, 2, 2, 10, false}}, s, &warning);
  EXPECT_EQ(warning, "");
  EXPECT_EQ(img.width, 360);
  EXPECT_GT(img.height, 20);
  EXPECT_EQ(brightness(img.at(5, 5)), brightness(s.colour(0)));       // value 0, black
  EXPECT_EQ(brightness(img.at(15, 15)), brightness(s.colour(0.25)));  // row 1, column 1
  int dark = 0;
  for (int y = 28; y < 28 + 18; ++y)
    for (int x = 10; x < 200; ++x) dark += brightness(img.at(x, y)) < 1.5f;
  EXPECT_GT(dark, 20) << "the legend's title was not drawn";
}

}  // namespace
}  // namespace bpm
