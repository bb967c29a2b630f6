// What every integrator's outer loop shares (section 4 of the paper): the budgets that end a
// render (passes, time, the requested accuracy delta of eq. 4, an interrupt), the progress line
// with delta, rays per second and the time left to the requested accuracy, intermediate outputs
// every so many seconds, and adaptive sampling: which pixels the next pass samples.
//
// Adaptive sampling keeps every pixel's estimate unbiased: a pixel is either sampled in a pass or
// not, with a probability decided at the start of the pass's round from the rounds before, and
// sampled in the round's first pass; its value weighs the mean of each round's passes that
// sampled it by the round's length (film/film.h: the mean of all its passes would not be
// unbiased, since how often a pixel is sampled follows what it drew). The probability follows the
// pixel's relative RMS (eq. 5 over its mean), is 1 for the noisiest pixels and never below a floor,
// so that no pixel starves and the error estimate of every pixel stays alive; it is 1 for a pixel
// whose passes have all been black, which has no error estimate at all.
#pragma once
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "base/bytes.h"
#include "film/film.h"

namespace bpm {

// Wall-clock time of the integrators' stages.
using Clock = std::chrono::steady_clock;
inline double since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

struct IntegratorOptions;

// The passes before adaptive sampling and the accuracy budget trust the error estimate.
constexpr int kWarmupPasses = 4;

// The relative error that adaptive sampling measures pixels against: the 90th percentile of the
// pixels' (non-empty `relative`), so that the noisiest tenth is sampled every pass.
template <class T>
T reference_relative_error(std::vector<T> relative) {
  const size_t k = std::min(relative.size() - 1, size_t(0.9 * double(relative.size())));
  std::nth_element(relative.begin(), relative.begin() + ptrdiff_t(k), relative.end());
  return relative[k];
}

// Passes are grouped into rounds. Within a round the passes are independent: the sampling
// probabilities and what an integrator learns from its passes (bpm's guided emission) stay as
// they were at the round's start; at its end what the round learnt is merged. A round is a
// quarter of the passes before it (one pass each for the first eight, at most 64), and where
// rounds end depends on the pass count alone, so that one process, or several sharing a round's
// passes (integrator/team.h), render the same passes from the same state.
bool ends_round(int passes);

class RenderControl {
 public:
  // `unit` names a pass in the progress line ("pass" or "iteration").
  RenderControl(const IntegratorOptions& opt, const Film& film, const char* unit);

  // Before pass `done` (0-based): false when the render must stop; stop_reason() says why.
  bool keep_going(int done);
  // Ends the render for a reason of the integrator's own (PassResult::stop_reason).
  void stop(const std::string& reason) { stop_reason_ = reason; }
  // After a pass: prints progress. `rays` is the total traced so far; `extra` is appended to the
  // progress line.
  void after_pass(int done, uint64_t rays, const std::string& extra = "");
  // At the end of a round (ends_round(passes)): the sampling probabilities of the next one.
  void end_round(int passes);
  // Whether work of pass `pass` not yet started (tiles, chunks of photons) is to be left out: an
  // interrupt, or the time budget spent. The time budget never cuts the first pass, so that a
  // render always has a complete image; a later pass cut by it ends the render.
  bool cut(int pass) const;
  // The time budget alone: set and spent.
  bool out_of_time() const;
  // An interrupt or the time budget, in any pass: what a light pass asks before each chunk.
  bool stop_requested() const;
  // Whether cut() or stop_requested() has said yes: a pass may then be incomplete (tiles left
  // out, a light pass ended early), and the render's state is not one to resume exactly from.
  bool cut_a_pass() const { return cut_seen_.load(); }
  // Whether the pass samples the pixel (always, without adaptive sampling).
  bool sample_pixel(int pass, uint32_t pixel) const;
  // Call once at the end: finishes the progress line.
  void finish();
  // After a pass: whether write_every_s has passed since the last checkpoint (then it starts
  // counting again).
  bool checkpoint_due();
  // What the next passes depend on (the sampling probabilities; delta for the progress line), for
  // resuming a render.
  void save(ByteWriter& w) const;
  void load(ByteReader& r);

  const std::string& stop_reason() const { return stop_reason_; }
  double elapsed() const;
  double delta() const { return delta_; }
  double mean_sampling_probability() const;

 private:
  void update_probabilities();
  void print_progress(int passes, double t, uint64_t rays, const std::string& extra);
  const IntegratorOptions& opt_;
  const Film& film_;
  const char* unit_;
  std::chrono::steady_clock::time_point t0_;
  std::string stop_reason_ = "samples";
  double delta_ = 0;  // the total error (Film::relative_error_total)
  double bias_ = 0;   // its bias part
  double last_progress_ = -1, last_checkpoint_ = 0;
  std::vector<float> probability_;  // empty: every pixel every pass
  mutable std::atomic<bool> cut_seen_{false};
};

}  // namespace bpm
