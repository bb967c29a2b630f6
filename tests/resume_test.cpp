// Resuming a render from its saved state (integrator/options.h, RenderState): the film's sums and
// the state run_passes hands to save_state give, after the remaining passes, the very image of a
// render that never stopped. Adaptive sampling and bpm's guided emission are on, so the state
// carried over (sampling probabilities, what the guide learnt, the pixels' running means) matters.
#include <gtest/gtest.h>

#include <string>

#include "test_util.h"

namespace bpm {
namespace {

using test::load;

const std::string kScene = test::glass_corner_scene(24, 18);

RenderOptions options(const LoadedScene& ls, const std::string& integrator, int passes) {
  RenderOptions opt = quiet_options(ls, integrator, passes, 7);
  opt.adaptive = true;
  opt.bpm.photons_per_iteration = 4000;
  opt.fpm.photons_per_iteration = 4000;
  opt.threads = 2;
  return opt;
}

TEST(Resume, ResumedRenderEqualsTheUninterruptedOne) {
  const LoadedScene ls = load(kScene);
  const int total = 14, first = 9;  // 9 is inside a round (8 to 10)
  for (const char* integrator : {"path", "bpm", "fpm"}) {
    Film straight(ls.film.width, ls.film.height, 4);
    render(ls, options(ls, integrator, total), &straight);

    // The first part, saving its state at the end as a checkpoint does.
    Film part(ls.film.width, ls.film.height, 4);
    RenderOptions opt = options(ls, integrator, first);
    RenderState saved;
    opt.save_state = [&](const RenderState& s) { saved = s; };
    render(ls, opt, &part);
    ASSERT_EQ(saved.passes, first) << integrator;
    ByteWriter w;
    part.save(w);

    // A new process: a fresh film takes the saved sums, the render goes on from the state.
    Film resumed(ls.film.width, ls.film.height, 4);
    ByteReader r(w.bytes(), "test state");
    resumed.load(r);
    RenderOptions rest = options(ls, integrator, total);
    rest.resume = &saved;
    const RenderStats st = render(ls, rest, &resumed);
    EXPECT_EQ(st.passes, total) << integrator;

    EXPECT_EQ(resumed.image().rgb, straight.image().rgb) << integrator;
    EXPECT_EQ(resumed.rms_rgb(), straight.rms_rgb()) << integrator;
    EXPECT_EQ(resumed.rms_m_images_rgb(), straight.rms_m_images_rgb()) << integrator;
    EXPECT_EQ(resumed.bias_rgb(), straight.bias_rgb()) << integrator;
  }
}

// A state that lacks what it should hold is refused, not guessed at.
TEST(Resume, AnEmptyStateIsRefused) {
  const LoadedScene ls = load(kScene);
  const int total = 14, first = 9;  // 9 is inside a round (8 to 10)
  Film straight(ls.film.width, ls.film.height);
  render(ls, options(ls, "bpm", total), &straight);
  Film part(ls.film.width, ls.film.height);
  RenderOptions opt = options(ls, "bpm", first);
  RenderState saved;
  opt.save_state = [&](const RenderState& s) { saved = s; };
  render(ls, opt, &part);
  saved.control.clear();
  saved.integrator.clear();
  RenderOptions rest = options(ls, "bpm", total);
  rest.resume = &saved;
  EXPECT_THROW(render(ls, rest, &part), Error);
}

// A film refuses the sums of another size or M.
TEST(Resume, FilmRefusesAnotherSize) {
  Film a(8, 6, 4);
  ByteWriter w;
  a.save(w);
  Film b(8, 7, 4), c(8, 6, 2);
  ByteReader r1(w.bytes(), "state"), r2(w.bytes(), "state");
  EXPECT_THROW(b.load(r1), Error);
  EXPECT_THROW(c.load(r2), Error);
  std::vector<uint8_t> cut(w.bytes().begin(), w.bytes().begin() + long(w.bytes().size() / 2));
  ByteReader r3(cut, "state");
  Film d(8, 6, 4);
  EXPECT_THROW(d.load(r3), Error);
}

}  // namespace
}  // namespace bpm
