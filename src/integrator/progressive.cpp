#include "integrator/progressive.h"

namespace bpm {

void run_passes(const IntegratorOptions& opt, Film* film, const char* unit,
                const PassFunction& pass, RenderStats* stats, const IntegratorState& state) {
  RenderControl control(opt, *film, unit);
  int first = 0;
  if (opt.resume) {
    ByteReader c(opt.resume->control, "the checkpoint's render state");
    control.load(c);
    ByteReader i(opt.resume->integrator, "the checkpoint's integrator state");
    if (state.load) state.load(i);
    if (!i.at_end()) throw Error("the checkpoint's integrator state does not fit this integrator");
    first = opt.resume->passes;
  }
  stats->passes = first;
  auto snapshot = [&] {
    RenderState s;
    s.passes = stats->passes;
    ByteWriter c, i;
    control.save(c);
    if (state.save) state.save(i);
    s.control = c.take();
    s.integrator = i.take();
    return s;
  };
  for (int p = first; control.keep_going(p); ++p) {
    film->begin_pass(opt.first_iteration + p);
    PassResult r = pass(p, control);
    if (!r.completed) {
      if (r.stop_reason.empty())
        control.keep_going(p + 1);  // sets the stop reason: the interrupt or the time budget
      else
        control.stop(r.stop_reason);
      break;
    }
    stats->passes = p + 1;
    if (ends_round(p + 1)) {
      if (state.learnt) {
        std::vector<double> learnt;
        state.learnt(&learnt);
        state.merge(learnt);
      }
      control.end_round(p + 1);
    }
    control.after_pass(p, r.rays, r.progress);
    if (control.checkpoint_due()) {
      if (opt.checkpoint) opt.checkpoint(p + 1);
      if (opt.save_state) opt.save_state(snapshot());
    }
  }
  control.finish();
  if (opt.save_state) opt.save_state(snapshot());
  stats->stop_reason = control.stop_reason();
  stats->mean_sampling_probability = control.mean_sampling_probability();
  stats->render_seconds = control.elapsed();
  stats->relative_error = film->relative_error();
}

}  // namespace bpm
