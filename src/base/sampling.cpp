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

AliasTable::AliasTable(const std::vector<float>& weights) {
  const size_t n = weights.size();
  bins_.resize(n);
  if (n == 0) return;
  double total = 0;
  for (float w : weights) {
    BPM_CHECK(w >= 0 && std::isfinite(w));
    total += w;
  }
  // Each bin's share scaled so that the mean is 1; bins below 1 are topped up from bins above.
  std::vector<double> scaled(n);
  std::vector<uint32_t> small, large;
  for (size_t i = 0; i < n; ++i) {
    const double p = total > 0 ? weights[i] / total : 1.0 / double(n);
    bins_[i] = {1, uint32_t(i), float(p)};
    scaled[i] = p * double(n);
    (scaled[i] < 1 ? small : large).push_back(uint32_t(i));
  }
  while (!small.empty() && !large.empty()) {
    const uint32_t s = small.back(), l = large.back();
    small.pop_back();
    bins_[s].keep = float(scaled[s]);
    bins_[s].alias = l;
    scaled[l] -= 1 - scaled[s];
    if (scaled[l] < 1) {
      large.pop_back();
      small.push_back(l);
    }
  }
  // What is left is 1 up to rounding: those bins keep their own index. A zero-weight bin left
  // over by rounding must still never be drawn: it sends every draw to a bin of positive weight.
  for (uint32_t i : small) bins_[i].keep = 1;
  for (uint32_t i : large) bins_[i].keep = 1;
  for (Bin& b : bins_)
    if (b.pmf == 0 && b.keep > 0) {
      b.keep = 0;
      if (bins_[b.alias].pmf == 0)
        for (uint32_t k = 0; k < n; ++k)
          if (bins_[k].pmf > 0) b.alias = k;
    }
}

Distribution2D::Distribution2D(const std::vector<float>& weights, int w, int h) : w_(w), h_(h) {
  BPM_CHECK(w > 0 && h > 0 && weights.size() == size_t(w) * size_t(h));
  std::vector<float> row_totals(static_cast<size_t>(h));
  rows_.reserve(size_t(h));
  for (int y = 0; y < h; ++y) {
    std::vector<float> row(weights.begin() + ptrdiff_t(y) * w,
                           weights.begin() + ptrdiff_t(y + 1) * w);
    rows_.emplace_back(row);
    row_totals[size_t(y)] = float(rows_.back().total());
  }
  marginal_ = Distribution1D(row_totals);
}

Vec2 Distribution2D::sample(Vec2 u, float* pdf) const {
  float pm = 0, pc = 0, uy = 0, ux = 0;
  int y = marginal_.sample(u.y, &pm, &uy);
  int x = rows_[size_t(y)].sample(u.x, &pc, &ux);
  *pdf = pm * pc * float(w_) * float(h_);
  return {(float(x) + ux) / float(w_), (float(y) + uy) / float(h_)};
}

float Distribution2D::pdf(Vec2 p) const {
  int x = std::clamp(int(p.x * float(w_)), 0, w_ - 1),
      y = std::clamp(int(p.y * float(h_)), 0, h_ - 1);
  return marginal_.pmf(y) * rows_[size_t(y)].pmf(x) * float(w_) * float(h_);
}

Vec3 equal_area_square_to_sphere(Vec2 p) {
  // Fold the square into the first quadrant, find the ring (r) and the position along it (phi).
  float u = 2 * p.x - 1, v = 2 * p.y - 1;
  float up = std::fabs(u), vp = std::fabs(v);
  float signed_distance = 1 - (up + vp);  // > 0 inside the central diamond (the upper hemisphere)
  float r = 1 - std::fabs(signed_distance);
  float phi = (r == 0 ? 1 : (vp - up) / r + 1) * kPi / 4;
  float z = std::copysign(1 - r * r, signed_distance);
  float cos_phi = std::copysign(std::cos(phi), u), sin_phi = std::copysign(std::sin(phi), v);
  float s = r * std::sqrt(std::fmax(0.0f, 2 - r * r));
  return {cos_phi * s, sin_phi * s, z};
}

Vec2 equal_area_sphere_to_square(Vec3 d) {
  float x = std::fabs(d.x), y = std::fabs(d.y), z = std::fabs(d.z);
  float r = std::sqrt(std::fmax(0.0f, 1 - z));
  float a = std::fmax(x, y), b = std::fmin(x, y);
  b = a == 0 ? 0 : b / a;
  float phi = std::atan(b) * 2 / kPi;
  if (x < y) phi = 1 - phi;
  float v = phi * r, u = r - v;
  if (d.z < 0) {  // lower hemisphere: mirror across the diamond's edge
    std::swap(u, v);
    u = 1 - u;
    v = 1 - v;
  }
  u = std::copysign(u, d.x);
  v = std::copysign(v, d.y);
  return {(u + 1) / 2, (v + 1) / 2};
}

Vec2 wrap_equal_area_square(Vec2 p) {
  if (p.x < 0 || p.x > 1) {
    p.x = p.x < 0 ? -p.x : 2 - p.x;
    p.y = 1 - p.y;
  }
  if (p.y < 0 || p.y > 1) {
    p.x = 1 - p.x;
    p.y = p.y < 0 ? -p.y : 2 - p.y;
  }
  return p;
}

Vec3 sample_henyey_greenstein(Vec3 travel, float g, Vec2 u) {
  // The inverse of the cosine's distribution, 2 pi HG(cos) on [-1, 1].
  float cos_theta;
  if (std::fabs(g) < 1e-3f) {
    cos_theta = 1 - 2 * u.x;
  } else {
    const float k = (1 - g * g) / (1 - g + 2 * g * u.x);
    cos_theta = (1 + g * g - k * k) / (2 * g);
  }
  cos_theta = std::clamp(cos_theta, -1.0f, 1.0f);
  const float sin_theta = std::sqrt(std::fmax(0.0f, 1 - cos_theta * cos_theta));
  const float phi = 2 * kPi * u.y;
  const Frame f = Frame::from_z(travel);
  return normalize(
      f.to_world(Vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta)));
}

}  // namespace bpm
