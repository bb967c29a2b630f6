// flatten_scene and the order of its steps; flatten_internal.h lists the files that define them.
#include "scene/flatten.h"

#include <algorithm>
#include <cmath>

#include "scene/flatten_internal.h"
#include "scene/spectra.h"

namespace bpm {

void FilmSettings::set_full_resolution(int w, int h) {
  full_width = w;
  full_height = h;
  int b[4];
  if (has_pixel_bounds) {
    // The file's pixel bounds, scaled to this resolution when it is another.
    const int size[4] = {file_width, file_width, file_height, file_height};
    const int to[4] = {w, w, h, h};
    for (int k = 0; k < 4; ++k)
      b[k] = size[k] == to[k] ? pixel_bounds[k]
                              : int(std::ceil(double(pixel_bounds[k]) * to[k] / size[k] - 1e-9));
  } else {
    // pbrt-v4: the pixels from ceil(resolution x crop min) up to ceil(resolution x crop max), in
    // single precision as pbrt-v4 (120 x 0.2f is 24 there, 24.0000004 in double).
    for (int k = 0; k < 4; ++k) b[k] = int(std::ceil(float(k < 2 ? w : h) * crop_window[k]));
  }
  // Pixel bounds beyond the raster are clamped to it, as pbrt-v4 does.
  x0 = std::clamp(b[0], 0, w);
  y0 = std::clamp(b[2], 0, h);
  width = std::clamp(b[1], 0, w) - x0;
  height = std::clamp(b[3], 0, h) - y0;
}
namespace flatten_internal {

Flattener::Flattener(const ParsedScene& p) : parsed_(p) {
  for (const TextureEntity& t : p.textures) textures_[t.texture_name] = &t;
}

LoadedScene Flattener::run() {
  LoadedScene out;
  read_camera(&out);
  read_film(&out);
  build_lens(&out);
  read_filter(&out);
  read_sampler_and_integrator(&out);
  // Default material (pbrt-v4: diffuse, reflectance 0.5) is material 0.
  scene().materials.push_back(DiffuseDesc{});
  for (const ShapeEntity& s : parsed_.shapes) add_shape(s, &out.scene);
  for (const LightEntity& l : parsed_.lights) add_light(l, &out.scene);
  out.scene.commit();
  // A glowing medium is path's alone (the photon methods refuse it): a file integrator that maps
  // to bpm renders such a scene with path, which reaches its light, and says so.
  if (out.scene.has_emissive_media() && out.render.integrator == "bpm" &&
      out.render.integrator_as_written != "bpm") {
    out.render.integrator = "path";
    out.render.integrator_note = "integrator \"" + out.render.integrator_as_written +
                                 "\" is rendered with bpm's path tracer (\"path\"): a medium "
                                 "glows, which the photon methods do not render yet";
  }
  // Distant and infinite lights needed the scene bounds; nothing more to do after commit.
  out.data_files = data_files_;
  return out;
}

void Flattener::read_data_file(const std::string& path) {
  if (data_file_set_.insert(path).second) data_files_.push_back(path);
}

std::optional<SpectrumCurve> Flattener::spectrum_curve(const ParamSet& ps, const std::string& name,
                                                       SpectrumKind kind) {
  std::vector<std::string> files;
  auto s = get_spectrum(ps, name, kind, parsed_.base_directory, &files);
  for (const std::string& f : files) read_data_file(f);
  return s;
}

}  // namespace flatten_internal

LoadedScene flatten_scene(const ParsedScene& parsed) {
  return flatten_internal::Flattener(parsed).run();
}

}  // namespace bpm
