// Comparing two images of the same size: per-channel means and the relative MSE of
// ../shared/references/README.md, mean over pixels and channels of (a - b)^2 / (b^2 + 0.01).
// Used by `bpm compare`, the pbrt-v4 reference tests and the conformance program.
#pragma once
#include <array>

#include "film/film.h"

namespace bpm {

std::array<double, 3> channel_means(const Image& img);

struct ImageComparison {
  std::array<double, 3> mean_a{}, mean_b{};
  double rel_mse = 0;
};
// a and b must have the same size.
ImageComparison compare_images(const Image& a, const Image& b);

}  // namespace bpm
