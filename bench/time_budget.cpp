// Whether --time holds: every scene of scenes/ (or those named) rendered by path, bpm and fpm with
// a time budget, as the command line renders (the file's settings, adaptive sampling), and the
// render stage's time (after parsing and building) printed beside the budget, with the passes, the
// stop reason and the light passes the budget cut. The first pass always completes, so a scene
// whose single pass takes longer than the budget ends later: the table shows it. Also the time
// of an iteration of scenes/slit-room.pbrt with its image-textured floor beside the same scene with
// a constant floor (--textures). Prints figures; never fails.
//   time_budget [--time S] [--scenes a,b] [--integrators path,bpm,fpm] [--textures]
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "render/renderer.h"
#include "scene/flatten.h"

using namespace bpm;
namespace fs = std::filesystem;

namespace {

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string t; std::getline(ss, t, ',');)
    if (!t.empty()) out.push_back(t);
  return out;
}

bool listed(const std::vector<std::string>& list, const std::string& name) {
  return list.empty() || std::find(list.begin(), list.end(), name) != list.end();
}

RenderStats render_for(const LoadedScene& ls, const std::string& integrator, double seconds,
                       int passes) {
  Film film(ls.film.width, ls.film.height);
  RenderOptions opt = quiet_options(ls, integrator, passes, 1);
  opt.bpm = bpm_settings_from_file(ls.render.integrator_directive);
  opt.fpm = fpm_settings_from_file(ls.render.integrator_directive);
  static_cast<PhotonSettings&>(opt.fpm) = opt.bpm;
  opt.time_limit_s = seconds;
  opt.adaptive = true;
  return render(ls, opt, &film);
}

int light_passes_cut(const RenderStats& st) {
  if (!st.details.contains("light") || !st.details["light"].contains("iterations_cut")) return 0;
  return st.details["light"]["iterations_cut"].get<int>();
}

void budgets(double seconds, const std::vector<std::string>& scenes,
             const std::vector<std::string>& integrators) {
  std::vector<fs::path> files;
  for (const auto& f : fs::directory_iterator(fs::path(BPM_SOURCE_DIR) / "scenes"))
    if (f.path().extension() == ".pbrt" && f.path().filename().string()[0] != '.' &&
        listed(scenes, f.path().stem().string()))
      files.push_back(f.path());
  std::sort(files.begin(), files.end());
  std::printf("== --time %.0f s: the render stage's time ==\n", seconds);
  std::printf("  %-22s %-6s %9s %7s %8s %10s %8s\n", "scene", "", "render s", "over s", "passes",
              "stop", "cut");
  double worst = 0;
  for (const fs::path& file : files) {
    LoadedScene ls = flatten_scene(parse_scene_file(file.string()));
    for (const std::string& integrator : integrators) {
      RenderStats st = render_for(ls, integrator, seconds, std::numeric_limits<int>::max());
      double over = st.render_seconds - seconds;
      worst = std::max(worst, over);
      std::printf("  %-22s %-6s %9.2f %7.2f %8d %10s %8d\n", file.stem().c_str(),
                  integrator.c_str(), st.render_seconds, over, st.passes, st.stop_reason.c_str(),
                  light_passes_cut(st));
    }
  }
  std::printf("  largest overrun: %.2f s (allowed: max(1 s, 5%%) = %.2f s)\n", worst,
              std::max(1.0, 0.05 * seconds));
}

// The slit room with its textured floor, and with the floor's texture replaced by a constant
// colour near the texture's mean: seconds per iteration of bpm (and of path's pass) for each.
void textures() {
  const fs::path file = fs::path(BPM_SOURCE_DIR) / "scenes" / "slit-room.pbrt";
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  std::string textured = text.str(), constant = textured;
  const std::string from = "\"texture reflectance\" \"wood\"";
  size_t at = constant.find(from);
  if (at == std::string::npos) {
    std::printf("textures: %s has no textured floor\n", file.c_str());
    return;
  }
  constant.replace(at, from.size(), "\"rgb reflectance\" [ 0.42 0.27 0.15 ]");
  std::printf("== slit-room: image-textured floor against a constant one, 2 runs each ==\n");
  std::printf("  %-10s %-6s %12s %12s %12s\n", "floor", "", "s / pass", "eye s", "light s");
  // light s: the light pass's trace and gather (its apply left out).
  for (int run = 0; run < 2; ++run)
    for (const std::string* scene : {&textured, &constant}) {
      LoadedScene ls = flatten_scene(parse_scene_string(*scene, file.parent_path().string()));
      for (const char* integrator : {"bpm", "path"}) {
        RenderStats st = render_for(ls, integrator, 0, 10);
        double eye = 0, light = 0;
        if (st.details.contains("stages_s")) {
          eye = st.details["stages_s"]["eye"].get<double>();
          light = st.details["stages_s"]["light_trace"].get<double>() +
                  st.details["stages_s"]["light_gather"].get<double>();
        }
        std::printf("  %-10s %-6s %12.3f %12.3f %12.3f\n",
                    scene == &textured ? "texture" : "constant", integrator,
                    st.render_seconds / std::max(1, st.passes), eye / std::max(1, st.passes),
                    light / std::max(1, st.passes));
      }
    }
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  double seconds = 20;
  std::vector<std::string> scenes, integrators = {"path", "bpm", "fpm"};
  bool only_textures = false;
  for (int i = 1; i < argc; ++i) {
    auto next = [&] { return i + 1 < argc ? std::string(argv[++i]) : std::string(); };
    if (!std::strcmp(argv[i], "--time")) {
      seconds = std::atof(next().c_str());
    } else if (!std::strcmp(argv[i], "--scenes")) {
      scenes = split(next());
    } else if (!std::strcmp(argv[i], "--integrators")) {
      integrators = split(next());
    } else if (!std::strcmp(argv[i], "--textures")) {
      only_textures = true;
    } else {
      bool help = !std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h");
      if (!help) std::fprintf(stderr, "time_budget: unknown argument '%s'\n", argv[i]);
      std::fprintf(help ? stdout : stderr,
                   "usage: time_budget [--time S] [--scenes a,b] [--integrators path,bpm,fpm] "
                   "[--textures]\n");
      return help ? 0 : 2;
    }
  }
  if (only_textures)
    textures();
  else
    budgets(seconds, scenes, integrators);
  return 0;
}
