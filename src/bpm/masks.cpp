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
  // Blocks own disjoint pixels and lists: they are rebuilt in parallel, each as it would be alone.
  tbb::parallel_for(tbb::blocked_range<int>(0, block_count(), 1),
                    [&](const tbb::blocked_range<int>& r) {
                      for (int b = r.begin(); b < r.end(); ++b) assign_block(b, &cost);
                    });
}

void PixelMasks::assign_block(int b, const std::vector<float>* cost) {
  int x0 = (b % bx_) * block_, y0 = (b / bx_) * block_;
  int x1 = std::min(x0 + block_, width_), y1 = std::min(y0 + block_, height_);
  std::vector<uint32_t> pix;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) pix.push_back(uint32_t(y) * width_ + x);
  for (int s = 0; s < slots_; ++s) lists_[size_t(b) * slots_ + s].clear();
  if (!cost) {
    // Before any measurement: a diagonal interleave, so that each slot's pixels spread over the
    // whole block.
    for (uint32_t p : pix) {
      int x = int(p % width_), y = int(p / width_);
      int s = (x + 3 * y) % slots_;
      owner_[p] = uint16_t(s);
      lists_[size_t(b) * slots_ + s].push_back(p);
    }
    return;
  }
  std::stable_sort(pix.begin(), pix.end(),
                   [&](uint32_t a, uint32_t c) { return (*cost)[a] > (*cost)[c]; });
  std::vector<double> load(slots_, 0.0);
  for (uint32_t p : pix) {
    int s = int(std::min_element(load.begin(), load.end()) - load.begin());
    load[s] += std::max(0.0f, (*cost)[p]);
    owner_[p] = uint16_t(s);
    lists_[size_t(b) * slots_ + s].push_back(p);
  }
  // Each slot walks its pixels in image order (coherent rays).
  for (int s = 0; s < slots_; ++s) {
    auto& l = lists_[size_t(b) * slots_ + s];
    std::sort(l.begin(), l.end());
  }
}

}  // namespace bpm
