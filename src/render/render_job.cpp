#include "render/render_job.h"

#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <thread>

#include "base/error.h"
#include "base/memory.h"
#include "film/image_io.h"
#include "integrator/control.h"
#include "integrator/team.h"
#include "path/sensors.h"

namespace bpm {
namespace {

// Bytes per pixel the outputs take while they are written (the image, its error channels and
// their copies in the EXR writer's layout): an upper estimate.
constexpr double kOutputBytesPerPixel = 200;

// --resolution WxH replaces the Film's resolution.
void set_resolution(const std::string& resolution, FilmSettings* film) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(resolution.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 ||
      (x != 'x' && x != 'X') || w <= 0 || h <= 0 || w > 65536 || h > 65536)
    throw Error("--resolution must look like 640x480; got \"" + resolution + "\"");
  film->set_full_resolution(w, h);
}

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

}  // namespace

IntegratorSettings integrator_settings(const ParsedScene& parsed) {
  return {bpm_settings_from_file(parsed.integrator), fpm_settings_from_file(parsed.integrator)};
}

namespace {

// A parsed scene with its Integrator line's settings, timed.
template <class Parse>
SceneFile read_scene(Parse&& parse) {
  SceneFile f;
  const auto t = Clock::now();
  f.parsed = parse();
  f.settings = integrator_settings(f.parsed);
  f.parse_s = since(t);
  return f;
}

}  // namespace

SceneFile read_scene_file(const std::string& path) {
  return read_scene([&] { return parse_scene_file(path); });
}

SceneFile read_scene_text(const std::string& text, const std::string& directory) {
  return read_scene([&] { return parse_scene_string(text, directory); });
}

LoadedScene build_scene(const SceneFile& file, const RenderRequest& request) {
  LoadedScene ls = flatten_scene(file.parsed);
  if (!request.resolution.empty()) set_resolution(request.resolution, &ls.film);
  // The file's integrator decides only without --integrator; then say how it was read.
  if (request.integrator.empty() && !ls.render.integrator_note.empty())
    warning(ls.render.integrator_directive.loc, ls.render.integrator_note);
  return ls;
}

RenderOptions render_options(const RenderRequest& a, const LoadedScene& ls,
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
  if (!a.estimators.empty()) opt.bpm.combine = *parse_combine_at(a.estimators);
  if (!a.camera_connections.empty())
    opt.bpm.camera_connections = *parse_connection_mode(a.camera_connections);
  if (!a.vertex_connections.empty())
    opt.bpm.vertex_connections = *parse_connection_mode(a.vertex_connections);
  if (a.no_coat_split) opt.bpm.split_coats = false;
  if (a.no_disc_probes) opt.bpm.disc_probes = opt.fpm.disc_probes = false;
  if (a.emission_samples > 0) opt.bpm.emission_samples = a.emission_samples;
  if (a.direct_samples > 0) opt.bpm.direct_samples = a.direct_samples;
  if (a.radius >= 0) opt.bpm.radius = a.radius;
  for (PhotonSettings* p :
       {static_cast<PhotonSettings*>(&opt.bpm), static_cast<PhotonSettings*>(&opt.fpm)}) {
    if (a.k0 > 0) p->k0 = a.k0;
    if (a.k1 > 0) p->k1 = a.k1;
    if (a.alpha > 0) p->alpha = a.alpha;
    if (!a.radius_policy.empty()) {
      const std::optional<RadiusPolicy> policy = parse_radius_policy(a.radius_policy);
      if (!policy)
        throw Error("--radius-policy must be fixed, progressive or perpixel, not \"" +
                    a.radius_policy + "\"");
      p->radius_policy = *policy;
    }
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
  if (!a.sensor_lines.empty())
    opt.sensors = parse_sensors(a.sensor_lines, a.sensors);
  else if (!a.sensors.empty())
    opt.sensors = read_sensors(a.sensors);
  if (a.no_image && a.sensors.empty()) throw Error("--no-image needs --sensors");
  opt.image = !a.no_image;
  return opt;
}

void record_outputs(const RenderRequest& a, const RenderOptions& opt, const Film& film,
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

nlohmann::json run_record(const RenderRequest& a, const LoadedScene& ls, const RenderOptions& opt,
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

OutputPaths checked_output_paths(const RenderRequest& a, const FilmSettings& film) {
  std::string out = a.output;
  if (out.empty()) out = std::filesystem::path(film.filename).stem().string() + ".exr";
  OutputPaths paths = output_paths(out);
  auto dir = std::filesystem::path(paths.exr).parent_path();
  if (!dir.empty() && !std::filesystem::is_directory(dir))
    throw Error("output folder \"" + dir.string() + "\" does not exist");
  return paths;
}

void check_film_memory(const RenderRequest& a, const LoadedScene& ls, const RenderOptions& opt,
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

void write_outputs(const FilmSettings& settings, const RenderOptions& opt, const Film& film,
                   const OutputPaths& paths) {
  const Raster r = settings.raster_for(film.width(), film.height());
  const DisplayWindow window{r.x0, r.y0, r.full_width, r.full_height};
  if (opt.image) write_images(paths, film, settings.imaging_ratio, window);
  if (opt.sensors.empty()) return;
  std::vector<std::array<float, 6>> sensors;
  for (const Sensor& s : opt.sensors) sensors.push_back({s.p.x, s.p.y, s.p.z, s.n.x, s.n.y, s.n.z});
  write_sensors_csv(paths.sensors, film, sensors);
  write_sensors_png(paths.sensors_png, film, sensor_grids(opt.sensors));
}

void write_intermediate(const RenderRequest& a, const LoadedScene& ls, const RenderOptions& opt,
                        const Film& film, const OutputPaths& paths, int passes) {
  write_outputs(ls.film, opt, film, paths);
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
}  // namespace bpm
