#include "render/renderer.h"

#include <tbb/global_control.h>

#include <memory>

#include "base/error.h"
#include "bpm/bpm_integrator.h"
#include "fpm/fpm_integrator.h"
#include "path/path_integrator.h"

namespace bpm {

RenderStats render(const LoadedScene& ls, const RenderOptions& opt, Film* film) {
  if (opt.integrator != "path" && opt.integrator != "bpm" && opt.integrator != "fpm")
    throw Error("integrator \"" + opt.integrator +
                "\" is not available (available: path, bpm, fpm)");
  std::unique_ptr<tbb::global_control> limit;
  if (opt.threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  opt.threads);
  if (opt.integrator == "bpm") return render_bpm(ls, opt, opt.bpm, film);
  if (opt.integrator == "fpm") return render_fpm(ls, opt, opt.fpm, film);
  return render_path(ls, opt, film);
}

}  // namespace bpm
