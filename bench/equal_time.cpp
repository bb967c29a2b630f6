// Equal time against pbrt-v4: every integrator renders each scene for the same wall time, and the
// table gives its relative MSE against a converged reference, the same without the worst 0.1% of
// pixels (fireflies), and the ratio of each channel's image mean to the reference's. Prints
// figures; never fails.
//   equal_time [--time S] [--scenes a,b] [--pbrt PATH] [--reference-time S] [--res WxH]
//              [--integrators path,bpm,fpm] [--references-only]
// Scenes: caustic-sphere, light-guides-inside, -outside, -side, prism, spot-facets, water-box,
// window-room (references by bpm), lamp-room, room2, shelf-room, kitchen, fog (reference by path),
// spot-lens-fog, underwater (references by bpm), smoke (a uniformgrid medium; reference by path),
// courtyard (sky and sun over a large ground; reference by path), the Cornell box
// (../shared's at 256x256 when present, else ours) and, when ../shared has them, the staircase2
// stand-in at 256x256 and other shared scenes (references by path), and volumetric-caustic at
// 256x256 (reference by bpm). In scenes with media pbrt-v4 renders with volpath and bdpt (its path
// and sppm ignore media). scenes/tools/make_equal_time_scenes.py writes spot-facets, water-box,
// lamp-room, spot-lens-fog, underwater, smoke, shelf-room and kitchen.
//
// Ours (path, bpm, fpm) render in this process for --time seconds (render time, the scene already
// loaded). pbrt-v4 (its path, bdpt and sppm), when ../shared/tools/pbrt-v4/pbrt or --pbrt is there,
// renders a copy of the scene file whose Integrator line is replaced; its sample count is
// calibrated from runs of 1 and 4 samples (wall time = start-up + cost per sample) so that its
// whole run, start-up included, takes --time seconds. sppm's radius is stated in the table: 0.002
// of the scene's bounding-box diagonal. References are made once, with their own seed, and kept in
// equal_time_references/ in the working folder (a JSON beside each says how it was made).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "film/image_compare.h"
#include "film/image_io.h"
#include "pbrt_runner.h"
#include "render/renderer.h"
#include "scene/flatten.h"

using namespace bpm;
namespace fs = std::filesystem;

namespace {

struct SceneEntry {
  std::string name;             // short name for the table
  std::string path;             // scene file
  std::string reference;        // our integrator that makes its reference: path or bpm
  std::string resolution = "";  // WxH instead of the file's, or "" for the file's
};

std::vector<SceneEntry> default_scenes() {
  const std::string ours = std::string(BPM_SOURCE_DIR) + "/scenes/";
  const fs::path shared_cornell =
      fs::path(BPM_SOURCE_DIR) / ".." / "shared" / "scenes" / "cornell-box" / "scene-v4.pbrt";
  std::vector<SceneEntry> s = {
      {"caustic-sphere", ours + "caustic-sphere.pbrt", "bpm"},
      {"light-guides-inside", ours + "light-guides-inside.pbrt", "bpm"},
      {"light-guides-outside", ours + "light-guides-outside.pbrt", "bpm"},
      {"light-guides-side", ours + "light-guides-side.pbrt", "bpm"},
      {"prism", ours + "prism.pbrt", "bpm"},
      {"spot-facets", ours + "spot-facets.pbrt", "bpm"},
      {"water-box", ours + "water-box.pbrt", "bpm"},
      // A room lit by a sun and a sky through a glass pane (path cannot find the sun through it).
      {"window-room", ours + "window-room.pbrt", "bpm"},
      {"lamp-room", ours + "lamp-room.pbrt", "path"},
      {"room2", ours + "room2.pbrt", "path"},
      {"shelf-room", ours + "shelf-room.pbrt", "path"},
      {"kitchen", ours + "kitchen.pbrt", "path"},
      {"fog", ours + "fog.pbrt", "path"},
      {"spot-lens-fog", ours + "spot-lens-fog.pbrt", "bpm"},
      {"underwater", ours + "underwater.pbrt", "bpm"},
      {"smoke", ours + "smoke.pbrt", "path"},
      {"courtyard", ours + "courtyard.pbrt", "path"},
  };
  if (fs::exists(shared_cornell))
    s.push_back({"cornell-box", shared_cornell.lexically_normal().string(), "path", "256x256"});
  else
    s.push_back({"cornell-box", ours + "cornell-box.pbrt", "path"});
  // The other shared scenes bpm renders, when ../shared has them: a real interior, a hall lit by
  // 21 small lamps set in holders against walls and ceiling, tiles under a near-mirror coat, glass,
  // rough metal (the stand-in replaces a missing wood texture); small lights on glossy plates
  // (veach-mis); a coated figure under one area light (killeroo-simple); plastic, glass and metal
  // under three area lights (coffee). At the conformance table's resolutions but the staircase's.
  const fs::path shared = shared_cornell.parent_path().parent_path();
  const std::vector<SceneEntry> more = {
      {"staircase2", (shared / "staircase2" / "scene-v4-standin.pbrt").string(), "path", "256x256"},
      {"veach-mis", (shared / "veach-mis" / "scene-v4.pbrt").string(), "path", "320x180"},
      {"killeroo-simple", (shared / "killeroo-simple" / "killeroo-simple.pbrt").string(), "path",
       "200x200"},
      {"coffee", (shared / "coffee" / "scene-v4.pbrt").string(), "path", "200x250"},
      // A glass sphere focusing a small light into a box of gas (a volumetric caustic).
      {"volumetric-caustic", (shared / "volumetric-caustic" / "scene-v4.pbrt").string(), "bpm",
       "256x256"},
  };
  for (SceneEntry e : more)
    if (fs::exists(e.path)) {
      e.path = fs::path(e.path).lexically_normal().string();
      s.push_back(e);
    }
  return s;
}

struct Metrics {
  double rel_mse = 0, rel_mse_trimmed = 0;
  std::array<double, 3> ratio{};
};

// relMSE as `bpm compare` (mean over pixels and channels of (a - r)^2 / (r^2 + 0.01)); the same
// without the 0.1% of pixels with the largest error; each channel's mean over the reference's.
Metrics measure(const Image& a, const Image& ref) {
  Metrics m;
  ImageComparison c = compare_images(a, ref);
  m.rel_mse = c.rel_mse;
  for (int k = 0; k < 3; ++k) m.ratio[size_t(k)] = c.mean_a[size_t(k)] / c.mean_b[size_t(k)];
  std::vector<double> per_pixel(size_t(a.width) * size_t(a.height));
  for (size_t i = 0; i < per_pixel.size(); ++i) {
    double e = 0;
    for (int k = 0; k < 3; ++k) {
      double d = a.rgb[3 * i + size_t(k)] - ref.rgb[3 * i + size_t(k)];
      double r = ref.rgb[3 * i + size_t(k)];
      e += d * d / (r * r + 0.01) / 3;
    }
    per_pixel[i] = e;
  }
  std::sort(per_pixel.begin(), per_pixel.end());
  size_t keep = per_pixel.size() - per_pixel.size() / 1000;
  double sum = 0;
  for (size_t i = 0; i < keep; ++i) sum += per_pixel[i];
  m.rel_mse_trimmed = keep ? sum / double(keep) : 0;
  return m;
}

Image render_ours(const LoadedScene& ls, const std::string& integrator, double seconds,
                  uint64_t seed, RenderStats* stats) {
  Film film(ls.film.width, ls.film.height);
  RenderOptions opt = quiet_options(ls, integrator, std::numeric_limits<int>::max(), seed);
  // The file's own settings, as the command line takes them.
  opt.bpm = bpm_settings_from_file(ls.render.integrator_directive);
  opt.fpm = fpm_settings_from_file(ls.render.integrator_directive);
  static_cast<PhotonSettings&>(opt.fpm) = opt.bpm;
  opt.time_limit_s = seconds;
  opt.adaptive = true;  // as the command line renders by default
  *stats = render(ls, opt, &film);
  return film.image();
}

// The reference of a scene: read from the cache, or rendered now and kept.
Image reference_for(const SceneEntry& e, const LoadedScene& ls, double seconds) {
  fs::create_directories("equal_time_references");
  std::string stem = "equal_time_references/" + e.name + "_" + std::to_string(ls.film.width) + "x" +
                     std::to_string(ls.film.height);
  if (fs::exists(stem + ".exr")) {
    // Kept from an earlier run: say how it was made (its own JSON), whatever --reference-time is.
    std::ifstream in(stem + ".json");
    const nlohmann::json how = nlohmann::json::parse(in, nullptr, false);
    if (how.is_object() && how.contains("seconds"))
      std::printf("  reference kept: %s, %s for %.0f s (%d passes, delta %.4f)\n", stem.c_str(),
                  how.value("integrator", std::string("?")).c_str(), how.value("seconds", 0.0),
                  how.value("passes", 0), how.value("relative_error_delta", 0.0));
    else
      std::printf("  reference kept: %s (no JSON beside it)\n", stem.c_str());
    return read_exr(stem + ".exr");
  }
  RenderStats st;
  Image img = render_ours(ls, e.reference, seconds, 0x5eed, &st);
  write_exr(stem + ".exr", img);
  nlohmann::json how = {{"scene", e.path},
                        {"integrator", e.reference},
                        {"seconds", st.render_seconds},
                        {"passes", st.passes},
                        {"seed", 0x5eed},
                        {"relative_error_delta", st.relative_error}};
  write_text_atomic(stem + ".json", how.dump(2) + "\n");
  std::printf("  reference made: %s, %s for %.0f s (%d passes, delta %.4f)\n", stem.c_str(),
              e.reference.c_str(), st.render_seconds, st.passes, st.relative_error);
  return img;
}

void row(const std::string& who, double seconds, const std::string& samples, const Metrics& m) {
  std::printf("  %-28s %7.1f %10s %12.3e %12.3e   %6.3f %6.3f %6.3f\n", who.c_str(), seconds,
              samples.c_str(), m.rel_mse, m.rel_mse_trimmed, m.ratio[0], m.ratio[1], m.ratio[2]);
}

void pbrt_rows(const std::string& pbrt, const SceneEntry& e, const LoadedScene& ls, double seconds,
               const Image& ref) {
  const int maxdepth = ls.render.max_depth;
  Vec3 diag = ls.scene.bounds.hi - ls.scene.bounds.lo;
  const float radius = 0.002f * length(diag);
  const std::string out = "equal_time_references/.pbrt_out.exr";
  struct Variant {
    std::string label, line;
  };
  std::vector<Variant> variants = {
      {"pbrt-v4 path", "Integrator \"path\" \"integer maxdepth\" " + std::to_string(maxdepth)},
      {"pbrt-v4 bdpt", "Integrator \"bdpt\" \"integer maxdepth\" " + std::to_string(maxdepth)},
      {"pbrt-v4 sppm r=" + std::to_string(radius).substr(0, 6),
       "Integrator \"sppm\" \"integer maxdepth\" " + std::to_string(maxdepth) +
           " \"float radius\" " + std::to_string(radius)},
  };
  // pbrt-v4's path and sppm ignore media: volpath instead, and bdpt.
  if (ls.scene.has_scattering_media() || !ls.scene.media.empty()) {
    variants.erase(variants.begin() + 2);
    variants[0] = {"pbrt-v4 volpath",
                   "Integrator \"volpath\" \"integer maxdepth\" " + std::to_string(maxdepth)};
  }
  const std::string film = film_at_resolution(e.path, ls.film.width, ls.film.height);
  for (const Variant& v : variants) {
    std::string copy =
        scene_copy_with(e.path, {{"Integrator", v.line}, {"Film", film}}, "equal_time");
    if (copy.empty()) {
      std::printf("  %-28s no WorldBegin in %s\n", v.label.c_str(), e.path.c_str());
      continue;
    }
    // Calibration: wall time = start-up + cost * samples, from runs of 1 and 4 samples. When the
    // difference drowns in the start-up's noise, the whole time of 4 samples counts as their cost
    // (fewer samples rather than a run far over the budget).
    double t1 = run_pbrt(pbrt, copy, 1, out, 2), t4 = run_pbrt(pbrt, copy, 4, out, 2);
    if (t1 < 0 || t4 < 0) {
      std::printf("  %-28s failed to run\n", v.label.c_str());
      fs::remove(copy);
      continue;
    }
    double per_sample = (t4 - t1) / 3, startup = std::max(0.0, t1 - per_sample);
    if (per_sample < 0.1 * t4 / 4) per_sample = t4 / 4, startup = 0;
    int spp = std::max(1, int((seconds - startup) / per_sample));
    double t = run_pbrt(pbrt, copy, spp, out, 2);
    fs::remove(copy);
    if (t < 0) {
      std::printf("  %-28s failed to run at %d spp\n", v.label.c_str(), spp);
      continue;
    }
    Image img = read_exr(out);
    if (img.width != ref.width || img.height != ref.height) {
      std::printf("  %-28s wrote %dx%d, not the reference's %dx%d\n", v.label.c_str(), img.width,
                  img.height, ref.width, ref.height);
      continue;
    }
    row(v.label, t, std::to_string(spp) + " spp", measure(img, ref));
  }
  fs::remove(out);
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  double seconds = 60, reference_s = 600;
  std::string only, res, ours = "path,bpm,fpm";
  bool references_only = false;
  std::string pbrt = default_pbrt_path();
  for (int i = 1; i < argc; ++i) {
    auto next = [&] { return i + 1 < argc ? std::string(argv[++i]) : std::string(); };
    if (!std::strcmp(argv[i], "--time"))
      seconds = std::atof(next().c_str());
    else if (!std::strcmp(argv[i], "--reference-time"))
      reference_s = std::atof(next().c_str());
    else if (!std::strcmp(argv[i], "--scenes"))
      only = next();
    else if (!std::strcmp(argv[i], "--pbrt"))
      pbrt = next();
    else if (!std::strcmp(argv[i], "--res"))
      res = next();
    else if (!std::strcmp(argv[i], "--integrators"))
      ours = next();
    else if (!std::strcmp(argv[i], "--references-only"))
      references_only = true;
    else {
      bool help = !std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h");
      if (!help) std::fprintf(stderr, "equal_time: unknown argument '%s'\n", argv[i]);
      std::fprintf(help ? stdout : stderr,
                   "usage: equal_time [--time S] [--scenes a,b] [--pbrt PATH] "
                   "[--reference-time S] [--res WxH] [--integrators path,bpm,fpm] "
                   "[--references-only]\n"
                   "  references are kept in ./equal_time_references/; --references-only makes "
                   "the missing ones and stops\n");
      return help ? 0 : 2;
    }
  }
  std::printf(
      "== equal time: %.0f s each; reference: a render with its own seed, kept or made for %.0f "
      "s ==\n",
      seconds, reference_s);
  std::printf("  %-28s %7s %10s %12s %12s   %s\n", "integrator", "s", "samples", "relMSE",
              "relMSE 99.9%", "mean / reference R G B");
  for (const SceneEntry& e : default_scenes()) {
    if (!only.empty() && ("," + only + ",").find("," + e.name + ",") == std::string::npos) continue;
    LoadedScene ls = flatten_scene(parse_scene_file(e.path));
    const std::string& wxh = res.empty() ? e.resolution : res;
    if (!wxh.empty()) std::sscanf(wxh.c_str(), "%dx%d", &ls.film.width, &ls.film.height);
    std::printf("%s (%dx%d, maxdepth %d)\n", e.name.c_str(), ls.film.width, ls.film.height,
                ls.render.max_depth);
    Image ref = reference_for(e, ls, reference_s);
    if (references_only) continue;
    for (const char* integrator : {"path", "bpm", "fpm"}) {
      if (("," + ours + ",").find(std::string(",") + integrator + ",") == std::string::npos)
        continue;
      RenderStats st;
      Image img = render_ours(ls, integrator, seconds, 1, &st);
      std::string samples =
          std::to_string(st.passes) + (std::string(integrator) == "path" ? " spp" : " its");
      row(std::string("bpm ") + integrator, st.render_seconds, samples, measure(img, ref));
    }
    if (!pbrt.empty()) pbrt_rows(pbrt, e, ls, seconds, ref);
  }
  return 0;
}
