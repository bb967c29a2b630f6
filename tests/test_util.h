// Helpers shared by the scene-level tests.
#pragma once
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "film/film.h"
#include "render/renderer.h"
#include "scene/flatten.h"
#include "scene/parsed_scene.h"

namespace bpm::test {

inline LoadedScene load(const std::string& text) { return flatten_scene(parse_scene_string(text)); }

inline Film render_film(const LoadedScene& ls, int spp, int threads = 0, uint64_t seed = 1) {
  Film film(ls.film.width, ls.film.height);
  RenderOptions opt = quiet_options(ls, ls.render.integrator, spp, seed);
  opt.threads = threads;
  render(ls, opt, &film);
  return film;
}

// The folder with the public scenes and pbrt-v4 references, or "" when absent.
inline std::string shared_dir() {
  std::filesystem::path p = std::filesystem::path(BPM_SOURCE_DIR) / ".." / "shared";
  return std::filesystem::is_directory(p / "scenes") ? p.lexically_normal().string() : "";
}

}  // namespace bpm::test
