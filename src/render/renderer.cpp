#include "render/renderer.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>

#include <memory>

#include "base/error.h"
#include "bpm/bpm_integrator.h"
#include "fpm/fpm_integrator.h"
#include "integrator/progressive.h"
#include "path/path_integrator.h"
#include "path/sensors.h"

namespace bpm {
namespace {

// The path tracer's passes of the sensors alone, without an image (--no-image).
RenderStats render_path_sensors(const RenderOptions& opt, Film* film,
                                const tbb::enumerable_thread_specific<PathCounters>& counters) {
  RenderStats stats;
  auto pass = [&](int, const RenderControl&) {
    PassResult r;
    for (const PathCounters& c : counters) r.rays += c.total();
    return r;
  };
  run_passes(opt, film, "pass", pass, &stats);
  return stats;
}

}  // namespace

RenderStats render(const LoadedScene& ls, const RenderOptions& opt, Film* film) {
  if (opt.integrator != "path" && opt.integrator != "bpm" && opt.integrator != "fpm")
    throw Error("integrator \"" + opt.integrator +
                "\" is not available (available: path, bpm, fpm)");
  std::unique_ptr<tbb::global_control> limit;
  if (opt.threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  opt.threads);
  if (opt.sensors.size() != film->sensor_count())
    throw Error("the film has " + std::to_string(film->sensor_count()) + " sensors, the render " +
                std::to_string(opt.sensors.size()));
  if (!opt.image && opt.sensors.empty())
    throw Error("a render without an image needs sensors (--sensors)");
  if (ls.scene.has_emissive_media() && opt.integrator != "path")
    throw Error(
        "the photon methods do not render glowing media (Le, temperature) yet: render the scene "
        "with "
        "--integrator path");
  if (ls.scene.has_scattering_media() && opt.integrator != "path" && !opt.sensors.empty())
    throw Error(
        "the photon methods' illuminance sensors in a scene whose media scatter are not "
        "supported yet: render them with --integrator path");
  // A named sensor is balanced by its fit (6500 K unless the film says); cie1931 by a matrix.
  if (ls.film.sensor != "cie1931")
    film->set_response(std::make_shared<const CameraResponse>(*CameraResponse::named(
        ls.film.sensor, ls.film.white_balance > 0 ? ls.film.white_balance : 6500)));
  else if (ls.film.white_balance > 0)
    film->set_colour_matrix(white_balance_srgb(ls.film.white_balance));
  // A spectral film's buckets (set before a resumed film was loaded, or here).
  if (!(film->spectral() == ls.film.spectral)) film->set_spectral(ls.film.spectral);
  // The photon methods' iterations are independent only stream by stream (photons/light_path.h).
  const bool photons = opt.integrator != "path";
  film->set_independent_passes(!photons);
  if (photons && film->m_images() > 0 && Film::kStreams % film->m_images() != 0)
    throw Error("--m-images " + std::to_string(film->m_images()) +
                ": the photon methods take 2, 4 or 8 images (their iterations form " +
                std::to_string(Film::kStreams) + " independent streams), or 0");
  RenderOptions o = opt;
  locate_sensor_media(ls.scene, ls.camera.medium, &o.sensors);
  if (opt.integrator == "bpm") return render_bpm(ls, o, o.bpm, film);
  if (opt.integrator == "fpm") return render_fpm(ls, o, o.fpm, film);
  tbb::enumerable_thread_specific<PathCounters> sensor_counters;
  if (!o.sensors.empty())
    o.sensor_pass = [&](int pass_index, Film* f) {
      sensor_pass(ls.scene, o.sensors, o.max_depth, o.seed, pass_index, f, sensor_counters);
    };
  RenderStats stats =
      o.image ? render_path(ls, o, film) : render_path_sensors(o, film, sensor_counters);
  for (const PathCounters& c : sensor_counters) stats.rays.add(c);
  return stats;
}

}  // namespace bpm
