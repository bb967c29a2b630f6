#include "integrator/control.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "base/interrupt.h"
#include "base/rng.h"
#include "integrator/options.h"

namespace bpm {
namespace {
constexpr uint64_t kAdaptiveStream = 0x6164617074ull;

// The first pass of the round that holds pass `pass` (0-based), and the round's length: a quarter
// of the passes before it, at least 1 and at most 64.
std::pair<int, int> round_of(int pass) {
  const auto length_after = [](int start) { return std::clamp(start / 4, 1, 64); };
  int start = 0;
  while (start + length_after(start) <= pass) start += length_after(start);
  return {start, length_after(start)};
}
}  // namespace

bool ends_round(int passes) { return round_of(passes).first == passes; }

RenderControl::RenderControl(const IntegratorOptions& opt, const Film& film, const char* unit)
    : opt_(opt), film_(film), unit_(unit), t0_(std::chrono::steady_clock::now()) {}

double RenderControl::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
}

bool RenderControl::out_of_time() const {
  return opt_.time_limit_s > 0 && elapsed() >= opt_.time_limit_s;
}

bool RenderControl::stop_requested() const {
  const bool stop = interrupted() || out_of_time();
  if (stop) cut_seen_ = true;
  return stop;
}

bool RenderControl::cut(int pass) const {
  const bool cut = interrupted() || (pass > 0 && out_of_time());
  if (cut) cut_seen_ = true;
  return cut;
}

bool RenderControl::keep_going(int done) {
  if (interrupt_flag().load()) {
    stop_reason_ = "interrupted";
    return false;
  }
  if (done >= opt_.spp) {
    stop_reason_ = "samples";
    return false;
  }
  if (opt_.time_limit_s > 0 && done > 0 && elapsed() >= opt_.time_limit_s) {
    stop_reason_ = "time";
    return false;
  }
  if (opt_.accuracy > 0 && done >= kWarmupPasses && delta_ > 0 && delta_ <= opt_.accuracy) {
    stop_reason_ = "accuracy";
    return false;
  }
  return true;
}

void RenderControl::update_probabilities() {
  std::vector<float> rms = film_.rms_rgb();
  Image img = film_.image();
  size_t n = rms.size() / 3;
  // Relative RMS over the three channels (an error of colour counts as much as one of
  // brightness), with a small share of the image's mean added to the denominator so that black
  // pixels (rms 0 / mean 0) are not declared infinitely noisy.
  std::vector<double> value(n), error(n);
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    double v2 = 0, e2 = 0;
    for (int c = 0; c < 3; ++c) {
      v2 += double(img.rgb[3 * i + c]) * img.rgb[3 * i + c];
      e2 += double(rms[3 * i + c]) * rms[3 * i + c];
    }
    value[i] = std::sqrt(v2);
    error[i] = std::sqrt(e2);
  });
  double image_mean = 0;
  for (size_t i = 0; i < n; ++i) image_mean += value[i] / double(n);
  std::vector<float> own(n), rel(n);
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    own[i] = float(error[i] / (value[i] + 0.01 * image_mean + 1e-12));
  });
  // Each pixel takes at least the RMS of the relative errors about it (3 x 3): a pixel whose
  // passes have not yet drawn the rare bright paths that its neighbours', which see much the same
  // light, have drawn looks converged by its own RMS and would be sampled at the floor; since its
  // value weighs each round's passes as the round's length (film/film.h), such a path drawn in a
  // round that samples it rarely then weighs all the more.
  const int w = film_.width(), h = film_.height();
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      double sum2 = 0;
      int count = 0;
      for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy)
        for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx, ++count) {
          const double e = own[size_t(yy) * size_t(w) + size_t(xx)];
          sum2 += e * e;
        }
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      rel[i] = std::max(own[i], float(std::sqrt(sum2 / count)));
    }
  });
  // The noisiest tenth of the pixels is sampled every pass; the rest in proportion.
  const float ref = reference_relative_error(rel);
  // A pixel whose passes have all been black has no error estimate: light may reach it by rare
  // paths (a small lit spot seen after two bounces) that the passes so far missed. Sampling it less
  // would leave it black far longer (unbiased, but heavily skewed), so it is sampled every pass.
  const std::vector<int> lit = film_.lit_pass_counts();
  probability_.resize(n);
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    probability_[i] =
        ref > 0 && lit[i] > 0 ? std::clamp(rel[i] / ref, opt_.adaptive_floor, 1.0f) : 1.0f;
  });
}

void RenderControl::after_pass(int done, uint64_t rays, const std::string& extra) {
  int passes = done + 1;
  double t = elapsed();
  const bool due = t - last_progress_ >= 0.5 || passes == opt_.spp;
  const bool print = opt_.progress && due, report = opt_.on_progress && due;
  // The total error: noise, and for the photon methods their bias estimate as well; with sensors,
  // the larger of the image's and the sensors' (without an image, the sensors' alone).
  if (opt_.accuracy > 0 || print || report) {
    bias_ = film_.relative_error_bias();
    delta_ =
        std::sqrt(std::pow(film_.relative_error(), 2) + bias_ * bias_);  // relative_error_total
    if (film_.sensor_count() > 0) delta_ = std::max(delta_, film_.sensor_relative_error());
  }
  if (!due || !(print || report)) return;
  last_progress_ = t;
  if (report) opt_.on_progress({passes, t, delta_, bias_});
  if (print) print_progress(passes, t, rays, extra);
}

void RenderControl::print_progress(int passes, double t, uint64_t rays, const std::string& extra) {
  char budget[32] = "";
  if (opt_.spp != std::numeric_limits<int>::max())
    std::snprintf(budget, sizeof budget, "/%d", opt_.spp);
  std::string eta;
  if (opt_.accuracy > 0 && delta_ > opt_.accuracy && passes >= kWarmupPasses) {
    // The noise falls as 1/sqrt(passes); the bias is held where it is (it stays with a fixed
    // radius and shrinks with progressive ones, so this is the longest it takes): the passes
    // still needed for noise^2 + bias^2 to reach the target, at the rate so far.
    const double noise2 = delta_ * delta_ - bias_ * bias_,
                 room = opt_.accuracy * opt_.accuracy - bias_ * bias_;
    char buf[80];
    if (room > 0)
      std::snprintf(buf, sizeof buf, "  %.0f s to delta %.3g",
                    std::fmax(0.0, double(passes) * (noise2 / room - 1)) * t / passes,
                    opt_.accuracy);
    else
      std::snprintf(buf, sizeof buf, "  bias above delta %.3g", opt_.accuracy);
    eta = buf;
  }
  char bias[32] = "";
  if (film_.has_bias()) std::snprintf(bias, sizeof bias, " (bias %.4f)", bias_);
  std::fprintf(stderr, "\rbpm: %s %d%s  %.1f s  delta %.4f%s  %.2f Mrays/s%s%s   ", unit_, passes,
               budget, t, delta_, bias, t > 0 ? double(rays) / t * 1e-6 : 0.0, extra.c_str(),
               eta.c_str());
  std::fflush(stderr);
}

bool RenderControl::sample_pixel(int pass, uint32_t pixel) const {
  if (probability_.empty()) return true;
  const float p = probability_[pixel];
  // The first pass of a round samples every pixel, so that no pixel's round is empty (Film); the
  // round's other passes make up the rest of its p * length samples, where there is any.
  const auto [first, length] = round_of(pass);
  if (p >= 1 || pass == first) return true;
  const float rest = (p * float(length) - 1) / float(length - 1);
  if (!(rest > 0)) return false;
  Rng rng(stream_key(opt_.seed ^ kAdaptiveStream, uint64_t(opt_.first_iteration + pass), pixel));
  return rng.uniform() < rest;
}

double RenderControl::mean_sampling_probability() const {
  if (probability_.empty()) return 1;
  double s = 0;
  for (float p : probability_) s += p;
  return s / double(probability_.size());
}

void RenderControl::end_round(int passes) {
  if (opt_.adaptive && passes >= kWarmupPasses) update_probabilities();
}

bool RenderControl::checkpoint_due() {
  const double t = elapsed();
  if (!(opt_.write_every_s > 0) || t - last_checkpoint_ < opt_.write_every_s) return false;
  last_checkpoint_ = t;
  return true;
}

void RenderControl::save(ByteWriter& w) const {
  w.put(delta_);
  w.put(bias_);
  w.put_vector(probability_);
}

void RenderControl::load(ByteReader& r) {
  delta_ = r.get<double>();
  bias_ = r.get<double>();
  probability_ = r.get_vector<float>();
  const size_t pixels = size_t(film_.width()) * size_t(film_.height());
  if (!probability_.empty() && probability_.size() != pixels)
    throw Error(r.what() + " is truncated or corrupt (sampling probabilities)");
}

void RenderControl::finish() {
  if (opt_.progress) std::fprintf(stderr, "\n");
  if (interrupt_flag().load()) stop_reason_ = "interrupted";
}

}  // namespace bpm
