// Per-pixel accumulation of weighted radiance samples. A pixel is only ever written by the thread
// rendering it, so no atomics are needed. Alongside the weighted sums, the film keeps per pixel the
// sum and sum of squares of per-pass luminance estimates, from which the error estimate of the
// paper's eq. (5) follows.
#pragma once
#include <vector>

#include "base/color.h"
#include "base/spectrum.h"

namespace bpm {

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // width * height * 3, row-major from the top
  Rgb at(int x, int y) const {
    size_t i = 3 * (size_t(y) * width + x);
    return Rgb(rgb[i], rgb[i + 1], rgb[i + 2]);
  }
};

// The colour a film records for a sample with radiance L at wavelengths wl: linear sRGB, with the
// largest channel clamped to max_value (pbrt-v4's maxcomponentvalue). A non-finite or negative
// spectral value (a numerical accident) gives black rather than poisoning the pixel. Colours may
// have negative channels: a single sample's few wavelengths can lie outside the sRGB gamut.
inline Rgb film_rgb(const Spectrum& L, const Wavelengths& wl, float max_value) {
  if (!L.is_finite() || L.has_negative()) return Rgb();
  Rgb c = spectrum_to_rgb(L, wl);
  float m = c.max_component();
  if (m > max_value) c *= max_value / m;
  return c;
}

class Film {
 public:
  // m_images > 0 also keeps the paper's M intermediate images (section 4): pass j of a pixel goes
  // to image j mod M, and the spread between the M images is a second error estimate.
  Film(int width, int height, int m_images = 0);
  int width() const { return width_; }
  int height() const { return height_; }

  void add_sample(int x, int y, const Rgb& L, float weight) {
    Pixel& p = pixels_[size_t(y) * width_ + x];
    for (int c = 0; c < 3; ++c) p.sum_wl[c] += double(weight) * L[c];
    p.sum_w += weight;
    p.pass_wl += double(weight) * L.luminance();
    p.pass_w += weight;
  }
  // Ends the current pass for one pixel: its pass estimate joins the running moments.
  void end_pass(int x, int y) {
    Pixel& p = pixels_[size_t(y) * width_ + x];
    if (p.pass_w != 0) {
      double e = p.pass_wl / p.pass_w;
      p.sum_e += e;
      p.sum_e2 += e * e;
      if (m_ > 0) {
        size_t k = size_t(y) * width_ * m_ + x * size_t(m_) + size_t(p.passes % m_);
        m_sum_[k] += e;
        ++m_count_[k];
      }
      ++p.passes;
    }
    p.pass_wl = p.pass_w = 0;
  }

  Image image(float scale = 1) const;
  // Per-pixel standard error of the luminance mean (eq. 5), and the image error delta (eq. 4).
  std::vector<float> rms() const;
  double relative_error() const;
  std::vector<float> pass_counts() const;
  // The M-images estimates: per-pixel standard error of the mean from the spread of the M image
  // means, and the image error delta from them (eq. 4). Zero until every image has a pass.
  int m_images() const { return m_; }
  std::vector<float> rms_m_images() const;
  double relative_error_m_images() const;

 private:
  // eq. (4) from per-pixel standard errors.
  double delta_from(const std::vector<float>& rms) const;
  struct Pixel {
    double sum_wl[3] = {0, 0, 0};
    double sum_w = 0;
    double pass_wl = 0, pass_w = 0;
    double sum_e = 0, sum_e2 = 0;
    int passes = 0;
  };
  int width_, height_;
  std::vector<Pixel> pixels_;
  int m_ = 0;
  std::vector<double> m_sum_;
  std::vector<int> m_count_;
};

}  // namespace bpm
