// The top of the render: which integrator renders the scene, with the options every integrator
// shares and each one's own settings. The command line, tests and benchmarks start here.
#pragma once
#include <string>

#include "base/interrupt.h"
#include "bpm/settings.h"
#include "film/film.h"
#include "fpm/settings.h"
#include "integrator/options.h"
#include "scene/flatten.h"

namespace bpm {

struct RenderOptions : IntegratorOptions {
  std::string integrator = "path";  // path, bpm or fpm
  BpmSettings bpm;
  FpmSettings fpm;
};

// Options for a render of `ls` without a progress line, with the file's maxdepth and default
// integrator settings: what tests and benchmarks start from.
inline RenderOptions quiet_options(const LoadedScene& ls, const std::string& integrator, int passes,
                                   uint64_t seed = 0) {
  RenderOptions opt;
  opt.integrator = integrator;
  opt.spp = passes;
  opt.seed = seed;
  opt.max_depth = ls.render.max_depth;
  opt.progress = false;
  return opt;
}

// Renders with options.integrator on at most options.threads threads (0: all), and the sensors.
RenderStats render(const LoadedScene& scene, const RenderOptions& options, Film* film);

}  // namespace bpm
