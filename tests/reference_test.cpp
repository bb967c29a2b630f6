// bpm's path integrator against pbrt-v4 renders of the same scene files (../shared/references).
// Skipped when ../shared is absent (a user's clone has none).
#include <cmath>

#include "film/image_io.h"
#include "test_util.h"

namespace bpm {
namespace {

struct Moments {
  double mean[3] = {0, 0, 0};
};

Moments channel_means(const Image& img) {
  Moments m;
  size_t n = size_t(img.width) * img.height;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) m.mean[c] += img.rgb[3 * i + c];
  for (double& v : m.mean) v /= n;
  return m;
}

// The metric of ../shared/references/README.md.
double rel_mse(const Image& a, const Image& b) {
  double s = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    double d = a.rgb[i] - b.rgb[i];
    s += d * d / (double(b.rgb[i]) * b.rgb[i] + 0.01);
  }
  return s / a.rgb.size();
}

struct Case {
  const char* scene;
  const char* reference;
  int width, height, spp;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.scene; }

class Reference : public ::testing::TestWithParam<Case> {};

TEST_P(Reference, MatchesPbrtV4) {
  std::string shared = test::shared_dir();
  if (shared.empty()) GTEST_SKIP() << "../shared is absent: no pbrt-v4 references to compare with";
  const Case& c = GetParam();
  LoadedScene ls = flatten_scene(parse_scene_file(shared + "/scenes/" + c.scene));
  ls.film.width = c.width;
  ls.film.height = c.height;
  Film fa = test::render_film(ls, c.spp, 0, 101);
  Film fb = test::render_film(ls, c.spp, 0, 202);
  Image a = fa.image(ls.film.imaging_ratio), b = fb.image(ls.film.imaging_ratio);
  Image ref = read_exr(shared + "/references/" + c.reference);
  ASSERT_EQ(ref.width, c.width);
  ASSERT_EQ(ref.height, c.height);

  Moments ma = channel_means(a), mb = channel_means(b), mr = channel_means(ref);
  for (int ch = 0; ch < 3; ++ch) {
    // The spread of our two independent means bounds the noise in the comparison.
    double noise = std::fabs(ma.mean[ch] - mb.mean[ch]);
    double diff = std::fabs(0.5 * (ma.mean[ch] + mb.mean[ch]) / mr.mean[ch] - 1);
    std::printf("%s channel %d: bpm/pbrt-v4 - 1 = %+.4f (noise %.4f)\n", c.scene, ch,
                0.5 * (ma.mean[ch] + mb.mean[ch]) / mr.mean[ch] - 1, noise / mr.mean[ch]);
    // Every channel within 3% (both renderers transport spectra, so saturated interreflections
    // agree too).
    EXPECT_LT(diff, 0.03 + 3 * noise / mr.mean[ch]) << "channel " << ch;
  }
  // What remains per pixel is noise: our render differs from pbrt-v4's (whose own noise is
  // negligible at 2048 spp) no more than from another render of ours. E[relMSE(a, ref)] is
  // sigma^2 + bias^2 and E[relMSE(a, b)] is 2 sigma^2, so this fails once bias^2 ~ sigma^2.
  double to_ref = rel_mse(a, ref), to_ours = rel_mse(a, b);
  std::printf("%s relMSE to pbrt-v4 %.5f, to an independent bpm render %.5f\n", c.scene, to_ref, to_ours);
  EXPECT_LT(to_ref, to_ours);
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, Reference,
    ::testing::Values(Case{"cornell-box/scene-v4.pbrt", "cornell-box-path-256x256-2048spp.exr", 256, 256, 32},
                      Case{"veach-mis/scene-v4.pbrt", "veach-mis-path-320x180-2048spp.exr", 320, 180, 32}),
    [](const auto& info) { return std::string(info.index == 0 ? "CornellBox" : "VeachMis"); });

}  // namespace
}  // namespace bpm
