// flatten_scene and the order of its steps; flatten_internal.h lists the files that define them.
#include "scene/flatten.h"

#include "scene/flatten_internal.h"
#include "scene/spectra.h"

namespace bpm {
namespace flatten_internal {

Flattener::Flattener(const ParsedScene& p) : parsed_(p) {
  for (const TextureEntity& t : p.textures) textures_[t.texture_name] = &t;
}

LoadedScene Flattener::run() {
  LoadedScene out;
  read_camera(&out);
  read_film(&out);
  read_filter(&out);
  read_sampler_and_integrator(&out);
  // Default material (pbrt-v4: diffuse, reflectance 0.5) is material 0.
  scene().materials.push_back(DiffuseDesc{});
  for (const ShapeEntity& s : parsed_.shapes) add_shape(s, &out.scene);
  for (const LightEntity& l : parsed_.lights) add_light(l, &out.scene);
  out.scene.commit();
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
