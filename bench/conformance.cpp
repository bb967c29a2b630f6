// Scene conformance: renders every scene file of ../shared/scenes with path, bpm and fpm at a
// small resolution and prints, per scene, the mean of each channel and, where ../shared/references
// holds a pbrt-v4 render of that scene, the ratio of our channel means to pbrt-v4's and the
// relative MSE (mean over pixels and channels of (a - b)^2 / (b^2 + 0.01)) against it. Then each
// of the project's own scenes (scenes/*.pbrt) with path, bpm and fpm (N samples per pixel or N
// iterations) against pbrt-v4 rendered on the spot at N samples per pixel, where
// ../shared/tools/pbrt-v4/pbrt exists. A scene bpm cannot render prints the error it reports.
// Prints figures; never fails.
//   conformance [--shared DIR] [--spp N] [--width W] [--only shared|own]
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "base/error.h"
#include "film/image_compare.h"
#include "film/image_io.h"
#include "render/renderer.h"
#include "scene/flatten.h"

using namespace bpm;
namespace fs = std::filesystem;

namespace {

struct Reference {
  fs::path path;
  int width = 0, height = 0, spp = 0;
};

// The pbrt-v4 reference of a scene folder with the most samples: <scene>-path-<W>x<H>-<N>spp.exr.
std::optional<Reference> find_reference(const fs::path& dir, const std::string& scene) {
  std::optional<Reference> best;
  if (!fs::is_directory(dir)) return best;
  for (const auto& e : fs::directory_iterator(dir)) {
    std::string name = e.path().filename().string();
    Reference r;
    r.path = e.path();
    std::string prefix = scene + "-path-";
    if (name.rfind(prefix, 0) != 0 || e.path().extension() != ".exr") continue;
    if (std::sscanf(name.c_str() + prefix.size(), "%dx%d-%dspp", &r.width, &r.height, &r.spp) != 3)
      continue;
    if (!best || r.spp > best->spp) best = r;
  }
  return best;
}

// One row of the own scenes' table: the scene rendered by `integrator` at its own resolution,
// against pbrt-v4's render when there is one.
void own_scene_row(const fs::path& file, const std::string& integrator, int spp,
                   const std::optional<Image>& pbrt) {
  const std::string label = "scenes/" + file.filename().string();
  try {
    LoadedScene ls = flatten_scene(parse_scene_file(file.string()));
    RenderOptions opt = quiet_options(ls, integrator, spp);
    Film film(ls.film.width, ls.film.height);
    auto t0 = std::chrono::steady_clock::now();
    render(ls, opt, &film);
    double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    Image img = film.image(ls.film.imaging_ratio);
    auto m = channel_means(img);
    std::printf("| %s | %s | %.1f | %.4f %.4f %.4f |", label.c_str(), integrator.c_str(), secs,
                m[0], m[1], m[2]);
    if (pbrt && pbrt->width == img.width && pbrt->height == img.height) {
      ImageComparison c = compare_images(img, *pbrt);
      const auto& mr = c.mean_b;
      std::printf(" %.4f %.4f %.4f | %.5f |\n", m[0] / mr[0], m[1] / mr[1], m[2] / mr[2],
                  c.rel_mse);
    } else {
      std::printf(" no pbrt-v4 render | |\n");
    }
  } catch (const std::exception& e) {
    std::string msg = e.what();
    std::replace(msg.begin(), msg.end(), '|', '/');
    std::printf("| %s | %s | | not rendered: %s | | |\n", label.c_str(), integrator.c_str(),
                msg.c_str());
  }
  std::fflush(stdout);
}

// The project's own test scenes, each rendered by pbrt-v4 and by every integrator.
void own_scenes(const std::string& shared, int spp) {
  const fs::path dir = fs::path(BPM_SOURCE_DIR) / "scenes";
  std::vector<fs::path> files;
  for (const auto& f : fs::directory_iterator(dir))
    if (f.path().extension() == ".pbrt") files.push_back(f.path());
  std::sort(files.begin(), files.end());
  const fs::path pbrt = fs::path(shared) / "tools" / "pbrt-v4" / "pbrt";
  const fs::path tmp = fs::temp_directory_path() / "bpm_conformance.exr";
  std::printf(
      "\nOwn scenes: path at %d spp, bpm and fpm at %d iterations; pbrt-v4 (%s) at %d "
      "spp\n\n",
      spp, spp, fs::exists(pbrt) ? "run here" : "not found", spp);
  std::printf(
      "| scene file | integrator | seconds | mean R G B | ours / pbrt-v4 per channel | "
      "relMSE to pbrt-v4 |\n| --- | --- | --- | --- | --- | --- |\n");
  for (const fs::path& file : files) {
    std::optional<Image> ref;
    if (fs::exists(pbrt)) {
      const std::string cmd = pbrt.string() + " --quiet --spp " + std::to_string(spp) +
                              " --outfile " + tmp.string() + " " + file.string() +
                              " > /dev/null 2>&1";
      if (std::system(cmd.c_str()) == 0) {
        try {
          ref = read_exr(tmp.string());
        } catch (const std::exception&) {
        }
      }
    }
    for (const char* integrator : {"path", "bpm", "fpm"}) own_scene_row(file, integrator, spp, ref);
  }
  std::error_code ec;
  fs::remove(tmp, ec);
}

}  // namespace

int main(int argc, char** argv) {
  std::string shared = std::string(BPM_SOURCE_DIR) + "/../shared";
  int spp = 64, max_width = 200;
  std::string only;
  for (int i = 1; i < argc; ++i) {
    auto next = [&] { return i + 1 < argc ? std::string(argv[++i]) : std::string(); };
    if (!std::strcmp(argv[i], "--shared"))
      shared = next();
    else if (!std::strcmp(argv[i], "--spp"))
      spp = std::atoi(next().c_str());
    else if (!std::strcmp(argv[i], "--width"))
      max_width = std::atoi(next().c_str());
    else if (!std::strcmp(argv[i], "--only"))
      only = next();
  }
  if (only == "own") {
    own_scenes(shared, spp);
    return 0;
  }
  fs::path scenes = fs::path(shared) / "scenes";
  if (!fs::is_directory(scenes)) {
    std::printf("no scenes at %s\n", scenes.string().c_str());
    if (only != "shared") own_scenes(shared, spp);
    return 0;
  }
  std::vector<fs::path> files;
  for (const auto& d : fs::directory_iterator(scenes))
    if (d.is_directory())
      for (const auto& f : fs::directory_iterator(d.path()))
        if (f.path().extension() == ".pbrt") files.push_back(f.path());
  std::sort(files.begin(), files.end());

  std::printf(
      "path at %d spp, bpm and fpm at %d iterations; references: pbrt-v4 renders in "
      "%s/references\n\n",
      spp, spp, shared.c_str());
  std::printf(
      "| scene file | integrator | resolution | seconds | mean R G B | ours / pbrt-v4 per channel "
      "| relMSE to pbrt-v4 |\n");
  std::printf("| --- | --- | --- | --- | --- | --- | --- |\n");
  for (const fs::path& file : files) {
    std::string scene = file.parent_path().filename().string();
    std::string label = scene + "/" + file.filename().string();
    try {
      LoadedScene ls = flatten_scene(parse_scene_file(file.string()));
      auto ref = find_reference(fs::path(shared) / "references", scene);
      int w = ls.film.width, h = ls.film.height;
      if (ref) {
        w = ref->width;
        h = ref->height;
      } else if (w > max_width) {
        h = std::max(1, h * max_width / w);
        w = max_width;
      }
      ls.film.width = w;
      ls.film.height = h;
      for (const char* integrator : {"path", "bpm", "fpm"}) {
        RenderOptions opt = quiet_options(ls, integrator, spp);
        Film film(w, h);
        auto t0 = std::chrono::steady_clock::now();
        render(ls, opt, &film);
        double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        Image img = film.image(ls.film.imaging_ratio);
        auto m = channel_means(img);
        std::printf("| %s | %s | %dx%d | %.1f | %.4f %.4f %.4f |", label.c_str(), integrator, w, h,
                    secs, m[0], m[1], m[2]);
        if (ref) {
          ImageComparison c = compare_images(img, read_exr(ref->path.string()));
          const auto& mr = c.mean_b;
          std::printf(" %.4f %.4f %.4f | %.5f |\n", m[0] / mr[0], m[1] / mr[1], m[2] / mr[2],
                      c.rel_mse);
        } else {
          std::printf(" no reference | |\n");
        }
        std::fflush(stdout);
      }
    } catch (const std::exception& e) {
      std::string msg = e.what();
      std::replace(msg.begin(), msg.end(), '|', '/');
      std::printf("| %s | | | | not rendered: %s | | |\n", label.c_str(), msg.c_str());
    }
    std::fflush(stdout);
  }
  if (only != "shared") own_scenes(shared, spp);
  return 0;
}
