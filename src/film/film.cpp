#include "film/film.h"

#include <cmath>

namespace bpm {

Film::Film(int width, int height, int m_images)
    : width_(width),
      height_(height),
      pixels_(size_t(width) * height),
      m_(m_images > 1 ? m_images : 0) {
  m_sum_.assign(pixels_.size() * size_t(m_), 0.0);
  m_count_.assign(pixels_.size() * size_t(m_), 0);
}

std::vector<float> Film::rms_m_images() const {
  std::vector<float> out(pixels_.size(), 0.0f);
  if (m_ == 0) return out;
  for (size_t i = 0; i < pixels_.size(); ++i) {
    const double* s = &m_sum_[i * m_];
    const int* c = &m_count_[i * m_];
    double mean = 0, var = 0;
    bool full = true;
    for (int k = 0; k < m_; ++k) full = full && c[k] > 0;
    if (!full) continue;
    for (int k = 0; k < m_; ++k) mean += s[k] / c[k];
    mean /= m_;
    for (int k = 0; k < m_; ++k) var += (s[k] / c[k] - mean) * (s[k] / c[k] - mean);
    // The standard deviation between the M images, over sqrt(M): the error of their average.
    out[i] = float(std::sqrt(var / (m_ - 1) / m_));
  }
  return out;
}

double Film::relative_error_m_images() const { return m_ == 0 ? 0 : delta_from(rms_m_images()); }

Image Film::image(float scale) const {
  Image img;
  img.width = width_;
  img.height = height_;
  img.rgb.resize(pixels_.size() * 3);
  for (size_t i = 0; i < pixels_.size(); ++i) {
    const Pixel& p = pixels_[i];
    for (int c = 0; c < 3; ++c)
      img.rgb[3 * i + c] = p.sum_w != 0 ? float(scale * p.sum_wl[c] / p.sum_w) : 0.0f;
  }
  return img;
}

std::vector<float> Film::rms() const {
  std::vector<float> out(pixels_.size(), 0.0f);
  for (size_t i = 0; i < pixels_.size(); ++i) {
    const Pixel& p = pixels_[i];
    if (p.passes < 2) continue;
    double n = p.passes, mean = p.sum_e / n;
    // eq. (5): RMS_i^2 = (1/N) (mean(L^2) - mean(L)^2), with Bessel's correction.
    double var = std::fmax(0.0, (p.sum_e2 / n - mean * mean)) * n / (n - 1);
    out[i] = float(std::sqrt(var / n));
  }
  return out;
}

double Film::relative_error() const { return delta_from(rms()); }

double Film::delta_from(const std::vector<float>& r) const {
  double num = 0, den = 0;
  for (size_t i = 0; i < pixels_.size(); ++i) {
    const Pixel& p = pixels_[i];
    if (p.passes == 0) continue;
    double mean = p.sum_e / p.passes;
    num += double(r[i]) * r[i];
    den += mean * mean;
  }
  return den > 0 ? std::sqrt(num / den) : 0;  // eq. (4)
}

std::vector<float> Film::pass_counts() const {
  std::vector<float> out(pixels_.size());
  for (size_t i = 0; i < pixels_.size(); ++i) out[i] = float(pixels_[i].passes);
  return out;
}

}  // namespace bpm
