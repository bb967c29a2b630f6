#include "integrator/progressive.h"

namespace bpm {

void run_passes(const IntegratorOptions& opt, Film* film, const char* unit,
                const PassFunction& pass, RenderStats* stats) {
  RenderControl control(opt, *film, unit);
  for (int p = 0; control.keep_going(p); ++p) {
    PassResult r = pass(p, control);
    if (!r.completed) {
      if (r.stop_reason.empty())
        control.keep_going(p + 1);  // sets the stop reason: the interrupt or the time budget
      else
        control.stop(r.stop_reason);
      break;
    }
    stats->passes = p + 1;
    control.after_pass(p, r.rays, r.progress);
  }
  control.finish();
  stats->stop_reason = control.stop_reason();
  stats->mean_sampling_probability = control.mean_sampling_probability();
  stats->render_seconds = control.elapsed();
  stats->relative_error = film->relative_error();
}

}  // namespace bpm
