// Turns the parsed scene into what rendering needs: the render scene (flat arrays + Embree), the
// camera, film and filter settings, and the Integrator directive (each integrator reads its own
// parameters from it). Every value is
// read with pbrt-v4's meaning; what bpm cannot render faithfully is an error, never a silently
// different image.
#pragma once
#include <string>

#include "camera/camera.h"
#include "film/filter.h"
#include "scene/parsed_scene.h"
#include "scene/render_scene.h"

namespace bpm {

struct FilmSettings {
  int width = 1280, height = 720;
  std::string filename = "pbrt.exr";
  float imaging_ratio = 1;  // exposure time * ISO / 100, as pbrt-v4's sensor
  float max_component_value = kInf;
};

// What the scene file says about how to render it; the command line may override each field.
struct FileRenderSettings {
  std::string integrator = "path";
  std::string integrator_as_written;
  // Why the file's integrator is rendered with another of bpm's, and with what (empty when it is
  // one of bpm's own or none was named); printed unless the command line chooses.
  std::string integrator_note;
  int max_depth = 5;
  int spp = 16;
  int seed = 0;
  // The Integrator directive as written: each integrator reads its own parameters from it
  // (bpm/settings.h, fpm/settings.h).
  SceneEntity integrator_directive;
};

struct LoadedScene {
  RenderScene scene;
  CameraSettings camera;
  FilmSettings film;
  FilterSettings filter;
  FileRenderSettings render;
  // The files other than scene files that the scene's contents come from: PLY meshes, images and
  // spectra, in the order first read (ParsedScene::files has the scene files).
  std::vector<std::string> data_files;
};

LoadedScene flatten_scene(const ParsedScene& parsed);

}  // namespace bpm
