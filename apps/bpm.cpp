// bpm: command-line front end. `bpm render SCENE.pbrt` renders a pbrt-v4 scene; `bpm compare A.exr
// B.exr` prints how two renders differ; `bpm luminaire FILE.ies` writes a luminaire for pbrt-v4.
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <thread>

#include "base/error.h"
#include "base/memory.h"
#include "film/image_compare.h"
#include "film/image_io.h"
#include "film/outputs.h"
#include "integrator/team.h"
#include "lights/photometric_file.h"
#include "path/sensors.h"
#include "render/checkpoint.h"
#ifdef BPM_HAVE_MPI
#include "render/mpi_team.h"
#endif
#include "render/renderer.h"
#include "scene/flatten.h"
#include "scene/parsed_scene.h"

namespace {

using namespace bpm;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

struct RenderArgs {
  std::string scene;
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
  bool debias = false;
  std::string bias_model;
  int emission_samples = 0;
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
  bool no_image = false;
};

// Bytes per pixel the outputs take while they are written (the image, its error channels and
// their copies in the EXR writer's layout): an upper estimate.
constexpr double kOutputBytesPerPixel = 200;

// The bpm statistics a user wants to see at the end of a run (all of them are in the JSON).
void print_bpm_summary(const nlohmann::json& d) {
  const auto &eye = d["eye"], &light = d["light"], &maps = d["maps"], &st = d["stages_s"];
  std::fprintf(
      stderr,
      "bpm: eye: %.3g rays, %.3g backward photons (%.3f per eye path), %.2f Mrays/s\n"
      "bpm: maps: %.1f MB photons, %.1f MB trees (peak), build %.2f s, sphere duplication %.2f\n"
      "bpm: light: %.3g photons, %.3g rays, %.2f Mrays/s, %.3g queries (%.2f M/s), %.1f "
      "batches/iteration, "
      "%.2f of the last backward photons hit\n"
      "bpm: stages: eye %.2f s, trees %.2f s, light trace %.2f + gather %.2f + apply %.2f s, "
      "accumulate %.2f s\n",
      double(eye["camera_rays"].get<uint64_t>() + eye["bounce_rays"].get<uint64_t>() +
             eye["shadow_rays"].get<uint64_t>()),
      double(eye["backward_photons"].get<uint64_t>()),
      eye["backward_photons_per_backward_ray"].get<double>(),
      eye["rays_per_second"].get<double>() * 1e-6, maps["peak_photon_bytes"].get<double>() * 1e-6,
      maps["peak_tree_bytes"].get<double>() * 1e-6, maps["tree_build_s"].get<double>(),
      maps["mean_sphere_duplication"].get<double>(), double(light["photons"].get<uint64_t>()),
      double(light["light_rays"].get<uint64_t>()), light["rays_per_second"].get<double>() * 1e-6,
      double(light["queries"].get<uint64_t>()), light["queries_per_second"].get<double>() * 1e-6,
      light["batches_per_iteration"].get<double>(), light["coverage_mean"].get<double>(),
      st["eye"].get<double>(), st["tree_build"].get<double>(), st["light_trace"].get<double>(),
      st["light_gather"].get<double>(), st["light_apply"].get<double>(),
      st["accumulate"].get<double>());
}

void print_fpm_summary(const nlohmann::json& d) {
  const auto &light = d["light"], &maps = d["maps"], &st = d["stages_s"];
  std::fprintf(
      stderr,
      "bpm: fpm light: %.3g photons, %.3g rays, %.3g photons stored (%.3f per photon path, a "
      "forward ray), %.2f Mrays/s\n"
      "bpm: fpm maps: %.1f MB photons, %.1f MB trees (peak), build %.2f s\n"
      "bpm: fpm stages: light %.2f s, trees %.2f s, eye %.2f s\n",
      double(light["photons"].get<uint64_t>()), double(light["light_rays"].get<uint64_t>()),
      double(light["photons_stored"].get<uint64_t>()),
      light["photons_per_forward_ray"].get<double>(), light["rays_per_second"].get<double>() * 1e-6,
      maps["peak_photon_bytes"].get<double>() * 1e-6, maps["peak_tree_bytes"].get<double>() * 1e-6,
      maps["tree_build_s"].get<double>(), st["light"].get<double>(), st["tree_build"].get<double>(),
      st["eye"].get<double>());
}

// --resolution WxH replaces the Film's resolution.
void set_resolution(const std::string& resolution, FilmSettings* film) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(resolution.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 ||
      (x != 'x' && x != 'X') || w <= 0 || h <= 0 || w > 65536 || h > 65536)
    throw Error("--resolution must look like 640x480; got \"" + resolution + "\"");
  film->set_full_resolution(w, h);
}

// The photon methods' settings on the file's Integrator line, read (and checked) right after
// parsing, before the scene is built.
struct IntegratorSettings {
  BpmSettings bpm;
  FpmSettings fpm;
};

// The scene file's settings, each overridden by its flag where one was given.
RenderOptions render_options(const RenderArgs& a, const LoadedScene& ls,
                             const IntegratorSettings& file) {
  RenderOptions opt;
  opt.integrator = a.integrator.empty() ? ls.render.integrator : a.integrator;
  opt.spp = a.spp > 0 ? a.spp : ls.render.spp;
  opt.time_limit_s = a.time;
  opt.threads = a.threads;
  // The images at the end (and at --write-every) compress on as many threads as the render runs.
  set_exr_threads(a.threads > 0 ? a.threads : int(std::thread::hardware_concurrency()));
  opt.seed = a.seed >= 0 ? uint64_t(a.seed) : uint64_t(ls.render.seed);
  opt.max_depth = a.max_depth >= 0 ? a.max_depth : ls.render.max_depth;
  opt.progress = !a.quiet;
  opt.equiangular = !a.no_equiangular;
  if (a.iterations > 0) opt.spp = a.iterations;  // one eye sample per pixel per iteration
  if (a.time > 0 && a.spp <= 0 && a.iterations <= 0)
    opt.spp = std::numeric_limits<int>::max();  // the time budget decides
  opt.bpm = file.bpm;
  opt.fpm = file.fpm;
  // Both photon methods read the same photon parameters from an Integrator line of either.
  static_cast<PhotonSettings&>(opt.fpm) = opt.bpm;
  if (a.diffuse_depth >= 0) opt.bpm.diffuse_depth = a.diffuse_depth;
  if (!a.tree.empty()) opt.bpm.centre_tree = a.tree == "centres";
  if (a.no_guide) opt.bpm.guide_emission = false;
  if (a.split_in_media) opt.bpm.split_in_media = true;
  if (a.no_disc_probes) opt.bpm.disc_probes = opt.fpm.disc_probes = false;
  if (a.emission_samples > 0) opt.bpm.emission_samples = a.emission_samples;
  if (a.radius >= 0) opt.bpm.radius = a.radius;
  for (PhotonSettings* p :
       {static_cast<PhotonSettings*>(&opt.bpm), static_cast<PhotonSettings*>(&opt.fpm)}) {
    if (a.k0 > 0) p->k0 = a.k0;
    if (a.k1 > 0) p->k1 = a.k1;
    if (a.alpha > 0) p->alpha = a.alpha;
    if (!a.radius_policy.empty())
      p->radius_policy =
          a.radius_policy == "fixed" ? RadiusPolicy::kFixed : RadiusPolicy::kProgressive;
    if (a.photons > 0) p->photons_per_iteration = a.photons;
    if (!a.bias_model.empty())
      p->bias_model = a.bias_model == "r2" ? BiasModel::kSquare : BiasModel::kSquareAndLinear;
  }
  if (a.final_gather) opt.fpm.final_gather = true;
  if (a.debias) opt.bpm.debias = opt.fpm.debias = true;
  if (a.knn >= 0) opt.fpm.knn = a.knn;

  opt.accuracy = a.accuracy;
  if (a.accuracy > 0 && a.spp <= 0 && a.iterations <= 0)
    opt.spp = std::numeric_limits<int>::max();  // delta decides
  opt.adaptive = !a.no_adaptive;
  opt.adaptive_floor = a.adaptive_floor;
  opt.write_every_s = a.write_every;
  opt.memory_budget = a.memory.empty() ? default_memory_budget() : parse_memory_size(a.memory);
  if (!a.sensors.empty()) opt.sensors = read_sensors(a.sensors);
  if (a.no_image && a.sensors.empty()) throw Error("--no-image needs --sensors");
  opt.image = !a.no_image;
  return opt;
}

struct StageSeconds {
  double parse, build, write;
};

// What each channel of OUT.exr holds, in which unit (docs/USAGE.md, Outputs).
nlohmann::json image_units(bool bias) {
  const char* image =
      "linear sRGB of the spectral radiance times settings.imaging_ratio (iso / 100 "
      "x shutter time), as pbrt-v4's rgb film";
  nlohmann::json u = {{"R, G, B", image},
                      {"rms.R, rms.G, rms.B, rms, rms_m_images*", "the image's"},
                      {"luminance.Y", "cd/m^2 (without the imaging ratio)"},
                      {"rms.Y", "cd/m^2"},
                      {"passes", "samples"},
                      {"result.relative_error_delta*", "relative (0.01 is 1%)"}};
  if (bias) {
    u["bias.R, bias.G, bias.B, total_error.R, total_error.G, total_error.B"] = "the image's";
    u["bias.Y, total_error.Y"] = "cd/m^2";
  }
  return u;
}

// The grids among the sensors, for OUT.sensors.png.
std::vector<SensorGrid> sensor_grids(const std::vector<Sensor>& sensors) {
  std::vector<SensorGrid> grids;
  for (size_t i = 0; i < sensors.size(); ++i)
    if (sensors[i].grid_nu > 0 && sensors[i].grid_k == 0)
      grids.push_back({i, int(sensors[i].grid_nu), int(sensors[i].grid_nv)});
  return grids;
}

// The record's outputs (the files written) and sensors.
void record_outputs(const RenderArgs& a, const RenderOptions& opt, const Film& film,
                    const OutputPaths& paths, nlohmann::json* rec) {
  nlohmann::json& out = (*rec)["outputs"];
  out = {{"json", paths.json}};
  if (opt.image) {
    out["exr"] = paths.exr;
    out["png"] = paths.png;
    out["error_png"] = paths.error_png;
    out["luminance_png"] = paths.luminance_png;
    if (film.has_bias()) out["bias_png"] = paths.bias_png;
  }
  if (opt.sensors.empty()) return;
  out["sensors_csv"] = paths.sensors;
  if (!sensor_grids(opt.sensors).empty()) out["sensors_png"] = paths.sensors_png;
  (*rec)["sensors"] = {
      {"file", a.sensors},
      {"count", opt.sensors.size()},
      {"samples_per_pass", kSensorSamplesPerPass},
      {"unit", "lux"},
      {"method", opt.integrator == "path"
                     ? "path: next-event estimation and a cosine-distributed path at each "
                       "sensor, in every pass"
                     : opt.integrator +
                           ": the path tracer's estimate at each sensor less the light "
                           "that reaches it through traced lobes only, and that light (caustics) "
                           "from the caustic photons reaching a disc about it of a backward "
                           "photon's radius (at most half a grid cell), in every iteration"}};
}

// The JSON record of a finished render: how the image was made and what it cost.
nlohmann::json run_record(const RenderArgs& a, const LoadedScene& ls, const RenderOptions& opt,
                          const RenderStats& st, const Film& film, const OutputPaths& paths,
                          StageSeconds t) {
  double t_parse = t.parse, t_build = t.build, t_write = t.write;
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  unsigned threads = opt.threads > 0 ? unsigned(opt.threads) : std::thread::hardware_concurrency();
  nlohmann::json rec;
  rec["scene"] = a.scene;
  rec["settings"] = {{"integrator", opt.integrator},
                     {"integrator_in_file", ls.render.integrator_as_written},
                     {"spp_requested", opt.spp == std::numeric_limits<int>::max() ? -1 : opt.spp},
                     {"time_limit_s", opt.time_limit_s},
                     {"memory_budget_bytes", opt.memory_budget},
                     {"accuracy", opt.accuracy},
                     {"adaptive", opt.adaptive},
                     {"adaptive_floor", opt.adaptive_floor},
                     {"write_every_s", opt.write_every_s},
                     {"threads", threads},
                     {"seed", opt.seed},
                     {"max_depth", opt.max_depth},
                     {"equiangular", opt.equiangular},
                     {"width", ls.film.width},
                     {"height", ls.film.height},
                     {"filter", Filter(ls.filter).name()},
                     {"filter_radius", {ls.filter.radius.x, ls.filter.radius.y}},
                     {"imaging_ratio", ls.film.imaging_ratio},
                     {"sensor", ls.film.sensor},
                     {"white_balance", ls.film.white_balance}};
  if (!st.details.is_null()) rec[opt.integrator] = st.details;
  double mean_samples = 0;
  for (float c : film.pass_counts()) mean_samples += c;
  mean_samples /= double(std::max<size_t>(1, size_t(film.width()) * film.height()));
  rec["result"] = {{"passes", st.passes},
                   {"iterations", st.passes},
                   {"samples_per_pixel_mean", mean_samples},
                   {"stop_reason", st.stop_reason},
                   {"mean_sampling_probability", st.mean_sampling_probability},
                   {"relative_error_delta", st.relative_error},
                   {"relative_error_delta_bias", film.relative_error_bias()},
                   {"relative_error_delta_total", film.relative_error_total()},
                   {"dropped_samples", film.dropped_samples()},
                   {"relative_error_delta_luminance", film.relative_error_luminance()},
                   {"m_images", film.m_images()},
                   {"relative_error_delta_m_images", film.relative_error_m_images()}};
  if (film.sensor_count() > 0)
    rec["result"]["relative_error_delta_sensors"] = film.sensor_relative_error();
  const std::vector<float> y = film.luminance_image();
  double y_sum = 0;
  for (float v : y) y_sum += v;
  rec["result"]["luminance_mean_cd_per_m2"] = y.empty() ? 0.0 : y_sum / double(y.size());
  rec["units"] = image_units(film.has_bias());
  rec["rays"] = {
      {"camera", st.rays.camera_rays},
      {"bounce", st.rays.bounce_rays},
      {"shadow", st.rays.shadow_rays},
      {"light", st.light_rays},
      {"total", st.total_rays()},
      {"per_second", st.render_seconds > 0 ? double(st.total_rays()) / st.render_seconds : 0.0}};
  rec["scene_stats"] = {{"objects", ls.scene.objects.size()},
                        {"triangles", ls.scene.triangle_count()},
                        {"lights", ls.scene.lights.size()},
                        {"materials", ls.scene.materials.size()},
                        {"warnings", warning_count()}};
  rec["peak_memory_bytes"] = uint64_t(ru.ru_maxrss) * 1024;
  record_outputs(a, opt, film, paths, &rec);
  if (opt.resume)
    rec["resumed"] = {{"checkpoint", a.resume},
                      {"passes_before", opt.resume->passes},
                      {"note", "rays, times and statistics are this run's alone"}};
  if (opt.save_state) rec["outputs"]["checkpoint"] = paths.checkpoint;
  if (opt.team) {
    rec["settings"]["processes"] = opt.team->size();
    rec["processes"] = st.processes;
  }
  rec["stages_s"] = {{"parse", t_parse},
                     {"build", t_build},
                     {"render", st.render_seconds},
                     {"write_images", t_write}};
  return rec;
}

// The scene file read and flattened, with the photon methods' settings from its Integrator line
// (read and checked right after parsing, before the scene is built).
struct SceneRead {
  ParsedScene parsed;
  IntegratorSettings file;
  LoadedScene ls;
  double parse_s = 0, build_s = 0;
};

SceneRead read_scene(const RenderArgs& a) {
  SceneRead r;
  auto t = Clock::now();
  r.parsed = parse_scene_file(a.scene);
  r.file = {bpm_settings_from_file(r.parsed.integrator),
            fpm_settings_from_file(r.parsed.integrator)};
  r.parse_s = seconds_since(t);
  t = Clock::now();
  r.ls = flatten_scene(r.parsed);
  r.build_s = seconds_since(t);
  if (!a.resolution.empty()) set_resolution(a.resolution, &r.ls.film);
  // The file's integrator decides only without --integrator; then say how it was read.
  if (a.integrator.empty() && !r.ls.render.integrator_note.empty())
    warning(r.ls.render.integrator_directive.loc, r.ls.render.integrator_note);
  return r;
}

// The output paths, from -o or the Film's filename; fails before rendering when the output folder
// does not exist.
OutputPaths checked_output_paths(const RenderArgs& a, const LoadedScene& ls) {
  std::string out = a.output;
  if (out.empty()) out = std::filesystem::path(ls.film.filename).stem().string() + ".exr";
  OutputPaths paths = output_paths(out);
  auto dir = std::filesystem::path(paths.exr).parent_path();
  if (!dir.empty() && !std::filesystem::is_directory(dir))
    throw Error("output folder \"" + dir.string() + "\" does not exist");
  return paths;
}

// The film and the images written from it (and a checkpoint's copy of the film, when one is kept;
// with other processes, the film process 0 receives and the one it adds) must fit before
// anything is allocated.
void check_film_memory(const RenderArgs& a, const LoadedScene& ls, const RenderOptions& opt,
                       bool keep_checkpoint, bool team) {
  const double pixels = double(ls.film.width) * double(ls.film.height);
  check_memory("a " + std::to_string(ls.film.width) + "x" + std::to_string(ls.film.height) +
                   " film with its outputs",
               pixels * ((double(Film::bytes_per_pixel(a.m_images)) +
                          // a spectral film's sums, and its channels in the outputs
                          double(ls.film.spectral.count) * (2 * sizeof(double))) *
                             (1 + (keep_checkpoint ? 1 : 0) + (team ? 2 : 0)) +
                         kOutputBytesPerPixel + double(ls.film.spectral.count) * sizeof(float)),
               opt.memory_budget, "lower --resolution or --m-images, or raise --memory");
}

// --resume: the checkpoint, checked against this render; the film's sums are process 0's alone
// (the others' films hold their passes until a round ends); every process takes the render state.
void resume_from(const RenderArgs& a, const nlohmann::json& identity, bool root,
                 Checkpoint* resumed, Film* film, RenderOptions* opt) {
  *resumed = read_checkpoint(a.resume);
  check_identity(resumed->identity, identity, a.resume);
  ByteReader r(resumed->film, "checkpoint \"" + a.resume + "\"");
  if (root) film->load(r);
  std::vector<uint8_t>().swap(resumed->film);
  opt->resume = &resumed->state;
  if (!a.quiet)
    std::fprintf(stderr, "bpm: resuming %s after %d %s\n", a.resume.c_str(), resumed->state.passes,
                 opt->integrator == "path" ? "passes" : "iterations");
}

// The images (unless --no-image), the sensors' CSV and the picture of their grids (with
// --sensors), each atomically.
void write_outputs(const LoadedScene& ls, const RenderOptions& opt, const Film& film,
                   const OutputPaths& paths) {
  const Raster r = ls.film.raster_for(film.width(), film.height());
  const DisplayWindow window{r.x0, r.y0, r.full_width, r.full_height};
  if (opt.image) write_images(paths, film, ls.film.imaging_ratio, window);
  if (opt.sensors.empty()) return;
  std::vector<std::array<float, 6>> sensors;
  for (const Sensor& s : opt.sensors) sensors.push_back({s.p.x, s.p.y, s.p.z, s.n.x, s.n.y, s.n.z});
  write_sensors_csv(paths.sensors, film, sensors);
  write_sensors_png(paths.sensors_png, film, sensor_grids(opt.sensors));
}

// Intermediate outputs: the images so far and a JSON record that says the render is running.
void write_intermediate(const RenderArgs& a, const LoadedScene& ls, const RenderOptions& opt,
                        const Film& film, const OutputPaths& paths, int passes) {
  write_outputs(ls, opt, film, paths);
  nlohmann::json rec;
  rec["scene"] = a.scene;
  rec["settings"] = {
      {"integrator", opt.integrator}, {"seed", opt.seed}, {"max_depth", opt.max_depth}};
  rec["result"] = {{"passes", passes},
                   {"stop_reason", "running"},
                   {"relative_error_delta", film.relative_error()},
                   {"relative_error_delta_total", film.relative_error_total()}};
  write_text_atomic(paths.json, rec.dump(2) + "\n");
}

// What a finished render prints on stderr.
void print_result(const RenderArgs& a, const RenderOptions& opt, const RenderStats& st,
                  const Film& film, const OutputPaths& paths) {
  if (film.dropped_samples() > 0)
    std::fprintf(stderr,
                 "bpm: warning: %llu samples had a non-finite or negative value (a numerical "
                 "accident) and were recorded as black (result.dropped_samples in the JSON)\n",
                 (unsigned long long)film.dropped_samples());
  if (a.quiet) return;
  if (opt.integrator == "bpm") print_bpm_summary(st.details);
  if (opt.integrator == "fpm") print_fpm_summary(st.details);
  char bias[64] = "";
  if (film.has_bias())
    std::snprintf(bias, sizeof bias, " (noise %.4f, bias %.4f)", st.relative_error,
                  film.relative_error_bias());
  char sensors[48] = "";
  if (film.sensor_count() > 0)
    std::snprintf(sensors, sizeof sensors, ", sensors' delta %.4f", film.sensor_relative_error());
  std::fprintf(stderr, "bpm: %d %s in %.2f s (%s), %.2f Mrays/s, delta %.4f%s%s -> %s\n", st.passes,
               opt.integrator == "path" ? "spp" : "iterations", st.render_seconds,
               st.stop_reason.c_str(),
               st.render_seconds > 0 ? st.total_rays() / st.render_seconds * 1e-6 : 0.0,
               film.relative_error_total(), bias, sensors,
               opt.image ? paths.exr.c_str() : paths.sensors.c_str());
}

// With several processes (mpirun), process 0 alone prints and writes; the others render.
int run_render(RenderArgs a, Team* team, bool* rendering) {
  const bool root = !team || team->rank() == 0;
  if (!root) a.quiet = true;
  const SceneRead scene = read_scene(a);
  const LoadedScene& ls = scene.ls;
  RenderOptions opt = render_options(a, ls, scene.file);
  const OutputPaths paths = checked_output_paths(a, ls);
  if (!a.quiet)
    std::fprintf(stderr, "bpm: %s: %zu objects, %zu triangles, %zu lights, %dx%d, integrator %s\n",
                 a.scene.c_str(), ls.scene.objects.size(), ls.scene.triangle_count(),
                 ls.scene.lights.size(), ls.film.width, ls.film.height, opt.integrator.c_str());
  // A checkpoint is kept when outputs are written as the render goes, or when it resumes one
  // (so that it can be resumed again); it is written every --write-every and at the end.
  // (Only then: its fingerprint reads every scene and data file again.)
  const bool keep_checkpoint = opt.write_every_s > 0 || !a.resume.empty();
  check_film_memory(a, ls, opt, keep_checkpoint, team != nullptr);
  Film film(ls.film.width, ls.film.height, a.m_images, opt.sensors.size());
  film.set_spectral(ls.film.spectral);
  std::vector<std::string> files = scene.parsed.files;
  if (!a.sensors.empty()) files.push_back(a.sensors);  // a checkpoint holds these sensors' sums
  const nlohmann::json identity =
      keep_checkpoint ? render_identity(files, ls, opt, film.m_images()) : nlohmann::json();
  Checkpoint resumed;
  if (!a.resume.empty()) resume_from(a, identity, root, &resumed, &film, &opt);
  if (keep_checkpoint && root)
    opt.save_state = [&](const RenderState& state) {
      const std::vector<uint8_t> bytes = encode_checkpoint(identity, film, state);
      write_bytes_atomic(paths.checkpoint, bytes.data(), bytes.size());
    };
  install_interrupt_handlers();
  if (root)
    opt.checkpoint = [&](int passes) { write_intermediate(a, ls, opt, film, paths, passes); };
  opt.team = team;
  *rendering = true;
  RenderStats st = render(ls, opt, &film);
  if (!root) return 0;

  auto t = Clock::now();
  write_outputs(ls, opt, film, paths);
  const double write_s = seconds_since(t);
  nlohmann::json rec =
      run_record(a, ls, opt, st, film, paths, {scene.parse_s, scene.build_s, write_s});
  write_text_atomic(paths.json, rec.dump(2) + "\n");
  print_result(a, opt, st, film, paths);
  return st.stop_reason == "interrupted" ? 130 : 0;
}

int run_compare(const std::string& a_path, const std::string& b_path) {
  Image a = read_exr(a_path), b = read_exr(b_path);
  if (a.width != b.width || a.height != b.height)
    throw Error("images differ in size: " + std::to_string(a.width) + "x" +
                std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                std::to_string(b.height));
  ImageComparison c = compare_images(a, b);
  const auto &ma = c.mean_a, &mb = c.mean_b;
  std::printf("mean A      %.6f %.6f %.6f\n", ma[0], ma[1], ma[2]);
  std::printf("mean B      %.6f %.6f %.6f\n", mb[0], mb[1], mb[2]);
  std::printf("mean A/B-1  %+.4f %+.4f %+.4f\n", ma[0] / mb[0] - 1, ma[1] / mb[1] - 1,
              ma[2] / mb[2] - 1);
  std::printf("relMSE      %.6f   (mean over pixels and channels of (a-b)^2/(b^2+0.01))\n",
              c.rel_mse);
  return 0;
}

// `bpm luminaire FILE`: the image and the LightSource lines with which pbrt-v4 renders the
// luminaire of a photometric file (lights/photometric_file.h), as bpm does when a goniometric
// light names the file itself.
struct LuminaireArgs {
  std::string file, output;
  int size = kLuminaireImageSize;
};

int run_luminaire(const LuminaireArgs& a) {
  const PhotometricData d = read_photometric_file(a.file);
  std::string out = a.output;
  if (out.empty()) out = std::filesystem::path(a.file).stem().string() + ".exr";
  if (std::filesystem::path(out).extension() != ".exr")
    throw Error("luminaire image \"" + out + "\" must end in .exr");
  Image img;
  img.width = img.height = a.size;
  for (float v : goniometric_image(d, a.size)) img.rgb.insert(img.rgb.end(), {v, v, v});
  write_exr(out, img);
  std::printf(
      "# %s%s%s (%s): %.6g lm, the integral of its intensities; lamps %.6g lm%s\n"
      "# The image holds candela toward each direction of pbrt-v4's goniometric light: the\n"
      "# luminaire's nadir (gamma 0) along the light's -y, C 0 along +x and C 90 along +z, so\n"
      "# that C runs counterclockwise seen from above in pbrt-v4's left-handed coordinates.\n"
      "AttributeBegin\n"
      "  Translate 0 0 0    # where the luminaire is\n"
      "  Rotate 90 1 0 0    # in a scene whose up is +z (nadir along -z, C 90 along -y); leave it\n"
      "                     # out where up is +y\n"
      "  LightSource \"goniometric\" \"string filename\" \"%s\"\n"
      "AttributeEnd\n",
      a.file.c_str(), d.name.empty() ? "" : ", ", d.name.c_str(), d.format.c_str(),
      d.luminous_flux(), d.lamp_lumens, d.lamp_lumens > 0 ? "" : " (absolute photometry)",
      out.c_str());
  return 0;
}

void add_luminaire_command(CLI::App& app, LuminaireArgs& la) {
  CLI::App* luminaire = app.add_subcommand(
      "luminaire",
      "Write the goniometric image of an IES or EULUMDAT file for pbrt-v4, and print the "
      "LightSource lines that place it");
  luminaire->add_option("file", la.file, "Photometric file (.ies or .ldt)")
      ->required()
      ->check(CLI::ExistingFile);
  luminaire->add_option("-o,--output", la.output,
                        "The image (EXR); default: the file's name with .exr, in this folder");
  luminaire
      ->add_option("--size", la.size,
                   "Side of the square image in texels (default " +
                       std::to_string(kLuminaireImageSize) + ", as bpm reads the file itself)")
      ->check(CLI::Range(16, 8192));
}

// The flags of `bpm render`, in the manual's groups (docs/USAGE.md).
const char* const kGeneral = "General";
const char* const kBudgets = "Budgets (the first one reached ends the render)";
const char* const kOutputs = "Outputs, checkpoints and the error estimate";
const char* const kBpm =
    "Backward photon mapping (--integrator bpm; the photon flags also apply to fpm)";
const char* const kFpm = "Forward photon mapping (--integrator fpm)";

void add_general_options(CLI::App* render, RenderArgs& ra) {
  render->add_option("scene", ra.scene, "Scene file (.pbrt)")->required();
  render
      ->add_option("--integrator", ra.integrator,
                   "Integrator: path, bpm or fpm; default: the scene file's")
      ->check(CLI::IsMember({"path", "bpm", "fpm"}))
      ->group(kGeneral);
  render->add_option("--resolution", ra.resolution, "Image size WxH; default: the scene file's")
      ->group(kGeneral);
  render->add_option("--threads", ra.threads, "Worker threads; default: all cores")
      ->check(CLI::Range(1, 4096))
      ->group(kGeneral);
  render
      ->add_option("--seed", ra.seed,
                   "Random seed; default: the sampler's seed in the file, else 0")
      ->check(CLI::Range(int64_t(0), int64_t(1) << 62))
      ->group(kGeneral);
  render
      ->add_option("--maxdepth", ra.max_depth,
                   "Maximum scattering events; default: the file's maxdepth (5)")
      ->check(CLI::Range(0, 100000))
      ->group(kGeneral);
  render
      ->add_flag("--no-equiangular", ra.no_equiangular,
                 "Direct light in scattering media from free-flight points only, "
                 "without equiangular sampling along the camera's rays")
      ->group(kGeneral);
  render->add_flag("-q,--quiet", ra.quiet, "No progress output")->group(kGeneral);
}

void add_budget_options(CLI::App* render, RenderArgs& ra) {
  render->add_option("--spp", ra.spp, "Samples per pixel; default: the scene file's pixelsamples")
      ->check(CLI::Range(1, 1 << 24))
      ->group(kBudgets);
  render
      ->add_option("--iterations", ra.iterations,
                   "Iterations (each one eye sample per pixel and a photon pass); same as --spp")
      ->check(CLI::Range(1, 1 << 24))
      ->group(kBudgets);
  render
      ->add_option("--time", ra.time,
                   "Time budget in seconds (stops after the pass that exceeds it)")
      ->check(CLI::Range(0.0, 1e9))
      ->group(kBudgets);
  render
      ->add_option(
          "--accuracy", ra.accuracy,
          "Stop when the image error delta (eq. 4 of the paper) is at most this, e.g. 0.01")
      ->check(CLI::Range(1e-6, 1.0))
      ->group(kBudgets);
  render
      ->add_option("--memory", ra.memory,
                   "Memory budget for the render's data (film, photon maps, trees, photon "
                   "entries), e.g. 512M or 8G; default: 3/4 of this machine's memory")
      ->group(kBudgets);
  render
      ->add_flag("--no-adaptive", ra.no_adaptive,
                 "Sample every pixel in every pass (by default pixels with a larger relative "
                 "error get more passes)")
      ->group(kBudgets);
  render
      ->add_option(
          "--adaptive-floor", ra.adaptive_floor,
          "Lowest probability of sampling a pixel in a pass under adaptive sampling (default 0.1)")
      ->check(CLI::Range(0.01, 1.0))
      ->group(kBudgets);
}

void add_output_options(CLI::App* render, RenderArgs& ra) {
  render
      ->add_option("-o,--output", ra.output,
                   "Output EXR; PNG, .error.png and .json are written beside it")
      ->group(kOutputs);
  render
      ->add_option("--write-every", ra.write_every,
                   "Write the outputs so far, and OUT.checkpoint to resume from, every SECONDS "
                   "(atomically)")
      ->check(CLI::Range(0.1, 1e9))
      ->group(kOutputs);
  render
      ->add_option("--resume", ra.resume,
                   "Go on from a checkpoint (OUT.checkpoint of --write-every) of the same "
                   "render: the same scene, resolution, integrator and settings; --spp and "
                   "--iterations count the passes before it too")
      ->group(kOutputs);
  render
      ->add_option("--sensors", ra.sensors,
                   "Illuminance sensors, one a line (x y z nx ny nz, as Radiance's rtrace -I) or a "
                   "grid (grid x y z ux uy uz vx vy vz nu nv); writes OUT.sensors.csv in lux")
      ->check(CLI::ExistingFile)
      ->group(kOutputs);
  render
      ->add_flag("--no-image", ra.no_image,
                 "Render the sensors alone: no image, no EXR or PNG (needs --sensors)")
      ->group(kOutputs);
  render
      ->add_option("--m-images", ra.m_images,
                   "Keep M intermediate images (pass j to image j mod M): the photon methods' "
                   "error estimate (2, 4 or 8), a second one for path (0: off; default 8)")
      ->check(CLI::Range(0, 64))
      ->group(kOutputs);
}

// The photon flags both photon methods read (PhotonSettings), then bpm's own.
void add_photon_options(CLI::App* render, RenderArgs& ra) {
  render->add_option("--k0", ra.k0, "Caustic radius in pixel footprints (default 1)")
      ->check(CLI::Range(1e-4, 1e4))
      ->group(kBpm);
  render
      ->add_option("--k1", ra.k1,
                   "Radius at the last diffuse vertex in pixel footprints (default 3)")
      ->check(CLI::Range(1e-4, 1e4))
      ->group(kBpm);
  render
      ->add_option("--radius-policy", ra.radius_policy, "fixed, or progressive shrinking (default)")
      ->check(CLI::IsMember({"fixed", "progressive"}))
      ->group(kBpm);
  render
      ->add_option("--alpha", ra.alpha,
                   "Progressive radius alpha: r2 *= (i+alpha)/(i+1) (default 2/3)")
      ->check(CLI::Range(1e-3, 0.999))
      ->group(kBpm);
  render
      ->add_option("--photons", ra.photons,
                   "Photons per iteration, fixed (bpm's default: chosen each round from the "
                   "variances and costs of the eye and light passes, starting from and never "
                   "above 100000 per 256x256 pixels, at least 100000; fpm's default: that count, "
                   "no more than --memory holds; file: integer photonsperiteration)")
      ->check(CLI::Range(1, 1 << 30))
      ->group(kBpm);
  render
      ->add_flag("--no-disc-probes", ra.no_disc_probes,
                 "bpm and fpm: divide the photons an estimate gathers by its whole disc, even "
                 "where a wall or an edge leaves photons part of it (file: bool discprobes false)")
      ->group(kBpm);
  render
      ->add_flag("--split-in-media", ra.split_in_media,
                 "bpm: an eye ray through a scattering medium gathers on every piece it crosses "
                 "and also goes on past it, instead of where a free flight makes it scatter "
                 "(file: bool splitinmedia true)")
      ->group(kBpm);
  render
      ->add_flag("--debias", ra.debias,
                 "bpm and fpm: record the image less its bias estimate (2 L(r/sqrt 2) - L(r) "
                 "under --bias-model r2); noisier, and without a bias estimate of its own")
      ->group(kBpm);
  render
      ->add_option("--bias-model", ra.bias_model,
                   "bpm and fpm: how the radius bias is estimated: r2 (two radii, the leading r^2 "
                   "term of a smooth density; default) or r2+r (three radii, also the r term of "
                   "edges)")
      ->check(CLI::IsMember({"r2", "r2+r"}))
      ->group(kBpm);
}

void add_bpm_options(CLI::App* render, RenderArgs& ra) {
  render
      ->add_option("--diffuse-depth", ra.diffuse_depth,
                   "Diffuse vertices before the last backward photon (0..3; default 0)")
      ->check(CLI::Range(0, 3))
      ->group(kBpm);
  add_photon_options(render, ra);
  render
      ->add_flag(
          "--no-guide", ra.no_guide,
          "Emit photons in proportion to light power only, without learning where the camera "
          "sees them (file: bool guideemission false)")
      ->group(kBpm);
  render
      ->add_option("--radius", ra.radius,
                   "Initial radius of every backward photon in scene units, in place of --k0 and "
                   "--k1 (default 0: off; file: float radius, also pbrt-v4 sppm's)")
      ->check(CLI::Range(0.0, 1e30))
      ->group(kBpm);
  render
      ->add_option("--emission-samples", ra.emission_samples,
                   "Most camera samples per iteration for light seen directly or through specular "
                   "surfaces, in pixels that show any; each pixel takes what its measured "
                   "variance pays for (default 8; file: integer emissionsamples)")
      ->check(CLI::Range(1, 1024))
      ->group(kBpm);
  render->add_option("--tree", ra.tree, "Backward photon kd-tree: spheres (default) or centres")
      ->check(CLI::IsMember({"spheres", "centres"}))
      ->group(kBpm);
}

void add_fpm_options(CLI::App* render, RenderArgs& ra) {
  render
      ->add_flag("--final-gather", ra.final_gather,
                 "Read indirect light one diffuse bounce after the first hit")
      ->group(kFpm);
  render
      ->add_option("--knn", ra.knn,
                   "Radius from the N nearest photons, capped by the k1 radius (0: off)")
      ->check(CLI::Range(0, 100000))
      ->group(kFpm);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bpm: physically based rendering with backward photon maps; reads pbrt-v4 scenes"};
  app.require_subcommand(1);
  RenderArgs ra;
  CLI::App* render = app.add_subcommand(
      "render", "Render a pbrt-v4 scene to EXR, PNGs (image, luminance, error) and JSON");
  add_general_options(render, ra);
  add_budget_options(render, ra);
  add_output_options(render, ra);
  add_bpm_options(render, ra);
  add_fpm_options(render, ra);

  std::string cmp_a, cmp_b;
  CLI::App* compare =
      app.add_subcommand("compare", "Compare two EXR images (channel means, relative MSE)");
  compare->add_option("a", cmp_a, "Image to test")->required()->check(CLI::ExistingFile);
  compare->add_option("b", cmp_b, "Reference image")->required()->check(CLI::ExistingFile);

  LuminaireArgs la;
  add_luminaire_command(app, la);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
#ifdef BPM_HAVE_MPI
  MpiSession mpi(&argc, &argv);
  Team* team = mpi.team();
#else
  Team* team = nullptr;
#endif
  // With other processes, an error in one ends them all (they would wait for it forever). Most
  // errors before the render meet every process alike (the same files and flags): the others
  // give process 0 half a second to say it and end the job, and say it themselves, naming their
  // process, when the error is theirs alone (a file missing on one machine).
  bool rendering = false;
  auto fail = [&](const char* what) {
    if (!team) {
      std::fprintf(stderr, "bpm: error: %s\n", what);
      return 1;
    }
#ifdef BPM_HAVE_MPI
    if (team->rank() == 0) {
      std::fprintf(stderr, "bpm: error: %s\n", what);
    } else {
      if (!rendering) std::this_thread::sleep_for(std::chrono::milliseconds(500));
      std::fprintf(stderr, "bpm: error (process %d): %s\n", team->rank(), what);
    }
    std::fflush(stderr);
    mpi.abort(1);
#endif
    return 1;
  };
  try {
    if (*render) return run_render(ra, team, &rendering);
    if (*compare) return run_compare(cmp_a, cmp_b);
    if (app.got_subcommand("luminaire")) return run_luminaire(la);
  } catch (const std::exception& e) {
    return fail(e.what());
  }
  return 0;
}
