#include "integrator/progressive.h"

#include <algorithm>

#include "integrator/team.h"

namespace bpm {
namespace {

// run_passes in one process.
void run_passes_alone(const IntegratorOptions& opt, Film* film, const PassFunction& pass,
                      RenderStats* stats, const IntegratorState& state, RenderControl& control,
                      const std::function<RenderState()>& snapshot, int first) {
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
      film->end_round();
      control.end_round(p + 1);
    }
    control.after_pass(p, r.rays, r.progress);
    if (control.checkpoint_due()) {
      if (opt.checkpoint) opt.checkpoint(p + 1);
      if (opt.save_state) opt.save_state(snapshot());
    }
  }
}

// At the end of a round with several processes: what every process learnt is added up and merged,
// and process 0's control state (its sampling probabilities) goes to every process.
void end_team_round(Team& team, int passes, const IntegratorState& state, RenderControl& control,
                    Film* film) {
  const bool root = team.rank() == 0;
  if (state.learnt) {
    std::vector<double> learnt;
    state.learnt(&learnt);
    team.sum(&learnt);
    state.merge(learnt);
  }
  if (root) {
    film->end_round();  // the round's passes are all in process 0's film (gather_film)
    control.end_round(passes);
  }
  ByteWriter w;
  if (root) control.save(w);
  std::vector<uint8_t> c = w.take();
  team.broadcast(&c);
  ByteReader r(c, "the render state of process 0");
  if (!root) control.load(r);
}

// Ended inside a round: what every process learnt in it goes to process 0's state unmerged, so
// that its final checkpoint resumes the round as one process would.
void keep_round_learnt(Team& team, int passes, const IntegratorState& state) {
  if (!ends_round(passes) && state.learnt && state.keep_learnt) {
    std::vector<double> learnt;
    state.learnt(&learnt);
    team.sum(&learnt);
    if (team.rank() == 0) state.keep_learnt(learnt);
  }
}

// What one process did: passes, rays, and seconds in its passes.
struct ProcessShare {
  uint64_t rays = 0;
  int passes = 0;
  double seconds = 0;
};

// Every process's share, in the statistics (the same on every process).
void record_processes(Team& team, const ProcessShare& mine, RenderStats* stats) {
  std::vector<std::vector<double>> rows =
      team.gather({double(mine.passes), double(mine.rays), mine.seconds});
  for (size_t r = 0; r < rows.size(); ++r)
    stats->processes.push_back({{"rank", r},
                                {"passes", int(rows[r][0])},
                                {"rays", uint64_t(rows[r][1])},
                                {"pass_seconds", rows[r][2]}});
}

// run_passes with several processes (integrator/team.h): round by round, each round's passes
// shared out, then the films gathered, what was learnt added up and merged, and process 0's
// decisions (sampling probabilities, go on or stop) sent to every process.
// Returns whether a pass of any process was cut short (an interrupt, the time budget).
bool run_team_passes(const IntegratorOptions& opt, Film* film, const PassFunction& pass,
                     RenderStats* stats, const IntegratorState& state, RenderControl& control,
                     const std::function<RenderState()>& snapshot) {
  Team& team = *opt.team;
  const bool root = team.rank() == 0;
  int passes = stats->passes;  // completed, over every process
  std::string reason, progress;
  bool any_cut = false;
  ProcessShare my;
  for (;;) {
    std::vector<uint8_t> go{uint8_t(root && control.keep_going(passes))};
    team.broadcast(&go);
    if (!go[0]) break;
    int end = passes + 1;
    while (!ends_round(end)) ++end;
    end = std::min(end, opt.spp);
    const auto t = Clock::now();
    // A pass cut short (or dropped) is not counted, and no process is given another: the render
    // stops after this round, as one process stops after its pass.
    const int mine = team.share_passes(passes, end, [&](int p) {
      film->begin_pass(opt.first_iteration + p);
      PassResult r = pass(p, control);
      if (!r.completed || control.cut_a_pass()) {
        if (!r.completed && reason.empty()) reason = r.stop_reason;
        return false;
      }
      my.rays = r.rays;
      progress = r.progress;
      return true;
    });
    my.seconds += since(t);
    my.passes += mine;
    // Over every process: completed passes, rays, cut passes, and integrator stop reasons (the
    // one there is: "memory").
    std::vector<double> counts{double(mine), double(my.rays), double(control.cut_a_pass()),
                               double(reason == "memory")};
    team.sum(&counts);
    const int completed = int(counts[0]);
    team.gather_film(film);
    any_cut = any_cut || counts[2] > 0;
    if (counts[3] > 0 && reason.empty()) reason = "memory";
    const bool cut = completed < end - passes;
    passes += completed;
    stats->passes = passes;
    if (ends_round(passes)) end_team_round(team, passes, state, control, film);
    if (root) {
      control.after_pass(passes - 1, uint64_t(counts[1]), progress);
      if (!cut && control.checkpoint_due()) {
        if (opt.checkpoint) opt.checkpoint(passes);
        if (opt.save_state) opt.save_state(snapshot());
      }
    }
    // A cut pass ends the render, as in one process: the reason is its integrator's, or the
    // interrupt or the time budget.
    std::vector<uint8_t> stop{uint8_t(cut)};
    team.broadcast(&stop);
    if (stop[0]) {
      if (root) {
        if (!reason.empty())
          control.stop(reason);
        else if (control.keep_going(passes))
          // Process 0 sees no budget reached: another process's clock (each keeps its own) ran
          // out first, or it was interrupted.
          control.stop(opt.time_limit_s > 0 ? "time" : "interrupted");
      }
      break;
    }
  }
  keep_round_learnt(team, passes, state);
  record_processes(team, my, stats);
  return any_cut;
}

}  // namespace

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
    // What the checkpoint had learnt inside its round is process 0's to bring to the round's end
    // (each process adds its own share there): the others forget it.
    if (opt.team && opt.team->rank() != 0 && state.learnt) {
      std::vector<double> forgotten;
      state.learnt(&forgotten);
    }
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
  // Illuminance sensors: each whole pass also estimates them (path/sensors.h).
  const PassFunction with_sensors = [&](int p, const RenderControl& c) {
    PassResult r = pass(p, c);
    if (r.completed && !c.cut_a_pass()) opt.sensor_pass(opt.first_iteration + p, film);
    return r;
  };
  const PassFunction& passes = opt.sensor_pass ? with_sensors : pass;
  bool cut = false;
  if (opt.team && opt.team->size() > 1) {
    cut = run_team_passes(opt, film, passes, stats, state, control, snapshot);
  } else {
    run_passes_alone(opt, film, passes, stats, state, control, snapshot, first);
    cut = control.cut_a_pass();
  }
  control.finish();
  // The final state, unless a pass was cut short: the film then holds part of a pass (or bpm's
  // guide learnt from a dropped iteration), and the last checkpoint written between whole passes
  // is the one to resume exactly from.
  if (opt.save_state && !cut) opt.save_state(snapshot());
  stats->stop_reason = control.stop_reason();
  stats->mean_sampling_probability = control.mean_sampling_probability();
  stats->render_seconds = control.elapsed();
  stats->relative_error = film->relative_error();
}

}  // namespace bpm
