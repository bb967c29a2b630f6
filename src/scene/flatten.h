// Turns the parsed scene into what rendering needs: the render scene (flat arrays + Embree), the
// camera, film and filter settings, and the Integrator directive (each integrator reads its own
// parameters from it). Every value is
// read with pbrt-v4's meaning; what bpm cannot render faithfully is an error, never a silently
// different image.
#pragma once
#include <string>

#include "camera/camera.h"
#include "film/film.h"
#include "film/filter.h"
#include "scene/parsed_scene.h"
#include "scene/render_scene.h"

namespace bpm {

struct FilmSettings {
  // The image rendered: width x height pixels, the crop of the camera's full_width x full_height
  // raster whose top-left pixel is (x0, y0) (pbrt-v4's "cropwindow" or "pixelbounds"; the whole
  // raster without them).
  int width = 1280, height = 720;
  int full_width = 1280, full_height = 720, x0 = 0, y0 = 0;
  // The crop as the file gives it: a window in [0, 1]^2 (x0 x1 y0 y1) or pixel bounds of the
  // file's resolution; set_full_resolution keeps it for another resolution.
  float crop_window[4] = {0, 1, 0, 1};
  int pixel_bounds[4] = {0, 0, 0, 0};
  bool has_pixel_bounds = false;
  int file_width = 1280, file_height = 720;
  // Sets the camera's raster and the image's crop of it.
  void set_full_resolution(int w, int h);
  Raster raster() const { return {width, height, full_width, full_height, x0, y0}; }
  bool has_crop() const {
    return has_pixel_bounds || crop_window[0] != 0 || crop_window[1] != 1 || crop_window[2] != 0 ||
           crop_window[3] != 1;
  }
  // The raster of a film of w x h pixels: the file's crop when it has one of that size, else a
  // whole raster of that size (width and height set by hand, or a film of another size).
  Raster raster_for(int w, int h) const {
    if (has_crop()) {
      FilmSettings c = *this;
      c.set_full_resolution(full_width, full_height);
      if (c.width == w && c.height == h) return c.raster();
    }
    return Raster{w, h, w, h, 0, 0};
  }
  std::string filename = "pbrt.exr";
  float imaging_ratio = 1;  // exposure time * ISO / 100, as pbrt-v4's sensor
  float max_component_value = kInf;
  float white_balance = 0;         // kelvin; 0: none (a named sensor's: 6500)
  std::string sensor = "cie1931";  // pbrt-v4's film "sensor": cie1931 or a camera's name
  SpectralBuckets spectral;        // pbrt-v4's "spectral" film; count 0 for "rgb"
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
