#include "film/legend.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "textures/image_file.h"

namespace bpm {
namespace {

// t in [0, 1] along a ramp.
Rgb ramp_colour(ColourScale::Ramp ramp, float t) {
  t = std::clamp(t, 0.0f, 1.0f);
  if (ramp == ColourScale::kBlueRed)
    return Rgb(std::clamp(2 * t - 1, 0.0f, 1.0f), 1 - std::fabs(2 * t - 1),
               std::clamp(1 - 2 * t, 0.0f, 1.0f));
  // Black through dark red, orange and yellow to white: brightness grows along it, so that it
  // reads in grey as well.
  return Rgb(std::clamp(3 * t, 0.0f, 1.0f), std::clamp(3 * t - 1, 0.0f, 1.0f),
             std::clamp(3 * t - 2, 0.0f, 1.0f));
}

std::string number_text(double v, bool percent) {
  char text[32];
  if (percent)
    std::snprintf(text, sizeof text, "%g%%", std::round(v * 1000) / 10);
  else
    std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

// The fraction along the scale of each labelled value, and its text.
std::vector<std::pair<double, std::string>> ticks(const ColourScale& s) {
  std::vector<std::pair<double, std::string>> out;
  if (s.log) {
    const int decades = int(std::lround(std::log10(s.hi / s.lo)));
    for (int k = 0; k <= decades; ++k)
      out.push_back({double(k) / decades, number_text(s.lo * std::pow(10.0, k), s.percent)});
  } else {
    for (int k = 0; k <= 4; ++k)
      out.push_back({k / 4.0, number_text(s.lo + (s.hi - s.lo) * k / 4.0, s.percent)});
  }
  return out;
}

// Draws on img, keeping the first failure's reason.
struct Pen {
  Image* img;
  std::string* warning;
  void text(int x, int y, const std::string& t, int size, Rgb c, int align) {
    const float colour[3] = {c[0], c[1], c[2]};
    std::string error;
    if (!draw_text(img->rgb.data(), img->width, img->height, x, y, t, size, colour, align,
                   &error) &&
        warning->empty())
      *warning = "the legend's text is not drawn: " + error;
  }
  void fill(int x0, int y0, int x1, int y1, Rgb c) {
    for (int y = std::max(y0, 0); y < std::min(y1, img->height); ++y)
      for (int x = std::max(x0, 0); x < std::min(x1, img->width); ++x) {
        float* p = &img->rgb[3 * (size_t(y) * size_t(img->width) + size_t(x))];
        p[0] = c[0];
        p[1] = c[1];
        p[2] = c[2];
      }
  }
};

constexpr int kLegendHeight = 64, kGap = 8, kMargin = 10, kMinWidth = 360;

void draw_block(const ValueBlock& b, const ColourScale& s, int top, Pen& pen) {
  const int z = b.zoom;
  for (int j = 0; j < b.height; ++j)
    for (int i = 0; i < b.width; ++i) {
      const float v = (*b.values)[size_t(j) * size_t(b.width) + size_t(i)];
      pen.fill(i * z, top + j * z, (i + 1) * z, top + (j + 1) * z, s.colour(v));
    }
  if (!b.labels || z < 36) return;
  const int size = std::min(14, z / 3);
  for (int j = 0; j < b.height; ++j)
    for (int i = 0; i < b.width; ++i) {
      const float v = (*b.values)[size_t(j) * size_t(b.width) + size_t(i)];
      const Rgb c = s.colour(v);
      const Rgb ink = 0.3f * c[0] + 0.6f * c[1] + 0.1f * c[2] > 0.5f ? Rgb(0.0f) : Rgb(1.0f);
      pen.text(i * z + z / 2, top + j * z + z / 2 + size / 2, number_text(v, s.percent), size, ink,
               1);
    }
}

void draw_legend(const ColourScale& s, int top, Pen& pen) {
  const int w = pen.img->width, bar0 = kMargin, bar1 = w - kMargin;
  const Rgb ink(0.0f);
  pen.text(kMargin, top + 16, s.title, 13, ink, 0);
  for (int x = bar0; x < bar1; ++x) {
    const double t = double(x - bar0) / std::max(1, bar1 - bar0 - 1);
    pen.fill(x, top + 22, x + 1, top + 38, ramp_colour(s.ramp, float(t)));
  }
  const auto marks = ticks(s);
  for (size_t k = 0; k < marks.size(); ++k) {
    const int x = bar0 + int(std::lround(marks[k].first * (bar1 - bar0 - 1)));
    pen.fill(x, top + 38, x + 1, top + 44, ink);
    const int align = k == 0 ? 0 : (k + 1 == marks.size() ? 2 : 1);
    pen.text(x, top + 57, marks[k].second, 12, ink, align);
  }
}

// The q-quantile of the positive finite values (0 when there are none).
double positive_quantile(const std::vector<float>& values, double q) {
  std::vector<float> v;
  for (float x : values)
    if (x > 0 && std::isfinite(x)) v.push_back(x);
  if (v.empty()) return 0;
  const size_t k = std::min(v.size() - 1, size_t(q * double(v.size())));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return v[k];
}

}  // namespace

Rgb ColourScale::colour(double value) const {
  double t;
  if (log)
    t = value > 0 ? std::log10(value / lo) / std::log10(hi / lo) : 0;
  else
    t = (value - lo) / (hi - lo);
  return ramp_colour(ramp, std::isfinite(t) ? float(t) : 0.0f);
}

ColourScale log_scale(const std::vector<float>& values, const std::string& title) {
  ColourScale s;
  s.log = true;
  s.title = title;
  const double top = positive_quantile(values, 0.999), bottom = positive_quantile(values, 0.01);
  if (!(top > 0)) {
    s.lo = 0.1;
    s.hi = 1;
    return s;
  }
  const int hi = int(std::ceil(std::log10(top)));
  const int lo = std::clamp(int(std::floor(std::log10(bottom))), hi - 6, hi - 1);
  s.lo = std::pow(10.0, lo);
  s.hi = std::pow(10.0, hi);
  return s;
}

ColourScale linear_scale(const std::vector<float>& values, const std::string& title) {
  ColourScale s;
  s.title = title;
  double top = 0;
  for (float v : values)
    if (std::isfinite(v)) top = std::max(top, double(v));
  if (!(top > 0)) top = 1;
  const double decade = std::pow(10.0, std::floor(std::log10(top)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * decade >= top * (1 - 1e-9)) {
      s.hi = m * decade;
      break;
    }
  return s;
}

Image false_colour_picture(const std::vector<ValueBlock>& blocks, const ColourScale& scale,
                           std::string* warning) {
  warning->clear();
  int width = kMinWidth, height = kLegendHeight;
  for (const ValueBlock& b : blocks) {
    width = std::max(width, b.width * b.zoom);
    height += b.height * b.zoom + kGap;
  }
  Image img;
  img.width = width;
  img.height = height;
  img.rgb.assign(size_t(width) * size_t(height) * 3, 1.0f);  // white
  Pen pen{&img, warning};
  int top = 0;
  for (const ValueBlock& b : blocks) {
    draw_block(b, scale, top, pen);
    top += b.height * b.zoom + kGap;
  }
  draw_legend(scale, top, pen);
  return img;
}

}  // namespace bpm
