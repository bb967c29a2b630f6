// Pixel masks: every pixel has one owner, each slot's list holds exactly the pixels it owns in
// image order, and rebuilding from measured costs balances the slots of each block to within one
// pixel's cost.
#include "bpm/masks.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "base/rng.h"

namespace bpm {
namespace {

// The lists and owners agree and cover every pixel once; returns each (block, slot)'s cost.
std::vector<double> check_masks(const PixelMasks& m, int width, int height,
                                const std::vector<float>& cost) {
  std::vector<int> seen(size_t(width) * height, 0);
  std::vector<double> load;
  for (int b = 0; b < m.block_count(); ++b)
    for (int s = 0; s < m.slots(); ++s) {
      const std::vector<uint32_t>& l = m.pixels(b, s);
      EXPECT_TRUE(std::is_sorted(l.begin(), l.end())) << "block " << b << " slot " << s;
      double sum = 0;
      for (uint32_t p : l) {
        EXPECT_EQ(m.owner()[p], s);
        ++seen[p];
        sum += cost.empty() ? 0.0 : cost[p];
      }
      load.push_back(sum);
    }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
  return load;
}

TEST(PixelMasks, EveryPixelHasOneOwnerAndBlocksAreBalanced) {
  const int width = 100, height = 70;  // blocks of 32: partial ones on the right and bottom
  for (int slots : {1, 2, 3, 7}) {
    PixelMasks m(width, height, slots);
    check_masks(m, width, height, {});
    // Costs with an expensive region (a glass object) and some free pixels (skipped ones).
    Rng rng(stream_key(5, uint64_t(slots)));
    std::vector<float> cost(size_t(width) * height);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        float c = 100 + 50 * rng.uniform();
        if (x > 40 && x < 60 && y > 20) c *= 20;
        if (rng.uniform() < 0.1f) c = 0;
        cost[size_t(y) * width + x] = c;
      }
    m.rebuild(cost);
    const std::vector<double> load = check_masks(m, width, height, cost);
    const float max_cost = *std::max_element(cost.begin(), cost.end());
    for (int b = 0; b < m.block_count(); ++b) {
      double sum = 0;
      for (int s = 0; s < slots; ++s) sum += load[size_t(b) * slots + s];
      for (int s = 0; s < slots; ++s)
        EXPECT_LE(load[size_t(b) * slots + s], sum / slots + max_cost)
            << slots << " slots, block " << b << " slot " << s;
    }
  }
}

}  // namespace
}  // namespace bpm
