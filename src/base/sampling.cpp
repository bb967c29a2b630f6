#include "base/sampling.h"

#include <algorithm>

#include "base/error.h"

namespace bpm {

Distribution1D::Distribution1D(const std::vector<float>& weights) {
  cdf_.resize(weights.size() + 1, 0.0);
  for (size_t i = 0; i < weights.size(); ++i) {
    BPM_CHECK(weights[i] >= 0 && std::isfinite(weights[i]));
    cdf_[i + 1] = cdf_[i] + weights[i];
  }
  total_ = cdf_.back();
  pmf_.resize(weights.size());
  if (weights.empty()) return;
  if (total_ <= 0) {
    for (size_t i = 0; i < weights.size(); ++i) {
      cdf_[i + 1] = double(i + 1) / weights.size();
      pmf_[i] = 1.0f / weights.size();
    }
    return;
  }
  for (size_t i = 0; i < weights.size(); ++i) {
    pmf_[i] = static_cast<float>(weights[i] / total_);
    cdf_[i + 1] /= total_;
  }
  cdf_.back() = 1.0;
}

int Distribution1D::sample(float u, float* pmf_out, float* u_remapped) const {
  BPM_CHECK(!pmf_.empty());
  auto it = std::upper_bound(cdf_.begin(), cdf_.end(), double(u));
  int i = std::clamp(int(it - cdf_.begin()) - 1, 0, size() - 1);
  while (pmf_[i] == 0 && i + 1 < size()) ++i;  // never return a zero-probability entry
  if (pmf_out) *pmf_out = pmf_[i];
  if (u_remapped) {
    double w = cdf_[i + 1] - cdf_[i];
    *u_remapped = w > 0 ? std::min(float((u - cdf_[i]) / w), 0x1.fffffep-1f) : 0.0f;
  }
  return i;
}

}  // namespace bpm
