#include "render/renderer.h"

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <limits>

#include "base/error.h"
#include "bpm/bpm_integrator.h"
#include "fpm/fpm_integrator.h"
#include "camera/camera.h"
#include "render/control.h"

namespace bpm {

std::atomic<bool>& interrupt_flag() {
  static std::atomic<bool> flag{false};
  return flag;
}

namespace {
void on_signal(int) { interrupt_flag().store(true); }
}  // namespace

void install_interrupt_handlers() {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
}

RenderStats render(const LoadedScene& ls, const RenderOptions& opt, Film* film) {
  if (opt.integrator == "bpm") return render_bpm(ls, opt, film);
  if (opt.integrator == "fpm") return render_fpm(ls, opt, film);
  if (opt.integrator != "path")
    throw Error("integrator \"" + opt.integrator + "\" is not available (available: path, bpm, fpm)");
  std::unique_ptr<tbb::global_control> limit;
  if (opt.threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, opt.threads);

  const int w = film->width(), h = film->height();
  PerspectiveCamera camera(ls.camera, w, h);
  Filter filter(ls.filter);
  PathSettings ps{opt.max_depth};
  const float max_value = ls.film.max_component_value;
  tbb::enumerable_thread_specific<PathCounters> counters;
  RenderStats stats;
  RenderControl control(opt, *film, "pass");
  auto total_rays = [&] {
    uint64_t n = 0;
    for (const PathCounters& c : counters) n += c.total();
    return n;
  };
  for (int pass = 0; control.keep_going(pass); ++pass) {
    tbb::parallel_for(tbb::blocked_range2d<int>(0, h, 16, 0, w, 16), [&](const tbb::blocked_range2d<int>& r) {
      if (interrupt_flag().load(std::memory_order_relaxed)) return;
      PathCounters& c = counters.local();
      for (int y = r.rows().begin(); y < r.rows().end(); ++y)
        for (int x = r.cols().begin(); x < r.cols().end(); ++x) {
          uint32_t pixel = uint32_t(y) * w + x;
          if (!control.sample_pixel(pass, pixel)) continue;
          Rng rng(stream_key(opt.seed, uint64_t(opt.first_iteration + pass), pixel));
          FilterSample fs = filter.sample({rng.uniform(), rng.uniform()});
          Vec2 p_film{x + 0.5f + fs.offset.x, y + 0.5f + fs.offset.y};
          Vec2 u_lens{rng.uniform(), rng.uniform()};
          Ray ray = camera.generate_ray(p_film, u_lens);
          Wavelengths wl = sample_wavelengths(rng.uniform());
          Spectrum L = path_radiance(ls.scene, ray, ps, wl, rng, c);
          film->add_sample(x, y, film_rgb(L, wl, max_value), fs.weight);
          film->end_pass(x, y);
        }
    });
    stats.passes = pass + 1;
    control.after_pass(pass, total_rays());
  }
  control.finish();
  stats.stop_reason = control.stop_reason();
  stats.render_seconds = control.elapsed();
  stats.mean_sampling_probability = control.mean_sampling_probability();
  for (const PathCounters& c : counters) stats.rays.add(c);
  stats.relative_error = film->relative_error();
  return stats;
}

}  // namespace bpm
