// bpm: command-line front end. `bpm render SCENE.pbrt` renders a pbrt-v4 scene; `bpm compare A.exr
// B.exr` prints how two renders differ.
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <thread>

#include "base/error.h"
#include "film/image_io.h"
#include "film/outputs.h"
#include "render/renderer.h"
#include "scene/flatten.h"
#include "scene/parsed_scene.h"

namespace {

using namespace bpm;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

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
};

int run_render(const RenderArgs& a) {
  auto t_start = Clock::now();
  ParsedScene parsed = parse_scene_file(a.scene);
  double t_parse = seconds_since(t_start);

  auto t1 = Clock::now();
  LoadedScene ls = flatten_scene(parsed);
  double t_build = seconds_since(t1);

  if (!a.resolution.empty()) {
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(a.resolution.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') ||
        w <= 0 || h <= 0 || w > 65536 || h > 65536)
      throw Error("--resolution must look like 640x480; got \"" + a.resolution + "\"");
    ls.film.width = w;
    ls.film.height = h;
  }
  RenderOptions opt;
  opt.integrator = a.integrator.empty() ? ls.render.integrator : a.integrator;
  opt.spp = a.spp > 0 ? a.spp : ls.render.spp;
  opt.time_limit_s = a.time;
  opt.threads = a.threads;
  opt.seed = a.seed >= 0 ? uint64_t(a.seed) : uint64_t(ls.render.seed);
  opt.max_depth = a.max_depth >= 0 ? a.max_depth : ls.render.max_depth;
  opt.progress = !a.quiet;
  if (a.time > 0 && a.spp <= 0) opt.spp = std::numeric_limits<int>::max();  // the time budget decides

  std::string out = a.output;
  if (out.empty()) out = std::filesystem::path(ls.film.filename).stem().string() + ".exr";
  OutputPaths paths = output_paths(out);
  // Fail before rendering when the output folder does not exist.
  auto dir = std::filesystem::path(paths.exr).parent_path();
  if (!dir.empty() && !std::filesystem::is_directory(dir))
    throw Error("output folder \"" + dir.string() + "\" does not exist");

  if (!a.quiet)
    std::fprintf(stderr, "bpm: %s: %zu objects, %zu triangles, %zu lights, %dx%d, integrator %s\n", a.scene.c_str(),
                 ls.scene.objects.size(), ls.scene.triangle_count(), ls.scene.lights.size(), ls.film.width,
                 ls.film.height, opt.integrator.c_str());
  install_interrupt_handlers();
  Film film(ls.film.width, ls.film.height);
  RenderStats st = render(ls, opt, &film);

  auto t3 = Clock::now();
  write_images(paths, film, ls.film.imaging_ratio);
  double t_write = seconds_since(t3);
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  unsigned threads = opt.threads > 0 ? unsigned(opt.threads) : std::thread::hardware_concurrency();
  nlohmann::json rec;
  rec["scene"] = a.scene;
  rec["settings"] = {{"integrator", opt.integrator},
                     {"integrator_in_file", ls.render.integrator_as_written},
                     {"spp_requested", opt.spp == std::numeric_limits<int>::max() ? -1 : opt.spp},
                     {"time_limit_s", opt.time_limit_s},
                     {"threads", threads},
                     {"seed", opt.seed},
                     {"max_depth", opt.max_depth},
                     {"width", ls.film.width},
                     {"height", ls.film.height},
                     {"filter", Filter(ls.filter).name()},
                     {"filter_radius", {ls.filter.radius.x, ls.filter.radius.y}},
                     {"imaging_ratio", ls.film.imaging_ratio}};
  rec["result"] = {{"passes", st.passes},
                   {"samples_per_pixel", st.passes},
                   {"stop_reason", st.stop_reason},
                   {"relative_error_delta", st.relative_error}};
  rec["rays"] = {{"camera", st.rays.camera_rays},
                 {"bounce", st.rays.bounce_rays},
                 {"shadow", st.rays.shadow_rays},
                 {"total", st.rays.total()},
                 {"per_second", st.render_seconds > 0 ? double(st.rays.total()) / st.render_seconds : 0.0}};
  rec["scene_stats"] = {{"objects", ls.scene.objects.size()},
                        {"triangles", ls.scene.triangle_count()},
                        {"lights", ls.scene.lights.size()},
                        {"materials", ls.scene.materials.size()},
                        {"warnings", warning_count()}};
  rec["peak_memory_bytes"] = uint64_t(ru.ru_maxrss) * 1024;
  rec["outputs"] = {{"exr", paths.exr}, {"png", paths.png}, {"error_png", paths.error_png}, {"json", paths.json}};
  rec["stages_s"] = {{"parse", t_parse}, {"build", t_build}, {"render", st.render_seconds}, {"write_images", t_write}};
  write_text_atomic(paths.json, rec.dump(2) + "\n");
  if (!a.quiet)
    std::fprintf(stderr, "bpm: %d spp in %.2f s (%s), %.2f Mrays/s, delta %.4f -> %s\n", st.passes, st.render_seconds,
                 st.stop_reason.c_str(), st.render_seconds > 0 ? st.rays.total() / st.render_seconds * 1e-6 : 0.0,
                 st.relative_error, paths.exr.c_str());
  return st.stop_reason == "interrupted" ? 130 : 0;
}

int run_compare(const std::string& a_path, const std::string& b_path) {
  Image a = read_exr(a_path), b = read_exr(b_path);
  if (a.width != b.width || a.height != b.height)
    throw Error("images differ in size: " + std::to_string(a.width) + "x" + std::to_string(a.height) + " vs " +
                std::to_string(b.width) + "x" + std::to_string(b.height));
  double ma[3] = {0, 0, 0}, mb[3] = {0, 0, 0}, rel_mse = 0;
  size_t n = size_t(a.width) * a.height;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      double x = a.rgb[3 * i + c], y = b.rgb[3 * i + c];
      ma[c] += x;
      mb[c] += y;
      rel_mse += (x - y) * (x - y) / (y * y + 0.01);
    }
  rel_mse /= 3.0 * n;
  std::printf("mean A      %.6f %.6f %.6f\n", ma[0] / n, ma[1] / n, ma[2] / n);
  std::printf("mean B      %.6f %.6f %.6f\n", mb[0] / n, mb[1] / n, mb[2] / n);
  std::printf("mean A/B-1  %+.4f %+.4f %+.4f\n", ma[0] / mb[0] - 1, ma[1] / mb[1] - 1, ma[2] / mb[2] - 1);
  std::printf("relMSE      %.6f   (mean over pixels and channels of (a-b)^2/(b^2+0.01))\n", rel_mse);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bpm: physically based rendering with backward photon maps; reads pbrt-v4 scenes"};
  app.require_subcommand(1);
  RenderArgs ra;
  CLI::App* render = app.add_subcommand("render", "Render a pbrt-v4 scene to EXR, PNG, error PNG and JSON");
  render->add_option("scene", ra.scene, "Scene file (.pbrt)")->required();
  render->add_option("--integrator", ra.integrator, "Integrator (path); default: the scene file's")
      ->check(CLI::IsMember({"path", "bpm", "fpm"}));
  render->add_option("--spp", ra.spp, "Samples per pixel; default: the scene file's pixelsamples")
      ->check(CLI::Range(1, 1 << 24));
  render->add_option("--time", ra.time, "Time budget in seconds (stops after the pass that exceeds it)")
      ->check(CLI::Range(0.0, 1e9));
  render->add_option("--resolution", ra.resolution, "Image size WxH; default: the scene file's");
  render->add_option("--threads", ra.threads, "Worker threads; default: all cores")->check(CLI::Range(1, 4096));
  render->add_option("--seed", ra.seed, "Random seed; default: the sampler's seed in the file, else 0")
      ->check(CLI::Range(int64_t(0), int64_t(1) << 62));
  render->add_option("--maxdepth", ra.max_depth, "Maximum scattering events; default: the file's maxdepth (5)")
      ->check(CLI::Range(0, 100000));
  render->add_option("-o,--output", ra.output, "Output EXR; PNG, .error.png and .json are written beside it");
  render->add_flag("-q,--quiet", ra.quiet, "No progress output");

  std::string cmp_a, cmp_b;
  CLI::App* compare = app.add_subcommand("compare", "Compare two EXR images (channel means, relative MSE)");
  compare->add_option("a", cmp_a, "Image to test")->required()->check(CLI::ExistingFile);
  compare->add_option("b", cmp_b, "Reference image")->required()->check(CLI::ExistingFile);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (*render) return run_render(ra);
    if (*compare) return run_compare(cmp_a, cmp_b);
  } catch (const bpm::Error& e) {
    std::fprintf(stderr, "bpm: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bpm: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
