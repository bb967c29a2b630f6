// Figures for the backward photon mapping integrator (prints them; never fails):
//   1. trees: the kd-tree over whole integration spheres against the kd-tree over centres on the
//      backward photon maps of a real render: build time, queries per second, light pass time;
//   2. rays: eye-pass and light-pass rays per second beside bare Embree casting the same rays;
//      the light pass's time per photon, split into trace, gather and apply beside its rays
//      alone, and beside pbrt-v4's sppm photon pass on the same scene file (when
//      ../shared/tools/pbrt-v4/pbrt or --pbrt is there);
//   3. equal time: relative MSE of bpm and path at equal render times against a converged
//      reference (path with a long budget, cached next to the binary).
//   bench_bpm [scene.pbrt] [--res WxH] [--iterations N] [--times 30,60] [--reference-time S]
//             [--only trees|rays|equal-time|reference] [--pbrt PATH]
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>
#include <thread>

#include "bpm/eye_pass.h"
#include "bpm/light_pass.h"
#include "camera/camera.h"
#include "embree_replay.h"
#include "film/image_io.h"
#include "pbrt_runner.h"
#include "photon_floor.h"
#include "render/renderer.h"
#include "scene/flatten.h"

using namespace bpm;

namespace {

RenderStats run(const LoadedScene& ls, const std::string& integrator, int iterations, double time_s,
                int threads, const BpmSettings& bs, Film* film, uint64_t seed = 1) {
  RenderOptions opt = quiet_options(ls, integrator, iterations, seed);
  opt.time_limit_s = time_s;
  opt.threads = threads;
  opt.bpm = bs;
  return render(ls, opt, film);
}

// Relative MSE as rendering papers use it: the mean over pixels and channels of
// (a - ref)^2 / (ref^2 + 0.01), so that every pixel counts by its relative error (a few very
// bright pixels, such as the light seen through the glass, do not decide it).
double rel_mse(const Image& a, const Image& ref) {
  double sum = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    double d = double(a.rgb[i]) - ref.rgb[i];
    sum += d * d / (double(ref.rgb[i]) * ref.rgb[i] + 0.01);
  }
  return sum / double(a.rgb.size());
}

// The same, summed over the image before dividing: dominated by the brightest pixels.
double global_rel_mse(const Image& a, const Image& ref) {
  double num = 0, den = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    double d = double(a.rgb[i]) - ref.rgb[i];
    num += d * d;
    den += double(ref.rgb[i]) * ref.rgb[i];
  }
  return num / den;
}

void trees(const LoadedScene& ls, int iterations, int threads, const BpmSettings& base) {
  std::printf("\n== sphere tree vs centre tree: %d iterations, %d threads ==\n", iterations,
              threads);
  std::printf("%-8s %10s %12s %12s %14s %12s %10s\n", "tree", "build s", "tree MB", "queries",
              "queries/s (M)", "light s", "dup");
  Image images[2];
  for (int centres = 0; centres < 2; ++centres) {
    BpmSettings bs = base;
    bs.centre_tree = centres;
    Film film(ls.film.width, ls.film.height);
    RenderStats st = run(ls, "bpm", iterations, 0, threads, bs, &film);
    images[centres] = film.image();
    const auto& d = st.details;
    double light_s = d["stages_s"]["light_trace"].get<double>() +
                     d["stages_s"]["light_gather"].get<double>() +
                     d["stages_s"]["light_apply"].get<double>();
    std::printf("%-8s %10.3f %12.2f %12.3g %14.2f %12.3f %10.2f\n", centres ? "centres" : "spheres",
                d["maps"]["tree_build_s"].get<double>(),
                d["maps"]["peak_tree_bytes"].get<double>() * 1e-6,
                double(d["light"]["queries"].get<uint64_t>()),
                d["light"]["queries_per_second"].get<double>() * 1e-6, light_s,
                d["maps"]["mean_sphere_duplication"].get<double>());
  }
  std::printf("images identical: %s\n", images[0].rgb == images[1].rgb ? "yes" : "NO");
}

// pbrt-v4's sppm photon pass on the same scene file at the same resolution and iterations: two
// runs that differ only in photons per iteration, so that the difference of their wall times and
// of their ray counts (--stats) is the cost of the extra photons alone.
struct PbrtPhotonCost {
  double us_per_photon = -1, rays_per_photon = -1;
};
PbrtPhotonCost pbrt_photon_cost(const std::string& pbrt, const std::string& scene_path,
                                const LoadedScene& ls, int iterations, int photons, int threads) {
  const Vec3 diag = ls.scene.bounds.hi - ls.scene.bounds.lo;
  const int few = std::max(1, photons / 10), many = few + photons;
  const std::string film = film_at_resolution(scene_path, ls.film.width, ls.film.height);
  double t[2], rays[2], paths[2];
  for (int k = 0; k < 2; ++k) {
    const std::string integrator =
        "Integrator \"sppm\" \"integer maxdepth\" " + std::to_string(ls.render.max_depth) +
        " \"float radius\" " + std::to_string(0.002f * length(diag)) +
        " \"integer photonsperiteration\" " + std::to_string(k ? many : few);
    const std::string copy =
        scene_copy_with(scene_path, {{"Integrator", integrator}, {"Film", film}}, "bench_bpm");
    if (copy.empty()) return {};
    std::string stats;
    t[k] = run_pbrt(pbrt, copy, iterations, ".bench_bpm_pbrt.exr", threads, &stats);
    std::filesystem::remove(copy);
    rays[k] = pbrt_stat(stats, "Regular ray intersection tests");
    paths[k] = pbrt_stat(stats, "Photon paths followed");
  }
  std::filesystem::remove(".bench_bpm_pbrt.exr");
  PbrtPhotonCost c;
  if (t[0] < 0 || t[1] < 0) return c;
  const double extra = double(many - few) * iterations;
  c.us_per_photon = (t[1] - t[0]) / extra * 1e6;
  if (rays[0] >= 0 && rays[1] >= 0 && paths[1] - paths[0] > 0)
    c.rays_per_photon = (rays[1] - rays[0]) / (paths[1] - paths[0]);
  return c;
}

void rays(const LoadedScene& ls, const std::string& scene_path, int iterations,
          const BpmSettings& bs, int hw, const std::string& pbrt) {
  std::printf("\n== eye and light passes against bare Embree on the same rays ==\n");
  int w = ls.film.width, h = ls.film.height;
  // The rays of the very render that is timed (one thread records them; the rays do not depend
  // on the thread count), guided emission and all.
  RayLog eye_log, light_log;
  {
    RenderOptions opt = quiet_options(ls, "bpm", iterations, 1);
    opt.threads = 1;
    opt.bpm = bs;
    opt.eye_ray_observer = &eye_log;
    opt.light_ray_observer = &light_log;
    Film film(w, h);
    render(ls, opt, &film);
  }
  std::printf("recorded %zu eye closest-hit + %zu shadow rays, %zu light rays (%d iterations)\n",
              eye_log.closest_rays.size(), eye_log.shadow_rays.size(),
              light_log.closest_rays.size(), iterations);
  // The floor loop's photons, and its rays (photon_floor.h).
  constexpr uint64_t kFloorPhotons = 1000000;
  RayLog floor_log, chain_log;
  photon_floor(ls.scene, kFloorPhotons, 1, &floor_log);
  photon_floor<true>(ls.scene, kFloorPhotons, 1, &chain_log);
  if (pbrt.empty())
    std::printf(
        "pbrt-v4 not found (../shared/tools/pbrt-v4/pbrt or --pbrt): no photon pass anchor\n");
  // The machine's speed drifts: each repeat times the passes, right after them Embree, then
  // pbrt-v4's photon pass; the medians of the repeats are printed.
  constexpr int kRepeats = 3;
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  for (int threads : {1, hw}) {
    std::vector<double> eye, eye_embree, eye_share, light, light_embree, light_share, us_photon,
        rays_photon, pbrt_us, pbrt_rays, trace_us, gather_us, apply_us, embree_us, embree_share,
        floor, floor_embree, floor_share, chain_share;
    for (int r = 0; r < kRepeats; ++r) {
      Film film(w, h);
      RenderStats st = run(ls, "bpm", iterations, 0, threads, bs, &film);
      const auto& d = st.details;
      const double light_s = d["stages_s"]["light_trace"].get<double>() +
                             d["stages_s"]["light_gather"].get<double>() +
                             d["stages_s"]["light_apply"].get<double>();
      const double photons = double(d["light"]["photons"].get<uint64_t>()),
                   light_rays = double(d["light"]["light_rays"].get<uint64_t>());
      eye.push_back(d["eye"]["rays_per_second"].get<double>());
      light.push_back(light_rays / light_s);
      us_photon.push_back(light_s / photons * 1e6);
      rays_photon.push_back(light_rays / photons);
      eye_embree.push_back(embree_replay(ls.scene, eye_log, threads));
      light_embree.push_back(embree_replay(ls.scene, light_log, threads));
      eye_share.push_back(eye.back() / eye_embree.back());
      trace_us.push_back(d["stages_s"]["light_trace"].get<double>() / photons * 1e6);
      gather_us.push_back(d["stages_s"]["light_gather"].get<double>() / photons * 1e6);
      apply_us.push_back(d["stages_s"]["light_apply"].get<double>() / photons * 1e6);
      embree_us.push_back(light_rays / photons / light_embree.back() * 1e6);
      embree_share.push_back(embree_us.back() / trace_us.back());
      light_share.push_back(light.back() / light_embree.back());
      const FloorRun fr = photon_floor(ls.scene, kFloorPhotons, threads);
      floor.push_back(double(fr.rays) / fr.seconds);
      floor_embree.push_back(embree_replay(ls.scene, floor_log, threads));
      floor_share.push_back(floor.back() / floor_embree.back());
      const FloorRun cr = photon_floor<true>(ls.scene, kFloorPhotons, threads);
      chain_share.push_back(double(cr.rays) / cr.seconds /
                            embree_replay(ls.scene, chain_log, threads));
      if (!pbrt.empty()) {
        PbrtPhotonCost c =
            pbrt_photon_cost(pbrt, scene_path, ls, iterations, bs.photons_per_iteration, threads);
        if (c.us_per_photon > 0) pbrt_us.push_back(c.us_per_photon);
        if (c.rays_per_photon > 0) pbrt_rays.push_back(c.rays_per_photon);
      }
    }
    std::printf(
        "threads %2d: eye %.2f Mrays/s vs Embree %.2f (%.0f%%); light %.2f Mrays/s vs Embree "
        "%.2f (%.0f%%)  [medians of %d]\n",
        threads, median(eye) * 1e-6, median(eye_embree) * 1e-6, 100 * median(eye_share),
        median(light) * 1e-6, median(light_embree) * 1e-6, 100 * median(light_share), kRepeats);
    std::printf("            light pass %.3f us per photon (%.2f rays each)", median(us_photon),
                median(rays_photon));
    if (!pbrt_us.empty()) {
      std::printf("; pbrt-v4 sppm photon pass %.3f us per photon", median(pbrt_us));
      if (!pbrt_rays.empty()) std::printf(" (%.2f rays each)", median(pbrt_rays));
      std::printf(": %.2fx bpm's", median(pbrt_us) / median(us_photon));
    } else if (!pbrt.empty()) {
      std::printf("; pbrt-v4 failed to run");
    }
    // Where a photon's time goes: tracing it (its rays, emission, scattering and each hit's
    // leaf), gathering at its hits (their sort included), applying the entries (the emission
    // guide's learning included); its rays alone in bare Embree.
    std::printf(
        "\n            medians: trace %.3f, gather %.3f, apply %.3f us per photon; its rays "
        "alone in Embree %.3f us (%.0f%% of the trace)",
        median(trace_us), median(gather_us), median(apply_us), median(embree_us),
        100 * median(embree_share));
    std::printf(
        "\n            floor (emission, hit points, diffuse bounces; nothing else): %.2f Mrays/s "
        "vs Embree %.2f on its own rays (%.0f%%)",
        median(floor) * 1e-6, median(floor_embree) * 1e-6, 100 * median(floor_share));
    std::printf("; its chain of rays alone (emissions made before, no hit points): %.0f%%",
                100 * median(chain_share));
    std::printf("\n");
    if (hw == 1) break;
  }
}

void equal_time(const LoadedScene& ls, const std::string& scene_path,
                const std::vector<double>& times, double reference_s, const BpmSettings& bs) {
  int w = ls.film.width, h = ls.film.height;
  std::printf("\n== equal time, %dx%d, against path run for %.0f s ==\n", w, h, reference_s);
  std::ostringstream name;
  name << "bench_bpm_reference_" << std::filesystem::path(scene_path).stem().string() << "_" << w
       << "x" << h << "_" << int(reference_s) << "s_path.exr";
  std::string ref_path = name.str();
  Image ref;
  if (std::filesystem::exists(ref_path)) {
    ref = read_exr(ref_path);
    std::printf("reference: %s (cached)\n", ref_path.c_str());
  } else {
    Film film(w, h);
    // Its own seed: the timed path renders must not share its first samples.
    RenderStats st =
        run(ls, "path", std::numeric_limits<int>::max(), reference_s, 0, bs, &film, 0x5eed);
    ref = film.image();
    write_exr(ref_path, ref);
    std::printf("reference: %s, %d spp, delta %.4f\n", ref_path.c_str(), st.passes,
                st.relative_error);
  }
  std::printf("relMSE: mean of (a-ref)^2/(ref^2+0.01); global: sum (a-ref)^2 / sum ref^2\n");
  std::printf("%7s %12s %12s %9s %13s %13s %9s %8s %8s\n", "time s", "path relMSE", "bpm relMSE",
              "path/bpm", "path global", "bpm global", "path/bpm", "path spp", "bpm its");
  for (double t : times) {
    if (t <= 0) continue;
    Film fp(w, h), fb(w, h);
    RenderStats sp = run(ls, "path", std::numeric_limits<int>::max(), t, 0, bs, &fp);
    RenderStats sb = run(ls, "bpm", std::numeric_limits<int>::max(), t, 0, bs, &fb);
    Image ip = fp.image(), ib = fb.image();
    double ep = rel_mse(ip, ref), eb = rel_mse(ib, ref), gp = global_rel_mse(ip, ref),
           gb = global_rel_mse(ib, ref);
    std::printf("%7.0f %12.3e %12.3e %9.2f %13.3e %13.3e %9.2f %8d %8d\n", t, ep, eb, ep / eb, gp,
                gb, gp / gb, sp.passes, sb.passes);
  }
}

int run_benchmarks(const std::string& scene_path, const std::string& only, const std::string& pbrt,
                   int w, int h, int iterations, double reference_s,
                   const std::vector<double>& times) {
  LoadedScene ls = flatten_scene(parse_scene_file(scene_path));
  ls.film.width = w;
  ls.film.height = h;
  int hw = int(std::thread::hardware_concurrency());
  BpmSettings bs = bpm_settings_from_file(ls.render.integrator_directive);
  bs.photons_per_iteration = photons_for(bs, size_t(w) * size_t(h));
  std::printf(
      "scene %s, %dx%d, maxdepth %d, %d hardware threads, D=%d k0=%g k1=%g, %d photons per "
      "iteration\n",
      scene_path.c_str(), w, h, ls.render.max_depth, hw, bs.diffuse_depth, bs.k0, bs.k1,
      bs.photons_per_iteration);
  if (only.empty() || only == "trees") trees(ls, iterations, hw, bs);
  if (only.empty() || only == "rays") rays(ls, scene_path, iterations, bs, hw, pbrt);
  if (only.empty() || only == "equal-time") equal_time(ls, scene_path, times, reference_s, bs);
  if (only == "reference") equal_time(ls, scene_path, {}, reference_s, bs);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene_path = std::string(BPM_SOURCE_DIR) + "/scenes/caustic-sphere.pbrt", only;
  std::string pbrt = default_pbrt_path();
  int w = 160, h = 120, iterations = 32;
  double reference_s = 600;
  std::vector<double> times = {30, 60};
  for (int i = 1; i < argc; ++i) {
    auto next = [&] { return i + 1 < argc ? std::string(argv[++i]) : std::string(); };
    if (!std::strcmp(argv[i], "--res"))
      std::sscanf(next().c_str(), "%dx%d", &w, &h);
    else if (!std::strcmp(argv[i], "--iterations"))
      iterations = std::atoi(next().c_str());
    else if (!std::strcmp(argv[i], "--reference-time"))
      reference_s = std::atof(next().c_str());
    else if (!std::strcmp(argv[i], "--only"))
      only = next();
    else if (!std::strcmp(argv[i], "--pbrt"))
      pbrt = next();
    else if (!std::strcmp(argv[i], "--times")) {
      times.clear();
      std::stringstream ss(next());
      for (std::string t; std::getline(ss, t, ',');) times.push_back(std::atof(t.c_str()));
    } else if (argv[i][0] == '-') {
      const bool help = !std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h");
      if (!help) std::fprintf(stderr, "bench_bpm: unknown argument '%s'\n", argv[i]);
      std::fprintf(help ? stdout : stderr,
                   "usage: bench_bpm [scene.pbrt] [--res WxH] [--iterations N] [--times 30,60] "
                   "[--reference-time S] [--only trees|rays|equal-time|reference] [--pbrt PATH]\n");
      return help ? 0 : 2;
    } else {
      scene_path = argv[i];
    }
  }
  try {
    return run_benchmarks(scene_path, only, pbrt, w, h, iterations, reference_s, times);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_bpm: %s\n", e.what());
    return 1;
  }
}
