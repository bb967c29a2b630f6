// A render of a scene file from end to end, for whoever asks for one (the command line, the Python
// module): the request (the command line's flags), the scene read and built, the options they
// make, the files written and the JSON record of how the image was made. Both callers go through
// these functions, so that the same request gives the same image and the same record.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "film/outputs.h"
#include "render/renderer.h"
#include "scene/flatten.h"
#include "scene/parsed_scene.h"

namespace bpm {

// A render as the command line asks for it (docs/USAGE.md names each flag): a zero, negative or
// empty field means "the scene file's value, else the default".
struct RenderRequest {
  std::string scene;  // the file, as named in the record
  std::string integrator;
  int spp = 0;
  double time = 0;
  std::string resolution;
  int threads = 0;
  int64_t seed = -1;
  int max_depth = -1;
  std::string output;
  bool quiet = false;
  int iterations = 0;
  // bpm; negative or empty means "the scene file's value or the default"
  int diffuse_depth = -1;
  float k0 = -1, k1 = -1, alpha = -1;
  std::string radius_policy, tree;
  bool no_guide = false;
  bool no_disc_probes = false;
  bool no_equiangular = false;
  bool split_in_media = false;
  std::string estimators;          // bpm: "partition", "glossy", "combined" or "auto"
  std::string camera_connections;  // bpm: "on", "off" or "alone"
  std::string vertex_connections;  // bpm: "on", "off" or "alone"
  bool no_coat_split = false;
  bool debias = false;
  std::string bias_model;
  int emission_samples = 0;
  int direct_samples = 0;
  float radius = -1;
  int photons = 0;
  bool final_gather = false;
  int knn = -1;
  double accuracy = 0, write_every = 0;
  bool no_adaptive = false;
  float adaptive_floor = 0.1f;
  int m_images = 8;
  std::string memory;   // --memory; empty: default_memory_budget()
  std::string resume;   // --resume: a checkpoint file
  std::string sensors;  // --sensors: illuminance sensors
  // Or the sensors' lines themselves (the Python module's sensors=[...]); sensors names them.
  std::string sensor_lines;
  bool no_image = false;
};

// The photon methods' settings on the file's Integrator line, read (and checked) right after
// parsing, before the scene is built.
struct IntegratorSettings {
  BpmSettings bpm;
  FpmSettings fpm;
};
IntegratorSettings integrator_settings(const ParsedScene& parsed);

// A scene file parsed (following Include and Import), with its Integrator line's settings.
struct SceneFile {
  ParsedScene parsed;
  IntegratorSettings settings;
  double parse_s = 0;
};
SceneFile read_scene_file(const std::string& path);
// Scene text held in memory; relative file names resolve against directory.
SceneFile read_scene_text(const std::string& text, const std::string& directory);

// The render scene of a parsed file at the request's resolution. When the request names no
// integrator, warns how the file's Integrator line was read (once per call).
LoadedScene build_scene(const SceneFile& file, const RenderRequest& request);

// The scene file's settings, each overridden by the request's where it gives one.
RenderOptions render_options(const RenderRequest& request, const LoadedScene& ls,
                             const IntegratorSettings& file);

// The output paths, from -o or the Film's filename; fails before rendering when the output folder
// does not exist.
OutputPaths checked_output_paths(const RenderRequest& request, const FilmSettings& film);

// The film and the images written from it (and a checkpoint's copy of the film, when one is kept;
// with other processes, the film process 0 receives and the one it adds) must fit before
// anything is allocated.
void check_film_memory(const RenderRequest& request, const LoadedScene& ls,
                       const RenderOptions& opt, bool keep_checkpoint, bool team);

// The images (unless the render has none), the sensors' CSV and the picture of their grids (with
// sensors), each atomically.
void write_outputs(const FilmSettings& settings, const RenderOptions& opt, const Film& film,
                   const OutputPaths& paths);

// Intermediate outputs: the images so far and a JSON record that says the render is running.
void write_intermediate(const RenderRequest& request, const LoadedScene& ls,
                        const RenderOptions& opt, const Film& film, const OutputPaths& paths,
                        int passes);

// Seconds spent reading the file, building the scene and writing the images.
struct StageSeconds {
  double parse, build, write;
};

// The record's "outputs" (the files written) and "sensors".
void record_outputs(const RenderRequest& request, const RenderOptions& opt, const Film& film,
                    const OutputPaths& paths, nlohmann::json* rec);

// The JSON record of a finished render: how the image was made and what it cost.
nlohmann::json run_record(const RenderRequest& request, const LoadedScene& ls,
                          const RenderOptions& opt, const RenderStats& st, const Film& film,
                          const OutputPaths& paths, StageSeconds t);

}  // namespace bpm
