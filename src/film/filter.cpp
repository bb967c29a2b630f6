#include "film/filter.h"

#include <algorithm>
#include <cmath>

namespace bpm {
namespace {

float gaussian_1d(float x, float sigma) {
  return std::exp(-x * x / (2 * sigma * sigma)) / std::sqrt(2 * kPi * sigma * sigma);
}
float mitchell_1d(float x, float b, float c) {
  x = std::fabs(x);
  if (x <= 1)
    return ((12 - 9 * b - 6 * c) * x * x * x + (-18 + 12 * b + 6 * c) * x * x + (6 - 2 * b)) / 6;
  if (x <= 2)
    return ((-b - 6 * c) * x * x * x + (6 * b + 30 * c) * x * x + (-12 * b - 48 * c) * x +
            (8 * b + 24 * c)) /
           6;
  return 0;
}
float sinc(float x) { return std::fabs(x) < 1e-5f ? 1 : std::sin(kPi * x) / (kPi * x); }
float windowed_sinc(float x, float radius, float tau) {
  if (std::fabs(x) > radius) return 0;
  return sinc(x) * sinc(x / tau);
}
// Sample of the tent on [-r, r] with density (r - |x|) / r^2.
float sample_tent(float u, float r) {
  if (u < 0.5f) {
    float v = u * 2;
    return -r + r * std::sqrt(v);
  }
  float v = (u - 0.5f) * 2;
  return r - r * std::sqrt(1 - v);
}

}  // namespace

Filter::Filter(const FilterSettings& s) : s_(s) {
  if (s_.type == FilterType::kBox || s_.type == FilterType::kTriangle) return;
  // 32 cells per pixel of filter extent (pbrt-v4 uses 32 per unit of radius).
  nx_ = std::max(1, int(32 * s_.radius.x * 2));
  ny_ = std::max(1, int(32 * s_.radius.y * 2));
  values_.resize(size_t(nx_) * ny_);
  std::vector<float> w(values_.size());
  float cell_area = (2 * s_.radius.x / nx_) * (2 * s_.radius.y / ny_);
  integral_ = 0;
  for (int y = 0; y < ny_; ++y)
    for (int x = 0; x < nx_; ++x) {
      Vec2 p{-s_.radius.x + (x + 0.5f) * 2 * s_.radius.x / nx_,
             -s_.radius.y + (y + 0.5f) * 2 * s_.radius.y / ny_};
      float f = evaluate(p);
      values_[y * nx_ + x] = f;
      w[y * nx_ + x] = std::fabs(f);
      integral_ += f * cell_area;
    }
  cells_ = Distribution1D(w);
}

float Filter::evaluate(Vec2 p) const {
  if (std::fabs(p.x) > s_.radius.x || std::fabs(p.y) > s_.radius.y) return 0;
  switch (s_.type) {
    case FilterType::kBox:
      return 1;
    case FilterType::kTriangle:
      return std::fmax(0.0f, s_.radius.x - std::fabs(p.x)) *
             std::fmax(0.0f, s_.radius.y - std::fabs(p.y));
    case FilterType::kGaussian:
      return std::fmax(0.0f, gaussian_1d(p.x, s_.sigma) - gaussian_1d(s_.radius.x, s_.sigma)) *
             std::fmax(0.0f, gaussian_1d(p.y, s_.sigma) - gaussian_1d(s_.radius.y, s_.sigma));
    case FilterType::kMitchell:
      return mitchell_1d(2 * p.x / s_.radius.x, s_.b, s_.c) *
             mitchell_1d(2 * p.y / s_.radius.y, s_.b, s_.c);
    case FilterType::kLanczos:
      return windowed_sinc(p.x, s_.radius.x, s_.tau) * windowed_sinc(p.y, s_.radius.y, s_.tau);
  }
  return 0;
}

FilterSample Filter::sample(Vec2 u) const {
  if (s_.type == FilterType::kBox)
    return {{(2 * u.x - 1) * s_.radius.x, (2 * u.y - 1) * s_.radius.y}, 1};
  if (s_.type == FilterType::kTriangle)
    return {{sample_tent(u.x, s_.radius.x), sample_tent(u.y, s_.radius.y)}, 1};
  float ur;
  float pmf;
  int cell = cells_.sample(u.x, &pmf, &ur);
  int cx = cell % nx_, cy = cell / nx_;
  float w = 2 * s_.radius.x / nx_, h = 2 * s_.radius.y / ny_;
  Vec2 p{-s_.radius.x + (cx + ur) * w, -s_.radius.y + (cy + u.y) * h};
  // Piecewise-constant density over |f|; the weight f / pdf averages to the filter integral,
  // which the film's weight sum divides out.
  float pdf = pmf / (w * h);
  float f = values_[cell];
  return {p, pdf > 0 ? f / pdf : 0};
}

int Filter::cell_of(Vec2 offset) const {
  const int cx =
      std::clamp(int((offset.x + s_.radius.x) / (2 * s_.radius.x) * float(nx_)), 0, nx_ - 1);
  const int cy =
      std::clamp(int((offset.y + s_.radius.y) / (2 * s_.radius.y) * float(ny_)), 0, ny_ - 1);
  return cy * nx_ + cx;
}

float Filter::sample_density(Vec2 offset) const {
  const float rx = s_.radius.x, ry = s_.radius.y;
  if (std::fabs(offset.x) > rx || std::fabs(offset.y) > ry) return 0;
  if (s_.type == FilterType::kBox) return 1 / (4 * rx * ry);
  if (s_.type == FilterType::kTriangle) return evaluate(offset) / (rx * rx * ry * ry);
  const float cell_area = (2 * rx / float(nx_)) * (2 * ry / float(ny_));
  return cells_.pmf(cell_of(offset)) / cell_area;
}

float Filter::normalized(Vec2 offset) const {
  const float rx = s_.radius.x, ry = s_.radius.y;
  if (std::fabs(offset.x) > rx || std::fabs(offset.y) > ry) return 0;
  if (s_.type == FilterType::kBox || s_.type == FilterType::kTriangle)
    return sample_density(offset);
  return integral_ != 0 ? values_[size_t(cell_of(offset))] / integral_ : 0;
}

std::string Filter::name() const {
  switch (s_.type) {
    case FilterType::kBox:
      return "box";
    case FilterType::kTriangle:
      return "triangle";
    case FilterType::kGaussian:
      return "gaussian";
    case FilterType::kMitchell:
      return "mitchell";
    case FilterType::kLanczos:
      return "lanczos";
  }
  return "?";
}

}  // namespace bpm
