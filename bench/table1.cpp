// The paper's Table 1 (section 5): photons stored per ray traced by forward photon mapping (fpm)
// against backward photons per ray by backward photon mapping (bpm), on the paper's scenes as we
// wrote them, with both integrators tracing about the same number of rays. A "ray" is, as in the
// paper, a ray from a light or from the camera with all its continuations (a path); the table also
// gives bytes of maps and time. Prints figures; never fails.
//   table1 [--res WxH] [--photons N] [--fpm-iterations N] [--scenes a,b,...]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "render/renderer.h"
#include "scene/flatten.h"

using namespace bpm;

namespace {

struct PaperRow {
  const char* scene;
  const char* label;
  double forward, backward, reduction;
};

// Zhdanov & Zhdanov 2020, Table 1.
const PaperRow kPaper[] = {
    {"cornell-box", "Cornell Box", 3.45, 1.59, 2.17},
    {"room2", "Room2", 7.6, 1.93, 3.94},
    {"light-guides-inside", "Light Guides (lights inside)", 7.6, 3.1, 2.45},
    {"light-guides-outside", "Light Guides (lights outside, aimed in)", 5.6, 3.1, 1.81},
    {"light-guides-side", "Light Guides (camera into a side face)", 7.6, 5.9, 1.29},
};

struct Run {
  uint64_t rays = 0, paths = 0, photons = 0;
  size_t map_bytes = 0;
  double seconds = 0;
};

}  // namespace

int main(int argc, char** argv) {
  int w = 160, h = 120, photons = 100000, fpm_iterations = 4;
  std::vector<std::string> only;
  for (int i = 1; i < argc; ++i) {
    auto next = [&] { return i + 1 < argc ? std::string(argv[++i]) : std::string(); };
    if (!std::strcmp(argv[i], "--res"))
      std::sscanf(next().c_str(), "%dx%d", &w, &h);
    else if (!std::strcmp(argv[i], "--photons"))
      photons = std::atoi(next().c_str());
    else if (!std::strcmp(argv[i], "--fpm-iterations"))
      fpm_iterations = std::atoi(next().c_str());
    else if (!std::strcmp(argv[i], "--scenes")) {
      std::stringstream ss(next());
      for (std::string t; std::getline(ss, t, ',');) only.push_back(t);
    }
  }
  std::printf(
      "Table 1 at %dx%d; fpm: %d iterations of %d photons; bpm (D = 1): iterations until it has "
      "traced as "
      "many rays\n\n",
      w, h, fpm_iterations, photons);
  std::printf("%-40s | %21s | %21s | %21s | %17s | %15s\n", "", "photons/forward ray",
              "photons/backward ray", "reduction", "map MB fpm / bpm", "time s fpm/bpm");
  std::printf("%-40s | %10s %10s | %10s %10s | %10s %10s | %17s | %15s\n", "scene", "ours", "paper",
              "ours", "paper", "ours", "paper", "", "");
  for (const PaperRow& row : kPaper) {
    if (!only.empty() && std::find(only.begin(), only.end(), row.scene) == only.end()) continue;
    std::string path = std::string(BPM_SOURCE_DIR) + "/scenes/" + row.scene + ".pbrt";
    LoadedScene ls = flatten_scene(parse_scene_file(path));
    ls.film.width = w;
    ls.film.height = h;
    RenderOptions opt = quiet_options(ls, "path", 16, 1);
    opt.bpm.photons_per_iteration = photons;
    opt.fpm.photons_per_iteration = photons;
    opt.bpm.diffuse_depth = 1;  // the paper's setting for its Table 1

    Run f;
    {
      Film film(w, h);
      opt.integrator = "fpm";
      opt.spp = fpm_iterations;
      RenderStats st = render(ls, opt, &film);
      f.rays = st.total_rays();
      f.paths = st.details["light"]["photons"].get<uint64_t>();
      f.photons = st.details["light"]["photons_stored"].get<uint64_t>();
      f.map_bytes = st.details["maps"]["peak_photon_bytes"].get<size_t>();
      f.seconds = st.render_seconds;
    }
    Run b;
    opt.integrator = "bpm";
    opt.spp = 1;
    for (int it = 0; b.rays < f.rays && it < 100000; ++it) {
      Film film(w, h);
      opt.first_iteration = it;
      RenderStats st = render(ls, opt, &film);
      b.rays += st.total_rays();
      b.paths += st.details["eye"]["camera_rays"].get<uint64_t>();
      b.photons += st.details["eye"]["backward_photons"].get<uint64_t>();
      b.map_bytes = std::max(b.map_bytes, st.details["maps"]["peak_photon_bytes"].get<size_t>());
      b.seconds += st.render_seconds;
    }
    double fr = double(f.photons) / double(f.paths), br = double(b.photons) / double(b.paths);
    std::printf(
        "%-40s | %10.2f %10.2f | %10.2f %10.2f | %10.2f %10.2f | %8.1f / %6.1f | %7.1f / %5.1f\n",
        row.label, fr, row.forward, br, row.backward, fr / br, row.reduction, f.map_bytes * 1e-6,
        b.map_bytes * 1e-6, f.seconds, b.seconds);
    std::fflush(stdout);
  }
  std::printf(
      "\nrays traced per scene: as many for bpm as for fpm (to within one iteration); map MB: peak "
      "bytes of\n"
      "one iteration's photons (fpm: forward photons; bpm: backward photons), trees excluded.\n");
  return 0;
}
