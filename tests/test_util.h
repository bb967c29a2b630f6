// Helpers shared by the scene-level tests.
#pragma once
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "film/film.h"
#include "film/image_io.h"
#include "render/renderer.h"
#include "scene/flatten.h"
#include "scene/parsed_scene.h"

namespace bpm::test {

inline LoadedScene load(const std::string& text) { return flatten_scene(parse_scene_string(text)); }

// The albedo-1 furnace filled with a medium: a sphere of radius 1.5 whose wall emits radiance 1
// (both sides) and reflects nothing, filled with a medium of the given "rgb sigma_s" values that
// absorbs nothing (g 0.6), the camera at its centre in the medium (fov 60, res x res pixels, box
// filter, maxdepth 100). With any sigma_s the radiance inside is 1 everywhere and in every
// direction, however often light scatters. albedo_one_furnace_of takes the whole medium (its
// MakeNamedMedium parameters); any medium that absorbs nothing keeps that radiance.
inline std::string albedo_one_furnace_of(const std::string& medium_params, int res) {
  const std::string r = std::to_string(res);
  return "LookAt 0 0 0  0 0 1  0 1 0\nMakeNamedMedium \"fog\" " + medium_params + R"(
MediumInterface "" "fog"
Camera "perspective" "float fov" 60
Film "rgb" "integer xresolution" )" +
         r + " \"integer yresolution\" " + r + R"(
PixelFilter "box"
Integrator "path" "integer maxdepth" 100
WorldBegin
MediumInterface "fog" ""
AreaLightSource "diffuse" "rgb L" [1 1 1] "bool twosided" true
Material "diffuse" "rgb reflectance" [0 0 0]
Shape "sphere" "float radius" 1.5
)";
}

inline std::string albedo_one_furnace(const std::string& sigma_s, int res) {
  return albedo_one_furnace_of(
      "\"string type\" \"homogeneous\" \"rgb sigma_a\" [0 0 0] \"rgb sigma_s\" [" + sigma_s +
          "] \"float g\" 0.6",
      res);
}

inline Film render_film(const LoadedScene& ls, int spp, int threads = 0, uint64_t seed = 1) {
  Film film(ls.film.width, ls.film.height);
  RenderOptions opt = quiet_options(ls, ls.render.integrator, spp, seed);
  opt.threads = threads;
  render(ls, opt, &film);
  return film;
}

// A glass sphere on a floor under a small light the camera sees (so that bpm's pixels that see
// emission take more samples), in a corner of two walls: caustics, indirect light and direct
// emission in a few pixels, for tests of how renders are made (resumed, distributed).
inline std::string glass_corner_scene(int width, int height) {
  return R"(LookAt 0 1.6 -1.8  0 0.3 0.3  0 1 0
Camera "perspective" "float fov" 45
Film "rgb" "integer xresolution" )" +
         std::to_string(width) + " \"integer yresolution\" " + std::to_string(height) + R"(
PixelFilter "box"
Integrator "path" "integer maxdepth" 5
WorldBegin
AttributeBegin
AreaLightSource "diffuse" "rgb L" [40 40 40] "bool twosided" true
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [-0.3 1.1 1.1  0.3 1.1 1.1  0.3 1.1 1.4  -0.3 1.1 1.4]
AttributeEnd
Material "diffuse" "rgb reflectance" [0.7 0.6 0.5]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [-2 0 -2  2 0 -2  2 0 2  -2 0 2]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [-2 0 1.5  2 0 1.5  2 2.5 1.5  -2 2.5 1.5]
AttributeBegin
Material "dielectric" "float eta" 1.5
Translate 0 0.4 0.4
Shape "sphere" "float radius" 0.4
AttributeEnd
)";
}

// An environment image written to a temporary EXR: a dim gradient, a bright patch in the upper
// hemisphere of the light's frame and a brighter one below it.
inline std::string write_environment_exr(const std::string& name, int width, int height) {
  Image env;
  env.width = width;
  env.height = height;
  env.rgb.resize(size_t(width) * height * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      float* t = &env.rgb[(size_t(y) * width + x) * 3];
      t[0] = 0.3f + 0.4f * x / width;
      t[1] = 0.2f + 0.3f * y / height;
      t[2] = 0.5f;
    }
  auto patch = [&](int x0, int y0, float v) {
    for (int y = y0; y < y0 + 2; ++y)
      for (int x = x0; x < x0 + 2; ++x)
        for (int c = 0; c < 3; ++c) env.rgb[(size_t(y) * width + x) * 3 + c] = v;
  };
  patch(width / 2 + 1, height / 2 - 3,
        30);                  // upper hemisphere (near the square's centre, or the top rows)
  patch(0, height - 2, 100);  // lower hemisphere (a corner, or the bottom rows)
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()) + ".exr");
  write_exr(path.string(), env);
  return path.string();
}

// The folder with the public scenes and pbrt-v4 references, or "" when absent.
inline std::string shared_dir() {
  std::filesystem::path p = std::filesystem::path(BPM_SOURCE_DIR) / ".." / "shared";
  return std::filesystem::is_directory(p / "scenes") ? p.lexically_normal().string() : "";
}

}  // namespace bpm::test
