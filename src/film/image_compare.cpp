#include "film/image_compare.h"

namespace bpm {

std::array<double, 3> channel_means(const Image& img) {
  std::array<double, 3> m{0, 0, 0};
  size_t n = size_t(img.width) * img.height;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) m[c] += img.rgb[3 * i + c];
  for (double& v : m) v /= double(n);
  return m;
}

ImageComparison compare_images(const Image& a, const Image& b) {
  ImageComparison r;
  r.mean_a = channel_means(a);
  r.mean_b = channel_means(b);
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    double d = double(a.rgb[i]) - b.rgb[i];
    r.rel_mse += d * d / (double(b.rgb[i]) * b.rgb[i] + 0.01);
  }
  r.rel_mse /= double(a.rgb.size());
  return r;
}

}  // namespace bpm
