// The outer loop every integrator shares (sections 3 and 4 of the paper): passes (path) or
// iterations (bpm, fpm), each a complete, unbiased estimate of the image (of its radius-blurred
// image for the photon methods; bpm's emission guide, its pixels' sample counts and per-pixel
// radii follow what the earlier ones measured, and nothing else links them), until a budget
// ends the render: a pass count, time, the requested accuracy, or an interrupt. RenderControl
// decides when to stop, which pixels a pass samples (adaptive sampling), prints progress and
// writes checkpoints; the integrator only renders one pass into the film.
//
// Also here: what the passes of every integrator share: the camera ray of a pixel sample and the
// parallel loop over the pixels a pass samples.
#pragma once
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <cstdint>
#include <functional>
#include <string>

#include "base/interrupt.h"
#include "base/rng.h"
#include "base/sampling.h"
#include "camera/camera.h"
#include "film/film.h"
#include "film/filter.h"
#include "integrator/control.h"
#include "integrator/options.h"

namespace bpm {

struct PassResult {
  bool completed = true;  // false: the pass was abandoned (interrupted) and left the film as it was
  uint64_t rays = 0;      // rays traced so far in the render, for the progress line
  std::string progress;   // appended to the progress line
  // With completed false: why the integrator ends the render (e.g. "memory"); empty: the
  // interrupt or the time budget did.
  std::string stop_reason;
};

// Renders pass `pass` (0-based; random streams and radii follow pass + first_iteration) into the
// film, sampling the pixels control.sample_pixel chooses.
using PassFunction = std::function<PassResult(int pass, const RenderControl& control)>;

// What an integrator carries from one pass to the next besides the film (bpm's guide), saved for
// a checkpoint and loaded when resuming one; integrators without such state pass none.
struct IntegratorState {
  std::function<void(ByteWriter&)> save;
  std::function<void(ByteReader&)> load;
  // What the integrator learnt during a round, as sums that add across processes (appended to
  // the vector, then forgotten); merge takes such sums (its own, or every process's added) at
  // the round's end. Unset for integrators that learn nothing.
  std::function<void(std::vector<double>*)> learnt;
  std::function<void(const std::vector<double>&)> merge;
  // Takes such sums back as learnt and not yet merged: when several processes end inside a
  // round, process 0 keeps everyone's share for its final checkpoint.
  std::function<void(const std::vector<double>&)> keep_learnt;
};

// Runs passes until a budget ends the render (from opt.resume's state when given). `unit` names a
// pass in the progress line. Fills the passes, stop reason, time, mean sampling probability and
// error delta of `stats`. Calls opt.checkpoint and opt.save_state (integrator/options.h).
void run_passes(const IntegratorOptions& opt, Film* film, const char* unit,
                const PassFunction& pass, RenderStats* stats, const IntegratorState& state = {});

// One pixel sample: its random stream, keyed by (seed, pass index, pixel), which has already
// drawn the filter offset and the lens position; the camera ray and the pixel's footprint along
// it; the filter weight; the camera's weight of the ray, a factor of the radiance it brings (1 but
// for the realistic camera; 0 where its lens stops the ray: the sample counts as black).
struct CameraSample {
  Rng rng;
  Ray ray;
  float filter_weight;
  PixelFootprint footprint;
  float weight = 1;
  int medium = -1;  // the medium the ray starts in (the camera's)
  CameraRay camera_ray() const { return {ray, weight, medium}; }
};

class CameraSampler {
 public:
  CameraSampler(const CameraSettings& camera, const FilterSettings& filter, const Raster& raster,
                uint64_t seed)
      : camera_(camera, raster), filter_(filter), raster_(raster), seed_(seed) {}
  CameraSampler(const CameraSettings& camera, const FilterSettings& filter, int width, int height,
                uint64_t seed)
      : CameraSampler(camera, filter, Raster{width, height, width, height, 0, 0}, seed) {}
  // `sub` > 0: further samples of the same pixel and pass, each with its own stream. The stream is
  // keyed by the pixel's place in the full raster, so that a crop renders its pixels as the
  // whole image does.
  CameraSample sample(int pass_index, uint32_t pixel, uint32_t sub = 0) const {
    const int x = int(pixel % uint32_t(raster_.width)) + raster_.x0,
              y = int(pixel / uint32_t(raster_.width)) + raster_.y0;  // in the full raster
    Rng rng(stream_key(seed_, uint64_t(pass_index),
                       uint64_t(y) * uint64_t(raster_.full_width) + uint64_t(x), sub));
    FilterSample fs = filter_.sample({rng.uniform(), rng.uniform()});
    Vec2 p_film{x + 0.5f + fs.offset.x, y + 0.5f + fs.offset.y};
    Vec2 u_lens{rng.uniform(), rng.uniform()};
    const CameraRay r = camera_.generate_ray_full(p_film, u_lens);
    return {rng, r.ray, fs.weight, camera_.footprint(p_film), r.weight, r.medium};
  }
  // A uniform number of a pixel's pass, stratified over the passes of its stream (Film::kStreams):
  // the t-th pass of a stream takes point t of the van der Corput sequence under a random digital
  // shift of the pixel's and the stream's own, so that the stream's first 2^m passes put one
  // number in each 2^-m of [0, 1). For one pass alone it is uniform and independent of the pass's
  // random stream, and the streams stay independent estimates of each other.
  float stream_uniform(int pass_index, uint32_t pixel) const {
    const int x = int(pixel % uint32_t(raster_.width)) + raster_.x0,
              y = int(pixel / uint32_t(raster_.width)) + raster_.y0;  // in the full raster
    const int stream = pass_index % Film::kStreams;
    Rng rng(stream_key(seed_ ^ 0x666c69676874ull, uint64_t(stream),
                       uint64_t(y) * uint64_t(raster_.full_width) + uint64_t(x), 5));
    const uint32_t bits =
        owen_van_der_corput_bits(uint32_t(pass_index / Film::kStreams), rng.next_u32());
    return float(bits >> 8) * 0x1p-24f;
  }
  const Camera& camera() const { return camera_; }
  const Filter& filter() const { return filter_; }

 private:
  Camera camera_;
  Filter filter_;
  Raster raster_;
  uint64_t seed_;
};

// Records a pixel's estimate of this pass: the radiance at the pass's wavelengths as film colour.
// A debiased estimate (PhotonSettings::debias) may be negative where the noise is: it is recorded
// as it is (still not when it is not finite), with the clamp on its largest magnitude.
inline void record_pass(Film* film, uint32_t pixel, const Spectrum& L, const Wavelengths& wl,
                        float filter_weight, float max_component_value,
                        bool may_be_negative = false) {
  int x = int(pixel % uint32_t(film->width())), y = int(pixel / uint32_t(film->width()));
  film->add_spectrum(x, y, L, wl, filter_weight, max_component_value);
  if (may_be_negative && L.is_finite()) {
    FilmSample f{film->rgb_of(L, wl), spectrum_to_luminance(L, wl)};
    const float m = std::fmax(f.rgb.max_component(), -f.rgb.min_component());
    if (m > max_component_value) {
      f.rgb *= max_component_value / m;
      f.luminance *= max_component_value / m;
    }
    film->add_sample(x, y, f, filter_weight);
  } else {
    if (!recordable(L)) film->drop_sample(x, y);
    film->add_sample(x, y, film->sample_of(L, wl, max_component_value), filter_weight);
  }
  film->end_pass(x, y);
}

// Calls f(pixel) for every pixel that pass samples, over 16 x 16 tiles in parallel; tiles not yet
// started when control.cut(pass) turns true (an interrupt, the time budget) are skipped: their
// pixels are not sampled in this pass, as with adaptive sampling.
template <class F>
void for_each_sampled_pixel(int width, int height, const RenderControl& control, int pass, F&& f) {
  tbb::parallel_for(tbb::blocked_range2d<int>(0, height, 16, 0, width, 16),
                    [&](const tbb::blocked_range2d<int>& r) {
                      if (control.cut(pass)) return;
                      for (int y = r.rows().begin(); y < r.rows().end(); ++y)
                        for (int x = r.cols().begin(); x < r.cols().end(); ++x) {
                          uint32_t pixel = uint32_t(y) * uint32_t(width) + uint32_t(x);
                          if (control.sample_pixel(pass, pixel)) f(pixel);
                        }
                    });
}

}  // namespace bpm
