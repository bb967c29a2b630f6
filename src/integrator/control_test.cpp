// Tests of the render loop's adaptive sampling (integrator/control.h) with the film's rounds
// (film/film.h), on synthetic passes whose distribution is known.
#include <gtest/gtest.h>

#include <cmath>

#include "integrator/progressive.h"

namespace bpm {
namespace {

// Renders `passes` passes of a side x side film in which every pixel draws, each time a pass
// samples it, 1 + 100 with probability 1/100 and 1 otherwise (mean 2, variance 99): a pixel
// that has drawn no 100 yet looks converged (its RMS is 0), one that has looks noisy.
Film render_rare_values(int side, int passes, bool adaptive, RenderStats* stats) {
  Film film(side, side);
  IntegratorOptions opt;
  opt.spp = passes;
  opt.adaptive = adaptive;
  opt.progress = false;
  opt.seed = 5;
  run_passes(
      opt, &film, "pass",
      [&](int pass, const RenderControl& control) {
        for_each_sampled_pixel(side, side, control, pass, [&](uint32_t pixel) {
          Rng rng(stream_key(opt.seed, uint64_t(pass), pixel));
          const float v = rng.uniform() < 0.01f ? 101.0f : 1.0f;
          const int x = int(pixel % uint32_t(side)), y = int(pixel / uint32_t(side));
          film.add_sample(x, y, FilmSample{Rgb(v, v, v), v}, 1);
          film.end_pass(x, y);
        });
        return PassResult{};
      },
      stats);
  return film;
}

double mean_of(const Image& img) {
  double sum = 0;
  for (size_t i = 0; i < img.rgb.size(); i += 3) sum += img.rgb[i];
  return sum / double(img.rgb.size() / 3);
}

// Where how often a pixel is sampled follows what it has drawn, the mean of the passes that
// sampled it reads low: pixels that drew no 100 in their first passes are sampled a tenth as
// often and keep their mean of 1 longer (this film read 1.50 so). Each round's mean weighed
// by the round's length is unbiased. Every pixel's estimate has a variance of at most
// 99 sum_r (L_r / N)^2 / n_r <= 99 * 10 / N (n_r >= L_r / 10 passes sample it in a round of L_r
// passes, and at least one), so the mean over 4096 pixels has a standard deviation of at most
// sqrt(99 * 10 / 300 / 4096) = 0.028.
TEST(AdaptiveSampling, PixelsOfRareBrightValuesStayUnbiased) {
  constexpr int kSide = 64, kPasses = 300;
  RenderStats stats;
  const Film film = render_rare_values(kSide, kPasses, true, &stats);
  EXPECT_LT(stats.mean_sampling_probability, 0.9);  // adaptive sampling is at work
  const double sd = std::sqrt(99.0 * 10 / kPasses / (kSide * kSide));
  EXPECT_NEAR(mean_of(film.image()), 2.0, 4 * sd);
  // Without adaptive sampling every round's passes all sample each pixel: the plain mean.
  RenderStats uniform_stats;
  const Film uniform = render_rare_values(kSide, kPasses, false, &uniform_stats);
  EXPECT_NEAR(mean_of(uniform.image()), 2.0, 4 * std::sqrt(99.0 / kPasses / (kSide * kSide)));
}

}  // namespace
}  // namespace bpm
