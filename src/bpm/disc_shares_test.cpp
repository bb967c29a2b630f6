// The disc probes that the eye pass leaves pending run after the light pass, only for the backward
// photons that gathered light: by a wall such a disc is found cut, on the open floor whole; a disc
// that gathered nothing, or was never pending, is left as it was; and what the probes find depends
// on the seed and the iteration, not on the threads.
#include "bpm/disc_shares.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "scene/flatten.h"
#include "scene/parsed_scene.h"

namespace bpm {
namespace {

// A 20 x 20 floor (object 0) and a wall in the plane x = 0 (object 1).
const char* kScene = R"(LookAt 0 3 -5  0 0 0  0 1 0
Camera "perspective"
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
WorldBegin
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point3 P" [-10 0 -10  -10 0 10  10 0 10  10 0 -10]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point3 P" [0 0 -10  0 0 10  0 2 10  0 2 -10]
)";

BackwardPhoton on_floor(Vec3 p, uint32_t pixel, bool pending) {
  BackwardPhoton bp{};
  bp.p = p;
  bp.radius = 1;
  bp.ng = bp.ns = bp.wo = Vec3(0, 1, 0);
  bp.pixel = pixel;
  bp.probes_pending = pending;
  bp.cut_off_tested = pending;
  bp.set_error(1e-6f);
  return bp;
}

// Four backward photons on the floor, `copies` times (each copy its own pixels), the light they
// gathered, and the maps that hold them.
struct Case {
  BackwardMaps maps;
  LightPassResult light;
  explicit Case(int copies) {
    for (uint32_t k = 0; k < uint32_t(copies); ++k) {
      const uint32_t p = 4 * k;
      maps.photons.push_back(on_floor(Vec3(0.3f, 0, 0), p, true));        // by the wall, lit
      maps.photons.push_back(on_floor(Vec3(0.3f, 0, 2), p + 1, true));    // by the wall, unlit
      maps.photons.push_back(on_floor(Vec3(-5, 0, 0), p + 2, true));      // in the open, lit
      maps.photons.push_back(on_floor(Vec3(0.3f, 0, -2), p + 3, false));  // never pending
      for (int i = 0; i < 4; ++i) {
        light.reached.push_back(i != 1);
        light.flux.push_back(i != 1 ? Spectrum(1.0f) : Spectrum());
      }
    }
    const uint32_t n = uint32_t(maps.photons.size());
    maps.object_begin = {0, n, n};
  }
};

std::vector<std::pair<uint8_t, uint8_t>> probe_with(const LoadedScene& ls, int threads, int seed,
                                                    int iteration, uint64_t* rays = nullptr,
                                                    int copies = 1) {
  Case c(copies);
  tbb::enumerable_thread_specific<EyeCounters> counters;
  tbb::task_arena(threads).execute([&] {
    probe_lit_discs(ls.scene, c.light, 0.5f, uint64_t(seed), iteration, &c.maps, &counters);
  });
  if (rays) {
    *rays = 0;
    for (const EyeCounters& e : counters) *rays += e.rays.probe_rays;
  }
  std::vector<std::pair<uint8_t, uint8_t>> bits;
  for (const BackwardPhoton& bp : c.maps.photons) bits.emplace_back(bp.disc_found, bp.disc_cut);
  return bits;
}

TEST(DiscShares, OnlyLitPendingDiscsAreProbed) {
  const LoadedScene ls = flatten_scene(parse_scene_string(kScene));
  uint64_t rays = 0;
  const auto bits = probe_with(ls, 2, 1, 0, &rays);
  // By the wall: the disc reaches 0.7 past it, 31% of its area; some of 8 probes find the wall.
  EXPECT_NE(bits[0].second, 0);
  EXPECT_NE(bits[0].first, 0);
  EXPECT_EQ(bits[1], std::make_pair(uint8_t(0), uint8_t(0)));
  EXPECT_EQ(bits[2].second, 0);
  EXPECT_NE(bits[2].first, 0);
  EXPECT_EQ(bits[3], std::make_pair(uint8_t(0), uint8_t(0)));
  // Two discs probed, each with at least its eight probes.
  EXPECT_GE(rays, uint64_t(2 * kDiscProbes));
  // By the wall the share found is near the disc's part this side of it, over many iterations.
  double share = 0;
  constexpr int kIterations = 400;
  for (int it = 0; it < kIterations; ++it) {
    const auto b = probe_with(ls, 2, 1, it);
    share += disc_share(b[0].first, b[0].second, 0) / double(kIterations);
  }
  const double d = 0.3, segment = (std::acos(d) - d * std::sqrt(1 - d * d)) / M_PI;
  EXPECT_NEAR(share, 1 - segment, 0.03);
}

TEST(DiscShares, ProbesDependOnTheSeedAndIterationNotTheThreads) {
  const LoadedScene ls = flatten_scene(parse_scene_string(kScene));
  // 4096 backward photons: several tasks of the parallel loop, taken by the threads in any order.
  constexpr int kCopies = 1024;
  const auto one = probe_with(ls, 1, 7, 3, nullptr, kCopies),
             two = probe_with(ls, 2, 7, 3, nullptr, kCopies);
  EXPECT_EQ(one, two);
  // Another iteration or another seed draws other probes: the wall's discs are found otherwise.
  EXPECT_NE(probe_with(ls, 2, 7, 4, nullptr, kCopies), one);
  EXPECT_NE(probe_with(ls, 2, 8, 3, nullptr, kCopies), one);
}

}  // namespace
}  // namespace bpm
