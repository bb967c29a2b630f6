// Blocks and per-thread masks (section 3 of the paper, Fig. 4). The image is cut into square
// blocks of 32, 64 or 128 pixels a side, larger with more threads; inside every block each of the
// K slots owns a subset of the pixels (its mask), so that every block is rendered by all threads
// and a block of expensive pixels does not leave the others idle. The same ownership decides who
// applies a photon's contribution to a pixel in the light pass. Masks are rebuilt between
// iterations from the measured cost of each pixel so that the slots of a block get equal work.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace bpm {

class PixelMasks {
 public:
  PixelMasks(int width, int height, int slots);
  static int block_size_for(int threads);

  int slots() const { return slots_; }
  int block_size() const { return block_; }
  int block_count() const { return bx_ * by_; }
  // Slot that owns each pixel (row-major pixel index).
  const std::vector<uint16_t>& owner() const { return owner_; }
  // Pixels of `block` owned by `slot`.
  const std::vector<uint32_t>& pixels(int block, int slot) const {
    return lists_[size_t(block) * slots_ + slot];
  }
  // Reassigns the pixels of every block to balance the summed cost per slot: no slot of a block
  // gets more than the block's mean cost per slot plus one pixel's.
  void rebuild(const std::vector<float>& cost_per_pixel);

 private:
  void assign_block(int block, const std::vector<float>* cost);
  int width_, height_, slots_, block_, bx_, by_;
  std::vector<uint16_t> owner_;
  std::vector<std::vector<uint32_t>> lists_;
};

}  // namespace bpm
