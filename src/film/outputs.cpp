#include "film/outputs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "base/error.h"
#include "film/image_io.h"

namespace bpm {

OutputPaths output_paths(const std::string& exr) {
  const std::string ext = ".exr";
  if (exr.size() <= ext.size() || exr.compare(exr.size() - ext.size(), ext.size(), ext) != 0)
    throw Error("output file \"" + exr + "\" must end in .exr");
  std::string stem = exr.substr(0, exr.size() - ext.size());
  return {exr,
          stem + ".png",
          stem + ".error.png",
          stem + ".json",
          stem + ".bias.png",
          stem + ".checkpoint",
          stem + ".sensors.csv"};
}

void write_sensors_csv(const std::string& path, const Film& film,
                       const std::vector<std::array<float, 6>>& sensors) {
  std::string text =
      "x,y,z,nx,ny,nz,illuminance_lux,standard_error_lux,bias_lux,total_error_lux,passes\n";
  char line[512];
  for (size_t i = 0; i < sensors.size(); ++i) {
    const std::array<float, 6>& s = sensors[i];
    std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,%.6g,%d\n",
                  s[0], s[1], s[2], s[3], s[4], s[5], film.sensor_mean(i),
                  film.sensor_standard_error(i), film.sensor_bias(i), film.sensor_total_error(i),
                  film.sensor_passes(i));
    text += line;
  }
  write_text_atomic(path, text);
}

// Per pixel, an error (R G B) relative to the pixel's value over the three channels (as eq. 4 per
// pixel), 0 to 10% from blue through green to red.
Image relative_false_colour(const Film& film, const std::vector<float>& rms) {
  Image img = film.image();
  Image out;
  out.width = img.width;
  out.height = img.height;
  out.rgb.resize(img.rgb.size());
  for (size_t i = 0; i < img.rgb.size() / 3; ++i) {
    double e2 = 0, v2 = 0;
    for (int c = 0; c < 3; ++c) {
      e2 += double(rms[3 * i + c]) * rms[3 * i + c];
      v2 += double(img.rgb[3 * i + c]) * img.rgb[3 * i + c];
    }
    float rel = v2 > 1e-12 ? float(std::sqrt(e2 / v2)) : (e2 > 0 ? 1.0f : 0.0f);
    float t = std::clamp(rel / 0.1f, 0.0f, 1.0f);
    // blue (0) -> green (0.5) -> red (1)
    out.rgb[3 * i] = std::clamp(2 * t - 1, 0.0f, 1.0f);
    out.rgb[3 * i + 1] = 1 - std::fabs(2 * t - 1);
    out.rgb[3 * i + 2] = std::clamp(1 - 2 * t, 0.0f, 1.0f);
  }
  return out;
}

namespace {

// Per-pixel values, scaled: one vector, or three (R, G, B) from an interleaved one.
std::vector<float> scaled(std::vector<float> v, float s) {
  for (float& x : v) x *= s;
  return v;
}
std::vector<float> channel(const std::vector<float>& rgb, int c, float s) {
  std::vector<float> out(rgb.size() / 3);
  for (size_t i = 0; i < out.size(); ++i) out[i] = rgb[3 * i + size_t(c)] * s;
  return out;
}

}  // namespace

void write_images(const OutputPaths& paths, const Film& film, float imaging_ratio) {
  Image img = film.image(imaging_ratio);
  std::vector<float> passes = film.pass_counts();
  // eq. (5) of the luminance and of each channel; the same from the M images.
  std::vector<std::vector<float>> values;
  std::vector<std::string> names;
  auto add = [&](const std::string& name, std::vector<float> v) {
    names.push_back(name);
    values.push_back(std::move(v));
  };
  add("rms", scaled(film.rms(), imaging_ratio));
  const std::vector<float> rgb = film.rms_rgb(), total = film.total_rms_rgb();
  for (int c = 0; c < 3; ++c) add(std::string("rms.") + "RGB"[c], channel(rgb, c, imaging_ratio));
  add("passes", passes);
  if (film.has_bias()) {
    // The photon methods' bias estimate (signed) and the total error, noise and bias together.
    std::vector<float> bias = film.bias_rgb();
    for (int c = 0; c < 3; ++c)
      add(std::string("bias.") + "RGB"[c], channel(bias, c, imaging_ratio));
    for (int c = 0; c < 3; ++c)
      add(std::string("total_error.") + "RGB"[c], channel(total, c, imaging_ratio));
  }
  // The luminance in cd/m^2 (without the imaging ratio: a physical quantity), its standard error
  // and, for the photon methods, its bias and total error.
  // A layer of its own: an EXR reader that finds a bare Y beside R, G, B may show it alone, grey.
  add("luminance.Y", film.luminance_image());
  add("rms.Y", film.rms());
  if (film.has_bias()) {
    add("bias.Y", film.bias_luminance());
    add("total_error.Y", film.total_rms_luminance());
  }
  if (film.m_images() > 0) {
    add("rms_m_images", scaled(film.rms_m_images(), imaging_ratio));
    std::vector<float> m_rgb = film.rms_m_images_rgb();
    for (int c = 0; c < 3; ++c)
      add(std::string("rms_m_images.") + "RGB"[c], channel(m_rgb, c, imaging_ratio));
  }
  std::vector<ExtraChannel> extra;
  for (size_t k = 0; k < names.size(); ++k) extra.push_back({names[k], &values[k]});
  write_exr(paths.exr, img, extra);
  write_png(paths.png, img);
  write_png_display(paths.error_png, relative_false_colour(film, total));
  if (!film.has_bias() && !paths.bias_png.empty()) {
    // No bias estimate (path, --debias): a bias PNG of an earlier render of OUT would not match.
    std::error_code ec;
    std::filesystem::remove(paths.bias_png, ec);
  }
  if (film.has_bias() && !paths.bias_png.empty()) {
    // The bias alone, its noise taken out (what the total error holds of it).
    std::vector<float> bias(total.size());
    for (size_t k = 0; k < bias.size(); ++k)
      bias[k] = std::sqrt(std::fmax(0.0f, total[k] * total[k] - rgb[k] * rgb[k]));
    write_png_display(paths.bias_png, relative_false_colour(film, bias));
  }
}

}  // namespace bpm
