// The emission guide draws cells with the probabilities it claims, and its weights keep photon
// estimates unbiased whatever it has learnt.
#include "photons/emission_guide.h"

#include <gtest/gtest.h>

#include <cmath>

#include "scene/flatten.h"
#include "scene/parsed_scene.h"

namespace bpm {
namespace {

// A point light and a quad area light (two triangles: two lights) of different power.
LoadedScene two_kinds_of_light() {
  return flatten_scene(parse_scene_string(
      "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\"\nFilm \"rgb\" \"integer xresolution\" 8 "
      "\"integer yresolution\" 8\nWorldBegin\n"
      "LightSource \"point\" \"rgb I\" [5 5 5] \"point3 from\" [0 2 0]\n"
      "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [3 3 3]\n"
      "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [-1 3 -1  1 3 -1  1 3 "
      "1 "
      " -1 3 1]\nAttributeEnd\n"
      "Shape \"sphere\" \"float radius\" 0.5\n"));
}

// A region of primary sample space: light 1 (a triangle of the area light) with u_dir.x < 0.25.
bool in_region(const EmissionDraw& e) { return e.light == 1 && e.u_dir.x < 0.25f; }

TEST(EmissionGuide, LearntDensityIsDrawnAndWeightedWithoutBias) {
  LoadedScene ls = two_kinds_of_light();
  ASSERT_EQ(ls.scene.lights.size(), 3u);
  EmissionGuide guide(ls.scene);
  ASSERT_FALSE(guide.empty());
  const float p_light1 = ls.scene.light_distribution.pmf(1);

  // Before learning the guide is the unguided density: weights 1, lights by power.
  Rng rng(stream_key(11, 0));
  const int n = 200000;
  int region = 0;
  std::vector<CellScore> scores;
  for (int k = 0; k < n; ++k) {
    EmissionDraw e = guide.sample(rng);
    ASSERT_NEAR(e.weight, 1.0f, 1e-5f);
    ASSERT_NEAR(e.light_pmf, ls.scene.light_distribution.pmf(e.light), 1e-6f);
    region += in_region(e);
    // Photons in the region score; all others score nothing.
    scores.push_back({e.cell, in_region(e) ? 1.0f : 0.0f});
  }
  const double p_region = p_light1 * 0.25;
  EXPECT_NEAR(region, n * p_region, 4.5 * std::sqrt(n * p_region * (1 - p_region)));
  guide.learn(scores);
  guide.update();
  EXPECT_NEAR(guide.moved(), 0.5 * (1 - p_region), 1e-3);

  // After learning half the photons go to the region, and weighting by unguided / guided
  // probability gives the unguided expectation of any function of the draw.
  region = 0;
  double sum = 0, sum2 = 0, expected = 0;
  for (int li = 0; li < 3; ++li)
    expected += ls.scene.light_distribution.pmf(li) * (li + 1) * (0.5 * 0.5);  // E[u_pos.y u_dir.x]
  for (int k = 0; k < n; ++k) {
    EmissionDraw e = guide.sample(rng);
    ASSERT_GT(e.weight, 0.0f);
    ASSERT_LE(e.weight, 2.0f + 1e-5f);
    ASSERT_NEAR(e.light_pmf, ls.scene.light_distribution.pmf(e.light), 1e-6f);
    region += in_region(e);
    double f = (e.light + 1) * e.u_pos.y * e.u_dir.x * e.weight;
    sum += f;
    sum2 += f * f;
  }
  const double p_guided = 0.5 * p_region + 0.5;
  EXPECT_NEAR(region, n * p_guided, 4.5 * std::sqrt(n * p_guided * (1 - p_guided)));
  const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
  EXPECT_NEAR(mean, expected, 4.5 * se);
}

TEST(EmissionGuide, SceneWithoutLightsHasNoCells) {
  LoadedScene ls = flatten_scene(parse_scene_string(
      "Camera \"perspective\"\nWorldBegin\nShape \"sphere\" \"float radius\" 1\n"));
  EXPECT_TRUE(EmissionGuide(ls.scene).empty());
}

}  // namespace
}  // namespace bpm
