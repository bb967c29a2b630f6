// bpm's path integrator against pbrt-v4 renders of the same scene files (../shared/references).
// Skipped when ../shared is absent (a user's clone has none).
#include <cmath>

#include "film/image_compare.h"
#include "film/image_io.h"
#include "test_util.h"

namespace bpm {
namespace {

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

  auto ma = channel_means(a), mb = channel_means(b), mr = channel_means(ref);
  for (int ch = 0; ch < 3; ++ch) {
    // The spread of our two independent means bounds the noise in the comparison.
    double noise = std::fabs(ma[ch] - mb[ch]);
    double diff = std::fabs(0.5 * (ma[ch] + mb[ch]) / mr[ch] - 1);
    std::printf("%s channel %d: bpm/pbrt-v4 - 1 = %+.4f (noise %.4f)\n", c.scene, ch,
                0.5 * (ma[ch] + mb[ch]) / mr[ch] - 1, noise / mr[ch]);
    // Every channel within 3% (both renderers transport spectra, so saturated interreflections
    // agree too).
    EXPECT_LT(diff, 0.03 + 3 * noise / mr[ch]) << "channel " << ch;
  }
  // What remains per pixel is noise: our render differs from pbrt-v4's (whose own noise is
  // negligible at 2048 spp) no more than from another render of ours. E[relMSE(a, ref)] is
  // sigma^2 + bias^2 and E[relMSE(a, b)] is 2 sigma^2, so this fails once bias^2 ~ sigma^2.
  double to_ref = compare_images(a, ref).rel_mse, to_ours = compare_images(a, b).rel_mse;
  std::printf("%s relMSE to pbrt-v4 %.5f, to an independent bpm render %.5f\n", c.scene, to_ref,
              to_ours);
  EXPECT_LT(to_ref, to_ours);
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, Reference,
    ::testing::Values(
        Case{"cornell-box/scene-v4.pbrt", "cornell-box-path-256x256-2048spp.exr", 256, 256, 32},
        Case{"veach-mis/scene-v4.pbrt", "veach-mis-path-320x180-2048spp.exr", 320, 180, 32}),
    [](const auto& info) { return std::string(info.index == 0 ? "CornellBox" : "VeachMis"); });

}  // namespace
}  // namespace bpm
