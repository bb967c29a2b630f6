// Rays per second of the path integrator on a Cornell box, beside bare Embree casting the very
// same rays (recorded from the integrator), so that the cost of everything that is not ray
// casting shows. Prints figures; never fails.
//   bench_path [scene.pbrt] [--spp N] [--res N]
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <thread>

#include "camera/camera.h"
#include "embree_replay.h"
#include "path/path_integrator.h"
#include "render/renderer.h"
#include "scene/flatten.h"

using namespace bpm;

int main(int argc, char** argv) {
  std::string scene_path;
  int spp = 16, res = 256;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--spp") && i + 1 < argc)
      spp = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--res") && i + 1 < argc)
      res = std::atoi(argv[++i]);
    else
      scene_path = argv[i];
  }
  if (scene_path.empty()) {
    std::filesystem::path here = std::filesystem::path(BPM_SOURCE_DIR);
    scene_path = std::filesystem::exists(here / "../shared/scenes/cornell-box/scene-v4.pbrt")
                     ? (here / "../shared/scenes/cornell-box/scene-v4.pbrt").string()
                     : (here / "scenes/cornell-box.pbrt").string();
  }
  LoadedScene ls = flatten_scene(parse_scene_file(scene_path));
  ls.film.width = ls.film.height = res;
  int hw = int(std::thread::hardware_concurrency());
  std::printf("scene %s, %dx%d, %d spp, maxdepth %d, %d hardware threads\n", scene_path.c_str(),
              res, res, spp, ls.render.max_depth, hw);

  // Record one pass worth of rays from the integrator itself (same camera, same BSDF sampling).
  RayLog log;
  {
    Camera cam(ls.camera, res, res);
    PathCounters c;
    c.observer = &log;
    for (int y = 0; y < res; ++y)
      for (int x = 0; x < res; ++x)
        for (int s = 0; s < 4; ++s) {
          Rng rng(stream_key(99, s, uint64_t(y) * res + x));
          Ray r = cam.generate_ray({x + rng.uniform(), y + rng.uniform()}, {0.5f, 0.5f}).ray;
          path_radiance(ls.scene, r, PathSettings{ls.render.max_depth},
                        sample_wavelengths(rng.uniform()), rng, c);
        }
  }
  std::printf("recorded %zu closest-hit and %zu shadow rays\n", log.closest_rays.size(),
              log.shadow_rays.size());

  for (int threads : {1, hw}) {
    RenderOptions opt = quiet_options(ls, "path", spp);
    opt.threads = threads;
    Film film(res, res);
    RenderStats st = render(ls, opt, &film);
    double path_rate = st.rays.total() / st.render_seconds;
    double embree_rate = embree_replay(ls.scene, log, threads);
    std::printf(
        "threads %2d: path %.2f Mrays/s, bare Embree %.2f Mrays/s on the same rays, path/Embree = "
        "%.2f\n",
        threads, path_rate * 1e-6, embree_rate * 1e-6, path_rate / embree_rate);
    if (threads == hw && hw == 1) break;
  }
  return 0;
}
