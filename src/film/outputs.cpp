#include "film/outputs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <mutex>

#include "base/error.h"
#include "film/image_io.h"
#include "film/legend.h"

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
          stem + ".sensors.csv",
          stem + ".luminance.png",
          stem + ".sensors.png"};
}

void write_sensors_csv(const std::string& path, const Film& film,
                       const std::vector<std::array<float, 6>>& sensors) {
  std::string text =
      "x,y,z,nx,ny,nz,illuminance_lux,standard_error_lux,bias_lux,total_error_lux,passes\n";
  char line[512];
  for (size_t i = 0; i < sensors.size(); ++i) {
    const std::array<float, 6>& s = sensors[i];
    std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,%.6g,%d\n", s[0],
                  s[1], s[2], s[3], s[4], s[5], film.sensor_mean(i), film.sensor_standard_error(i),
                  film.sensor_bias(i), film.sensor_total_error(i), film.sensor_passes(i));
    text += line;
  }
  write_text_atomic(path, text);
}

std::vector<float> relative_error(const Film& film, const std::vector<float>& rms) {
  const Image img = film.image();
  std::vector<float> out(img.rgb.size() / 3);
  for (size_t i = 0; i < out.size(); ++i) {
    double e2 = 0, v2 = 0;
    for (int c = 0; c < 3; ++c) {
      e2 += double(rms[3 * i + c]) * rms[3 * i + c];
      v2 += double(img.rgb[3 * i + c]) * img.rgb[3 * i + c];
    }
    out[i] = v2 > 1e-12 ? float(std::sqrt(e2 / v2)) : (e2 > 0 ? 1.0f : 0.0f);
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

// A picture of values with its legend, written atomically; legend text that could not be drawn is
// said once per process.
void write_picture(const std::string& path, const std::vector<ValueBlock>& blocks,
                   const ColourScale& scale) {
  std::string warning;
  const Image img = false_colour_picture(blocks, scale, &warning);
  static std::once_flag said;
  if (!warning.empty())
    std::call_once(said, [&] { std::fprintf(stderr, "bpm: warning: %s\n", warning.c_str()); });
  write_png_display(path, img);
}

// The relative error of each pixel, 0 to 10% and more, blue through green to red.
void write_relative_error(const std::string& path, const Film& film,
                          const std::vector<float>& error_rgb, const std::string& what) {
  const std::vector<float> rel = relative_error(film, error_rgb);
  ColourScale scale;
  scale.hi = 0.1;
  scale.ramp = ColourScale::kBlueRed;
  scale.percent = true;
  scale.title = what + " / value, linear scale";
  write_picture(path, {{&rel, film.width(), film.height()}}, scale);
}

}  // namespace

void write_sensors_png(const std::string& path, const Film& film,
                       const std::vector<SensorGrid>& grids) {
  if (grids.empty()) {
    std::error_code ec;
    std::filesystem::remove(path, ec);  // a picture of an earlier render would not match
    return;
  }
  std::vector<std::vector<float>> values;
  std::vector<float> all;
  for (const SensorGrid& g : grids) {
    std::vector<float> v(size_t(g.nu) * size_t(g.nv));
    for (int j = 0; j < g.nv; ++j)
      for (int i = 0; i < g.nu; ++i)  // v up: the last row of the grid on top
        v[size_t(g.nv - 1 - j) * size_t(g.nu) + size_t(i)] =
            float(film.sensor_mean(g.first + size_t(j) * size_t(g.nu) + size_t(i)));
    all.insert(all.end(), v.begin(), v.end());
    values.push_back(std::move(v));
  }
  std::vector<ValueBlock> blocks;
  for (size_t k = 0; k < grids.size(); ++k) {
    const int cells = std::max(grids[k].nu, grids[k].nv);
    const int zoom = std::clamp(480 / cells, 1, 64);
    blocks.push_back({&values[k], grids[k].nu, grids[k].nv, zoom, true});
  }
  write_picture(path, blocks, linear_scale(all, "illuminance, lux, linear scale"));
}

void write_images(const OutputPaths& paths, const Film& film, float imaging_ratio,
                  const DisplayWindow& window) {
  Image img = film.image(imaging_ratio);
  img.window = window;
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
  // A spectral film's buckets, named as pbrt-v4 names them (OpenEXR's spectral layout: S0. and
  // the bucket's centre with a decimal comma), with the layout's attributes.
  std::vector<std::pair<std::string, std::string>> attributes;
  const SpectralBuckets& sb = film.spectral();
  for (int b = 0; b < sb.count; ++b) {
    char name[64];
    std::snprintf(
        name, sizeof name, "%.3fnm",
        sb.lambda_min + (float(b) + 0.5f) / float(sb.count) * (sb.lambda_max - sb.lambda_min));
    std::string n = name;
    std::replace(n.begin(), n.end(), '.', ',');
    add("S0." + n, film.bucket_image(b));
  }
  if (sb.count > 0)
    attributes = {{"spectralLayoutVersion", "1.0"}, {"emissiveUnits", "W.m^-2.sr^-1"}};
  std::vector<ExtraChannel> extra;
  for (size_t k = 0; k < names.size(); ++k) extra.push_back({names[k], &values[k]});
  write_exr(paths.exr, img, extra, attributes);
  write_png(paths.png, img);
  const std::vector<float> luminance = film.luminance_image();
  write_picture(paths.luminance_png, {{&luminance, film.width(), film.height()}},
                log_scale(luminance, "luminance, cd/m^2, log scale"));
  write_relative_error(paths.error_png, film, total,
                       film.has_bias() ? "total error (noise and bias)" : "standard error");
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
    write_relative_error(paths.bias_png, film, bias, "bias estimate");
  }
}

}  // namespace bpm
