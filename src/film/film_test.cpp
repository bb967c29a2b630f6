#include "film/film.h"

#include <gtest/gtest.h>

#include <cmath>

#include "base/rng.h"

namespace bpm {
namespace {

// Records one pass of one pixel (and sensor 0) with the estimate v.
void record(Film* film, int pass, float v) {
  film->begin_pass(pass);
  FilmSample s;
  s.rgb = Rgb(v, v, v);
  s.luminance = v;
  film->add_sample(0, 0, s, 1);
  film->end_pass(0, 0);
  film->add_sensor_pass(0, v);
}

// Passes stratified within each stream (the t-th pass of a stream is 1 + 0.5 or 1 - 0.5 by the
// parity of t, so a stream's mean is exactly 1 after an even number of its passes): the spread
// between the streams and between the M images sees no error, where eq. 5 over the passes, which
// takes them for independent, sees 0.5 / sqrt(passes).
TEST(Film, DependentPassesTakeTheirErrorFromTheStreams) {
  for (bool independent : {true, false}) {
    Film film(1, 1, Film::kStreams, 1);
    film.set_independent_passes(independent);
    const int passes = 16 * Film::kStreams;
    for (int j = 0; j < passes; ++j) record(&film, j, (j / Film::kStreams) % 2 ? 1.5f : 0.5f);
    const double eq5 = 0.5 / std::sqrt(passes - 1.0);
    EXPECT_NEAR(film.image().at(0, 0)[0], 1.0, 1e-6);
    if (independent) {
      EXPECT_NEAR(film.rms()[0], eq5, 1e-4);
      EXPECT_NEAR(film.sensor_standard_error(0), eq5, 1e-4);
    } else {
      EXPECT_LT(film.rms()[0], 1e-6);
      EXPECT_LT(film.rms_rgb()[1], 1e-6);
      EXPECT_LT(film.sensor_standard_error(0), 1e-9);
    }
  }
}

// Independent passes: both estimates are the standard error of the mean, within the spread of
// a 7-degree-of-freedom estimate; and until each image and stream has a pass, the film states
// eq. 5 (an upper bound) rather than nothing.
TEST(Film, StreamSpreadAgreesWithEq5ForIndependentPasses) {
  Rng rng(7);
  double sum_ratio2 = 0;
  constexpr int kTrials = 40, kPasses = 64;
  for (int trial = 0; trial < kTrials; ++trial) {
    Film a(1, 1, Film::kStreams, 1), b(1, 1, Film::kStreams, 1);
    b.set_independent_passes(false);
    for (int j = 0; j < kPasses; ++j) {
      const float v = 1 + float(rng.uniform()) - 0.5f;
      record(&a, j, v);
      record(&b, j, v);
    }
    const double ratio = b.sensor_standard_error(0) / a.sensor_standard_error(0);
    EXPECT_NEAR(b.rms()[0], b.sensor_standard_error(0), 1e-5);
    sum_ratio2 += ratio * ratio;
  }
  // E[ratio^2] = 1 for both unbiased variance estimates; its mean over 40 trials has a standard
  // deviation of about sqrt(2/7 / 40) = 0.085.
  EXPECT_NEAR(sum_ratio2 / kTrials, 1.0, 4 * 0.085);

  Film early(1, 1, Film::kStreams, 1);
  early.set_independent_passes(false);
  for (int j = 0; j < 4; ++j) record(&early, j, j % 2 ? 2.0f : 0.0f);
  EXPECT_NEAR(early.rms()[0], std::sqrt(4.0 / 3 / 4), 1e-5);
  EXPECT_NEAR(early.sensor_standard_error(0), std::sqrt(4.0 / 3 / 4), 1e-5);
}

// Films that recorded other passes (the processes of a distributed render) add up to the film
// that recorded them all: the pixels, the M images and the sensors' streams, so that every error
// estimate is the same.
TEST(Film, AddedFilmsStateTheErrorOfAllTheirPasses) {
  Rng rng(11);
  Film all(1, 1, Film::kStreams, 1), a(1, 1, Film::kStreams, 1), b(1, 1, Film::kStreams, 1);
  for (Film* f : {&all, &a, &b}) f->set_independent_passes(false);
  for (int j = 0; j < 4 * Film::kStreams; ++j) {
    const float v = 1 + float(rng.uniform());
    record(&all, j, v);
    record(j % 3 ? &a : &b, j, v);
  }
  a.add(b);
  EXPECT_NEAR(a.sensor_mean(0), all.sensor_mean(0), 1e-9);
  EXPECT_NEAR(a.sensor_standard_error(0), all.sensor_standard_error(0), 1e-9);
  EXPECT_NEAR(a.rms()[0], all.rms()[0], 1e-6);
}

}  // namespace
}  // namespace bpm
