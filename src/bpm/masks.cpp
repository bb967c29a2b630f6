#include "bpm/masks.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <numeric>

#include "base/error.h"

namespace bpm {

int PixelMasks::block_size_for(int threads) {
  return threads <= 4 ? 32 : (threads <= 16 ? 64 : 128);
}

PixelMasks::PixelMasks(int width, int height, int slots)
    : width_(width),
      height_(height),
      slots_(std::clamp(slots, 1, 65535)),
      block_(block_size_for(slots)) {
  bx_ = (width_ + block_ - 1) / block_;
  by_ = (height_ + block_ - 1) / block_;
  owner_.assign(size_t(width_) * height_, 0);
  lists_.assign(size_t(block_count()) * slots_, {});
  for (int b = 0; b < block_count(); ++b) assign_block(b, nullptr);
}

void PixelMasks::rebuild(const std::vector<float>& cost) {
  BPM_CHECK(cost.size() == owner_.size());
  if (slots_ == 1) return;  // one slot owns every pixel, in image order, whatever the costs
  // Blocks own disjoint pixels and lists: they are rebuilt in parallel, each as it would be alone.
  tbb::parallel_for(tbb::blocked_range<int>(0, block_count(), 1),
                    [&](const tbb::blocked_range<int>& r) {
                      for (int b = r.begin(); b < r.end(); ++b) assign_block(b, &cost);
                    });
}

void PixelMasks::assign_block(int b, const std::vector<float>* cost) {
  const int x0 = (b % bx_) * block_, y0 = (b / bx_) * block_;
  const int x1 = std::min(x0 + block_, width_), y1 = std::min(y0 + block_, height_);
  std::vector<uint32_t>* lists = &lists_[size_t(b) * slots_];
  for (int s = 0; s < slots_; ++s) lists[s].clear();
  // Before any measurement: a diagonal interleave, so that each slot's pixels spread over the
  // whole block. After: each pixel, in image order, goes to the slot with the least cost so far
  // (list scheduling), so that no slot's cost exceeds the mean by more than one pixel's, and each
  // slot walks its pixels in image order (coherent rays).
  std::vector<double> load(cost ? size_t(slots_) : 0, 0.0);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const uint32_t p = uint32_t(y) * uint32_t(width_) + uint32_t(x);
      int s = (x + 3 * y) % slots_;
      if (cost) {
        s = int(std::min_element(load.begin(), load.end()) - load.begin());
        load[size_t(s)] += std::max(0.0f, (*cost)[p]);
      }
      owner_[p] = uint16_t(s);
      lists[s].push_back(p);
    }
}

}  // namespace bpm
