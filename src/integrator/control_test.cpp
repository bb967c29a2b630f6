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

// An upper bound of the variance of a pixel's estimate, per unit variance of its draws, after
// `passes` passes: every round sampling it at the floor f (RenderControl::sample_pixel), so
// that a round of L passes, of which L' were rendered, samples it 1 + B times, B binomial over
// L' - 1 passes with probability q = (f L - 1) / (L - 1) (none where q <= 0), and E[1 / (1 + B)] =
// (1 - (1 - q)^L') / (L' q); the round's mean weighs L' / passes.
double variance_bound(int passes, double floor) {
  double v = 0;
  for (int start = 0, end = 1; end <= passes; ++end) {
    if (!ends_round(end) && end < passes) continue;
    int full = end;  // the round's length had it not been cut
    while (!ends_round(full)) ++full;
    const int length = full - start, done = end - start;
    const double q = length > 1 ? (floor * length - 1) / (length - 1) : 0.0;
    const double inverse_count = q > 0 ? (1 - std::pow(1 - q, done)) / (done * q) : 1.0;
    v += std::pow(double(done) / passes, 2) * inverse_count;
    start = end;
  }
  return v;
}

// Where how often a pixel is sampled follows what it has drawn, the mean of the passes that
// sampled it reads low: pixels that drew no 100 in their first passes are sampled a tenth as
// often and keep their mean of 1 longer (this film read 1.50 so). Each round's mean weighed by
// the round's length is unbiased; over 4096 pixels, within 4 standard deviations of the bound.
TEST(AdaptiveSampling, PixelsOfRareBrightValuesStayUnbiased) {
  constexpr int kSide = 64, kPasses = 300, kPixels = kSide * kSide;
  RenderStats stats;
  const Film film = render_rare_values(kSide, kPasses, true, &stats);
  EXPECT_LT(stats.mean_sampling_probability, 0.9);  // adaptive sampling is at work
  const double sd = std::sqrt(99.0 * variance_bound(kPasses, 0.1) / kPixels);
  EXPECT_LT(sd, 0.05);
  EXPECT_NEAR(mean_of(film.image()), 2.0, 4 * sd);
  // Without adaptive sampling every round's passes all sample each pixel: the plain mean.
  RenderStats uniform_stats;
  const Film uniform = render_rare_values(kSide, kPasses, false, &uniform_stats);
  EXPECT_NEAR(mean_of(uniform.image()), 2.0, 4 * std::sqrt(99.0 / kPasses / kPixels));
}

}  // namespace
}  // namespace bpm
