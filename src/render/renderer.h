// The render loop of the path integrator (bpm's is in bpm/bpm_integrator.h): passes of one sample per pixel over tiles, in parallel with oneTBB, until the
// sample budget, the time budget or an interrupt ends it. Every pixel sample draws from a random
// stream keyed by (seed, pass, pixel), so the image does not depend on the number of threads.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "bpm/settings.h"
#include "film/film.h"
#include "path/path_integrator.h"
#include "scene/flatten.h"

namespace bpm {

struct RenderOptions {
  std::string integrator = "path";
  int spp = 16;              // passes (iterations for the photon integrators)
  int first_iteration = 0;   // index of the first pass: random streams and radii follow it, so
                             // passes [a, b) rendered apart average to the same image
  double time_limit_s = 0;  // 0: none
  int threads = 0;          // 0: all hardware threads
  uint64_t seed = 0;
  int max_depth = 5;
  bool progress = true;
  double accuracy = 0;        // stop when the image error delta (eq. 4) is at most this; 0: off
  bool adaptive = false;      // adaptive sampling (render/control.h)
  float adaptive_floor = 0.1f;  // lowest probability of sampling a pixel in a pass
  double write_every_s = 0;   // call checkpoint this often (between passes); 0: never
  std::function<void(int passes)> checkpoint;
  BpmSettings bpm;  // used by the bpm integrator, and by fpm for radii and photon counts
  FpmSettings fpm;
};

// Options for a render of `ls` without a progress line, with the file's maxdepth: what tests and
// benchmarks start from.
inline RenderOptions quiet_options(const LoadedScene& ls, const std::string& integrator, int passes, uint64_t seed = 0) {
  RenderOptions opt;
  opt.integrator = integrator;
  opt.spp = passes;
  opt.seed = seed;
  opt.max_depth = ls.render.max_depth;
  opt.progress = false;
  return opt;
}

struct StageTime {
  std::string name;
  double seconds = 0;
};

struct RenderStats {
  int passes = 0;
  std::string stop_reason;  // "samples", "time", "accuracy", "interrupted"
  double mean_sampling_probability = 1;  // adaptive sampling: the last pass's mean
  PathCounters rays;       // eye rays (camera, bounce, shadow)
  uint64_t light_rays = 0;  // photon rays (bpm)
  double render_seconds = 0;
  double relative_error = 0;  // eq. (4) over per-pass estimates
  nlohmann::json details;     // integrator-specific statistics
  uint64_t total_rays() const { return rays.total() + light_rays; }
};

// Set by SIGINT/SIGTERM handlers; the loop stops at the next tile and the image so far is kept.
std::atomic<bool>& interrupt_flag();
void install_interrupt_handlers();

RenderStats render(const LoadedScene& scene, const RenderOptions& options, Film* film);

}  // namespace bpm
