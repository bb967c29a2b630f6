#include "film/outputs.h"

#include <algorithm>
#include <cmath>

#include "base/error.h"
#include "film/image_io.h"

namespace bpm {

OutputPaths output_paths(const std::string& exr) {
  const std::string ext = ".exr";
  if (exr.size() <= ext.size() || exr.compare(exr.size() - ext.size(), ext.size(), ext) != 0)
    throw Error("output file \"" + exr + "\" must end in .exr");
  std::string stem = exr.substr(0, exr.size() - ext.size());
  return {exr, stem + ".png", stem + ".error.png", stem + ".json"};
}

Image error_false_colour(const Film& film) {
  Image img = film.image();
  std::vector<float> rms = film.rms();
  Image out;
  out.width = img.width;
  out.height = img.height;
  out.rgb.resize(img.rgb.size());
  for (size_t i = 0; i < rms.size(); ++i) {
    Rgb c(img.rgb[3 * i], img.rgb[3 * i + 1], img.rgb[3 * i + 2]);
    float lum = c.luminance();
    float rel = lum > 1e-6f ? rms[i] / lum : (rms[i] > 0 ? 1.0f : 0.0f);
    float t = std::clamp(rel / 0.1f, 0.0f, 1.0f);
    // blue (0) -> green (0.5) -> red (1)
    out.rgb[3 * i] = std::clamp(2 * t - 1, 0.0f, 1.0f);
    out.rgb[3 * i + 1] = 1 - std::fabs(2 * t - 1);
    out.rgb[3 * i + 2] = std::clamp(1 - 2 * t, 0.0f, 1.0f);
  }
  return out;
}

void write_images(const OutputPaths& paths, const Film& film, float imaging_ratio) {
  Image img = film.image(imaging_ratio);
  std::vector<float> rms = film.rms();
  for (float& r : rms) r *= imaging_ratio;
  std::vector<float> passes = film.pass_counts();
  std::vector<float> rms_m = film.rms_m_images();
  for (float& r : rms_m) r *= imaging_ratio;
  if (film.m_images() > 0)
    write_exr(paths.exr, img, {{"rms", &rms}, {"passes", &passes}, {"rms_m_images", &rms_m}});
  else
    write_exr(paths.exr, img, {{"rms", &rms}, {"passes", &passes}});
  write_png(paths.png, img);
  write_png_display(paths.error_png, error_false_colour(film));
}

}  // namespace bpm
