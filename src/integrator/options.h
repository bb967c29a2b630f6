// What every integrator takes (budgets, threads, seed, depth, accuracy, adaptive sampling,
// checkpoints) and what every render reports. Integrator-specific settings are their own
// (bpm/settings.h, fpm/settings.h).
#pragma once
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "integrator/counters.h"
#include "integrator/sensors.h"

namespace bpm {
class Film;
}

namespace bpm {

// What a render needs, besides its film, to go on exactly where it stopped: the passes done, the
// render control's state (sampling probabilities) and the integrator's (what bpm's guide has
// learnt). Random streams are keyed by (seed, pass index), so nothing else carries over.
struct RenderState {
  int passes = 0;
  std::vector<uint8_t> control, integrator;
};

class Team;  // integrator/team.h

// Where a render stands after a pass, as its progress line says it.
struct RenderProgress {
  int passes = 0;      // done so far in this render
  double seconds = 0;  // since the render began
  double delta = 0;    // the image's total relative error (eq. 4, with the bias estimate)
  double bias = 0;     // its bias part
};

struct IntegratorOptions {
  int spp = 16;             // passes (iterations for the photon integrators)
  int first_iteration = 0;  // index of the first pass: random streams and radii follow it, so
                            // passes [a, b) rendered apart estimate the same image (the same
                            // pixels exactly, unless bpm's guide, sample counts or per-pixel
                            // radii learnt from earlier passes)
  double time_limit_s = 0;  // 0: none
  int threads = 0;          // 0: all hardware threads
  uint64_t seed = 0;
  int max_depth = 5;
  // Direct light in scattering media also sampled along the camera paths' rays
  // (integrator/direct_light.h, sample_direct_light_along).
  bool equiangular = true;
  bool progress = true;  // the progress line on stderr
  // Called with the progress line's figures, as often as it is printed (twice a second and after
  // the last pass), from the thread that runs the passes, whether or not the line is printed.
  std::function<void(const RenderProgress&)> on_progress;
  double accuracy = 0;          // stop when the image error delta (eq. 4) is at most this; 0: off
  bool adaptive = false;        // adaptive sampling (integrator/control.h)
  float adaptive_floor = 0.1f;  // lowest probability of sampling a pixel in a pass
  double write_every_s = 0;     // call checkpoint this often (between passes); 0: never
  // Bytes the render's own data may take (film, photon maps, trees, entries; base/memory.h);
  // 0: no budget.
  uint64_t memory_budget = 0;
  // Every write_every_s: intermediate outputs (checkpoint), then, when set, the state to resume
  // from (save_state), which is also called once when the render ends.
  std::function<void(int passes)> checkpoint;
  std::function<void(const RenderState&)> save_state;
  // Go on from this state (the film given to render() already holds its sums): passes continue
  // from state.passes, and spp counts them too. Null: a fresh render.
  const RenderState* resume = nullptr;
  // Several processes render this image together (integrator/team.h); null: this one alone.
  Team* team = nullptr;
  // Illuminance sensors (integrator/sensors.h), estimated in every pass by the integrator's own
  // estimator (the film must have as many); with image false, only they are rendered.
  std::vector<Sensor> sensors;
  bool image = true;
  // Called after each whole pass with its index (first_iteration + pass): the sensors record that
  // pass's estimates in the film. Set by the integrator; unset: no sensors.
  std::function<void(int pass_index, Film* film)> sensor_pass;
  // Benchmarks only: sees every ray the passes trace, eye and light rays apart (bpm). Null in
  // renders; called from every rendering thread, so render with one thread when it is set.
  RayObserver* eye_ray_observer = nullptr;
  RayObserver* light_ray_observer = nullptr;
};

struct RenderStats {
  int passes = 0;
  std::string stop_reason;               // "samples", "time", "accuracy", "interrupted"
  double mean_sampling_probability = 1;  // adaptive sampling: the last pass's mean
  PathCounters rays;                     // eye rays (camera, bounce, shadow)
  uint64_t light_rays = 0;               // photon rays (bpm, fpm)
  double render_seconds = 0;
  double relative_error = 0;  // eq. (4) over per-pass estimates
  nlohmann::json details;     // integrator-specific statistics
  // With a team, in process 0: per process its passes, rays and seconds spent in passes.
  nlohmann::json processes;
  uint64_t total_rays() const { return rays.total() + light_rays; }
};

}  // namespace bpm
