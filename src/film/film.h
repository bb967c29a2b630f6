// Per-pixel accumulation of weighted radiance samples. A pixel is only ever written by the thread
// rendering it, so no atomics are needed. A film records four channels: the colour (linear sRGB,
// R G B) and the photopic luminance Y, computed from the sample's wavelengths (cd/m^2 when the
// scene states its light in pbrt-v4's photometric terms). Alongside the weighted sums, the film
// keeps per pixel and channel the sum and sum of squares of the per-pass estimates, from which the
// error estimate of the paper's eq. (5) follows.
//
// Adaptive sampling (integrator/control.h) decides from a pixel's passes so far how often the
// next round of passes samples it. The plain mean over the passes that sampled a pixel would then
// be biased: a pixel whose passes so far drew none of its rare bright paths looks converged, is
// sampled less, and keeps its low mean longer, so in scenes of heavy-tailed estimates (a small
// light in fog) whole images read percents dark. The film therefore keeps each round's mean apart
// (the passes that sampled the pixel in it) and weighs the rounds by their lengths in passes,
// which the pixels' data never change: each round's mean is unbiased (which passes of a round
// sample a pixel is decided before the round), and so is their fixed-weight average. Every pixel
// is sampled in the first pass of each round (RenderControl::sample_pixel), so no round of it is
// empty.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "base/bytes.h"
#include "base/color.h"
#include "base/spectrum.h"
#include "film/camera_response.h"

namespace bpm {

// Where an image lies in a larger one (a crop of a camera's raster): its top-left pixel (x0, y0)
// in a width x height display window; width 0: the image is the whole window.
struct DisplayWindow {
  int x0 = 0, y0 = 0, width = 0, height = 0;
};

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // width * height * 3, row-major from the top
  DisplayWindow window;    // OpenEXR's data window within its display window
  Rgb at(int x, int y) const {
    size_t i = 3 * (size_t(y) * width + x);
    return Rgb(rgb[i], rgb[i + 1], rgb[i + 2]);
  }
};

// Whether a sample's radiance can be recorded: a non-finite or negative spectral value is a
// numerical accident, recorded as black (Film::drop_sample counts it) rather than poisoning the
// pixel.
inline bool recordable(const Spectrum& L) { return L.is_finite() && !L.has_negative(); }

// What a film records of one sample: its colour and its luminance.
struct FilmSample {
  Rgb rgb;
  float luminance = 0;
};

// Scales a sample down when its largest colour channel exceeds max_value (pbrt-v4's
// maxcomponentvalue), its luminance with it.
inline FilmSample clamp_sample(FilmSample f, float max_value) {
  const float m = f.rgb.max_component();
  if (m > max_value) {
    f.rgb *= max_value / m;
    f.luminance *= max_value / m;
  }
  return f;
}

// pbrt-v4's "spectral" film: besides the colour, `count` buckets evenly over [lambda_min,
// lambda_max] nm, each the mean over the samples that fell in it of the radiance at their
// wavelengths (sampled uniformly over the range), in pbrt-v4's units: the spectrum whose ybar-
// weighted mean is the luminance (cd/m^2 where lights are stated photometrically), i.e. spectral
// radiance in W m^-2 sr^-1 nm^-1 times 683 lm/W times the integral of ybar (106.857 nm). count 0:
// no buckets.
struct SpectralBuckets {
  int count = 0;
  float lambda_min = 360, lambda_max = 830;
  int bucket(float lambda) const {
    const int b = int(float(count) * (lambda - lambda_min) / (lambda_max - lambda_min));
    return b < 0 ? 0 : b >= count ? count - 1 : b;
  }
  bool operator==(const SpectralBuckets&) const = default;
  // A sample's wavelengths: uniform over the buckets' range for a spectral film (as pbrt-v4's),
  // else importance-sampled over the visible range.
  Wavelengths wavelengths(float u) const {
    return count > 0 ? sample_wavelengths_uniform(u, lambda_min, lambda_max)
                     : sample_wavelengths(u);
  }
};

class Film {
 public:
  // A render's passes form kStreams streams, pass j in stream j mod kStreams, whose means are
  // independent estimates even where the passes of one stream are not independent of each other:
  // the photon methods stratify their iterations' wavelengths within a stream
  // (photons/light_path.h). The sensors keep each stream's sum.
  static constexpr int kStreams = 8;
  // m_images > 0 also keeps the paper's M intermediate images (section 4): pass j goes to image
  // j mod M (begin_pass), and the spread between the M images is a second error estimate (with
  // M a divisor of kStreams, each image holds whole streams). sensors: illuminance sensors
  // (integrator/sensors.h) whose per-pass estimates the film keeps too.
  Film(int width, int height, int m_images = 0, size_t sensors = 0);
  // Whether the passes are independent estimates (the default; a path tracer's): the standard
  // error is then eq. 5 over the passes. Where they are not (the photon methods), it is the
  // spread between the M images (or, for a sensor, between the streams) once each has a pass,
  // and eq. 5, an upper bound, until then.
  void set_independent_passes(bool independent) { independent_ = independent; }
  // A 3 x 3 matrix (row-major) every sample's and bias estimate's colour goes through before it
  // is recorded: the film's white balance (base/color.h); none by default. The luminance is
  // never changed.
  void set_colour_matrix(const std::array<float, 9>& m) {
    colour_matrix_ = m;
    has_colour_matrix_ = true;
  }
  // The film's spectral response (a named camera sensor); the CIE matching functions when none.
  void set_response(std::shared_ptr<const CameraResponse> r) { response_ = std::move(r); }
  // Linear sRGB of the estimate L at the wavelengths wl, through the film's response.
  Rgb rgb_of(const Spectrum& L, const Wavelengths& wl) const {
    return response_ ? response_->to_rgb(L, wl) : spectrum_to_rgb(L, wl);
  }
  // The sample the film records for radiance L at wavelengths wl: linear sRGB and the luminance,
  // clamped to max_value (clamp_sample); black unless recordable(L). Colours may have negative
  // channels: a single sample's few wavelengths can lie outside the sRGB gamut.
  FilmSample sample_of(const Spectrum& L, const Wavelengths& wl, float max_value) const {
    if (!recordable(L)) return {};
    return clamp_sample({rgb_of(L, wl), spectrum_to_luminance(L, wl)}, max_value);
  }
  bool independent_passes() const { return independent_; }
  // Keeps spectral buckets (none by default); forgets what they held.
  void set_spectral(const SpectralBuckets& b) {
    spectral_ = b;
    bucket_sums_.assign(pixels_.size() * 3 * size_t(b.count), 0.0);
  }
  const SpectralBuckets& spectral() const { return spectral_; }
  // Records a sample's radiance at its wavelengths into the buckets (clamped as sample_of
  // clamps its colour, by its largest spectral value); no-op without buckets.
  void add_spectrum(int x, int y, const Spectrum& L, const Wavelengths& wl, float weight,
                    float max_value) {
    if (spectral_.count == 0 || !recordable(L)) return;
    const float m = L.max_component(), k = m > max_value ? max_value / m : 1;
    double* sums = bucket_sums_.data() + (size_t(y) * width_ + x) * 3 * size_t(spectral_.count);
    for (int i = 0; i < Spectrum::kChannels; ++i) {
      const int b = spectral_.bucket(wl.lambda[size_t(i)]);
      sums[3 * b + 1] += double(weight) * k * L[i];
      sums[3 * b + 2] += weight;
    }
  }
  // Bucket b's image (width * height), in pbrt-v4's units (SpectralBuckets).
  std::vector<float> bucket_image(int b) const;
  int width() const { return width_; }
  int height() const { return height_; }
  // What a film takes per pixel with m_images intermediate images, and what this one takes.
  static size_t bytes_per_pixel(int m_images) {
    return sizeof(Pixel) + size_t(m_images) * (kChannels * sizeof(float) + sizeof(int));
  }
  size_t bytes() const {
    return size_t(width_) * size_t(height_) * bytes_per_pixel(m_) +
           sensors_.size() * sizeof(SensorSums) + bucket_sums_.size() * sizeof(double);
  }

  void add_sample(int x, int y, const FilmSample& s, float weight) {
    Pixel& p = pixels_[size_t(y) * width_ + x];
    const Rgb c = colour(s.rgb);
    const float v[kChannels] = {c[0], c[1], c[2], s.luminance};
    for (int c = 0; c < kChannels; ++c) p.pass_wl[c] += double(weight) * v[c];
    p.pass_w += weight;
  }
  // The photon methods' estimate of this pass's bias in the pixel (film colour, the same units as
  // its estimate): 2 (L(r) - L(r / sqrt 2)) from the photons gathered over the radius r and over
  // the inner half of its area (bias.h), of the colour and the luminance. Called at most once per
  // pass, before end_pass.
  void add_bias(int x, int y, const Rgb& b, float b_luminance) {
    Pixel& p = pixels_[size_t(y) * width_ + x];
    const Rgb c = colour(b);
    const float v[kChannels] = {c[0], c[1], c[2], b_luminance};
    for (int c = 0; c < kChannels; ++c) {
      p.sum_b[c] += v[c];
      p.sum_b2[c] += double(v[c]) * v[c];
    }
    ++p.bias_passes;
  }
  // Counts a sample of the pixel that was not recordable (and was recorded as black).
  void drop_sample(int x, int y) { ++pixels_[size_t(y) * width_ + x].dropped; }
  uint64_t dropped_samples() const;
  // The render's index of the pass about to be recorded: it chooses each pixel's M-image (pass
  // j goes to image j mod M), so that passes rendered apart (integrator/team.h) land where one
  // process puts them. The pass counts in the length of the open round.
  void begin_pass(int index) {
    pass_index_ = index;
    ++round_length_;
  }
  // Ends the open round of passes: each pixel's mean over the round's passes that sampled it joins
  // its estimate with the weight of the round's length in passes (every pass begun since the last
  // end_round, by this film or by the films added to it).
  void end_round();
  // Ends the current pass for one pixel: its pass estimate joins the running moments.
  void end_pass(int x, int y) {
    Pixel& p = pixels_[size_t(y) * width_ + x];
    if (p.pass_w != 0) {
      double e[kChannels];
      for (int c = 0; c < kChannels; ++c) {
        e[c] = p.pass_wl[c] / p.pass_w;
        p.sum_e[c] += e[c];
        p.sum_e2[c] += e[c] * e[c];
      }
      for (int c = 0; c < kChannels; ++c) p.round_wl[c] += p.pass_wl[c];
      p.weight_sum += p.pass_w;
      ++p.round_passes;
      if (e[0] != 0 || e[1] != 0 || e[2] != 0) ++p.lit_passes;
      if (m_ > 0) {
        const size_t k = (size_t(y) * width_ + x) * size_t(m_) + size_t(pass_index_ % m_);
        for (int c = 0; c < kChannels; ++c) m_sum_[kChannels * k + c] += float(e[c]);
        ++m_count_[k];
      }
      ++p.passes;
    }
    p.pass_wl[0] = p.pass_wl[1] = p.pass_wl[2] = p.pass_wl[3] = p.pass_w = 0;
  }

  // One pass's estimate of sensor i and the estimate of its bias (photon methods; each sensor
  // written by one thread at a time), and per sensor the mean of its passes, the standard error of
  // that mean (eq. 5, or the spread between the streams: set_independent_passes), the mean of the
  // bias estimates, the total error (as the pixels' total_rms: the standard error and the part of
  // the bias estimate beyond its own noise) and its passes.
  void add_sensor_pass(size_t i, double value, double bias = 0) {
    SensorSums& s = sensors_[i];
    s.sum += value;
    s.sum2 += value * value;
    s.bias_sum += bias;
    s.bias_sum2 += bias * bias;
    ++s.passes;
    s.stream_sum[pass_index_ % kStreams] += value;
    ++s.stream_passes[pass_index_ % kStreams];
  }
  size_t sensor_count() const { return sensors_.size(); }
  double sensor_mean(size_t i) const;
  double sensor_standard_error(size_t i) const;
  double sensor_bias(size_t i) const;
  double sensor_total_error(size_t i) const;
  // delta (eq. 4) over the sensors: sqrt(sum total error^2 / sum value^2), 0 without sensors.
  double sensor_relative_error() const;
  int sensor_passes(size_t i) const { return sensors_[i].passes; }

  Image image(float scale = 1) const;
  // Per-pixel standard error of the mean of each channel, R G B per pixel, and of the luminance
  // (eq. 5, or the M images' spread: set_independent_passes).
  std::vector<float> rms_rgb() const;
  std::vector<float> rms() const;
  // The luminance per pixel (the mean of its samples, as image()); its bias estimate (zero
  // without one) and its total error, sqrt(rms^2 + bias^2) with bias^2 as total_rms_rgb's.
  std::vector<float> luminance_image() const;
  std::vector<float> bias_luminance() const;
  std::vector<float> total_rms_luminance() const;
  // The image error delta (eq. 4) over the three channels, sqrt(sum RMS_ic^2 / sum L_ic^2): what
  // the accuracy budget and the progress line use, so that an error of colour counts; and delta
  // of the luminance alone.
  double relative_error() const;
  double relative_error_luminance() const;
  // The bias estimate (add_bias): per pixel its mean over the passes, R G B (zero without one);
  // and delta of it, sqrt(sum bias^2 / sum L^2) over pixels and channels, where each pixel's
  // bias^2 is estimated without the noise of its estimate (mean^2 minus its standard error^2,
  // summed over the image before the root, never below zero).
  bool has_bias() const;
  std::vector<float> bias_rgb() const;
  std::vector<float> bias_standard_error_rgb() const;  // of bias_rgb(), eq. (5) over its passes
  // Per pixel and channel the total error, sqrt(RMS^2 + bias^2), with bias^2 the part of the mean
  // bias estimate's square beyond what its noise alone gives (film.cpp, bias_beyond_noise; a
  // single pixel's bias estimate is noisier than its value); rms_rgb() without a bias estimate.
  std::vector<float> total_rms_rgb() const;
  double relative_error_bias() const;
  // The total error: sqrt(delta^2 + delta_bias^2), noise and bias together (what --accuracy
  // bounds); delta alone for an integrator without a bias estimate.
  double relative_error_total() const;
  std::vector<float> pass_counts() const;
  // Per pixel, the passes whose estimate was not black: a pixel without any has no error estimate
  // yet (its RMS is zero because nothing was found, not because it converged).
  std::vector<int> lit_pass_counts() const;
  // The M-images estimates: per-pixel standard error of the mean from the spread of the M image
  // means (per channel, and of the luminance), and delta over the channels from them. Zero until
  // every image of a pixel has a pass. Their sums are single precision: they give the spread
  // only, never the image.
  int m_images() const { return m_; }
  std::vector<float> rms_m_images_rgb() const;
  std::vector<float> rms_m_images() const;
  double relative_error_m_images() const;

  // Adds another film's sums (of other passes) to this one's, as if its passes had been recorded
  // here; clear() forgets every pass. Both films must have the same size and M.
  void add(const Film& other);
  void clear();
  // Every per-pixel sum the film keeps, for a checkpoint; load() takes them back (between passes)
  // into a film of the same size and M, and throws Error naming what differs otherwise.
  void save(ByteWriter& w) const;
  void load(ByteReader& r);

 private:
  // eq. (4) from per-pixel standard errors of the three channels.
  double delta_rgb(const std::vector<float>& rms_rgb) const;
  static constexpr int kChannels = 4, kY = 3;  // R, G, B and the luminance
  struct Pixel {
    // The rounds ended (end_round): the sum over them of the round's length times its mean per
    // pass of weight * value (over the passes that sampled the pixel), the sum of the lengths,
    // and the sum of length^2 / those passes (for its error). The estimate divides the mean by
    // the samples' mean weight over every pass (weight_sum / passes): a filter's weights,
    // signed for a filter with negative lobes, which are too few in one round to divide by.
    double sum_wl[kChannels] = {};
    double sum_w = 0, sum_w2_n = 0;
    double round_wl[kChannels] = {};  // the open round's sums of weight * value
    int round_passes = 0;             // the open round's passes that sampled the pixel
    double weight_sum = 0;
    double pass_wl[kChannels] = {}, pass_w = 0;
    double sum_e[kChannels] = {}, sum_e2[kChannels] = {};  // per-pass estimates, per channel
    int passes = 0;
    int lit_passes = 0;                                    // passes whose estimate was not black
    int dropped = 0;                                       // samples not recordable (drop_sample)
    double sum_b[kChannels] = {}, sum_b2[kChannels] = {};  // per-pass bias estimates (add_bias)
    int bias_passes = 0;
  };
  struct SensorSums {
    double sum = 0, sum2 = 0, bias_sum = 0, bias_sum2 = 0;
    int passes = 0;
    double stream_sum[kStreams] = {};
    int stream_passes[kStreams] = {};
  };
  Rgb colour(const Rgb& c) const {
    if (!has_colour_matrix_) return c;
    const float* m = colour_matrix_.data();
    return Rgb(m[0] * c[0] + m[1] * c[1] + m[2] * c[2], m[3] * c[0] + m[4] * c[1] + m[5] * c[2],
               m[6] * c[0] + m[7] * c[1] + m[8] * c[2]);
  }
  // Pixel i's estimate of channel c: its rounds' means weighted by their lengths, the open round's
  // by the passes begun in it.
  double mean(size_t i, int c) const;
  // The same weighing of one sum per pass, given its rounds ended (`ended`, as Pixel::sum_wl) and
  // its open round (`open`, as Pixel::round_wl); 0 where p has no pass.
  double per_pass(const Pixel& p, double ended, double open) const {
    const double w = open_weight(p), total = p.sum_w + w;
    return total != 0 ? (ended + (w > 0 ? w * open / p.round_passes : 0.0)) / total : 0.0;
  }
  // The open round's weight in pixel p: its length, or where passes were recorded without
  // begin_pass, the passes that sampled p.
  double open_weight(const Pixel& p) const {
    return p.round_passes > 0 ? std::max(double(round_length_), double(p.round_passes)) : 0.0;
  }
  // The standard error of pixel i's channel c (rms_rgb), and the M images' (none until each has
  // a pass).
  float noise(size_t i, int c) const;
  std::optional<float> image_spread(size_t i, int c) const;
  int width_, height_;
  std::vector<Pixel> pixels_;
  std::vector<SensorSums> sensors_;
  int m_ = 0;
  int pass_index_ = 0;
  int round_length_ = 0;  // passes begun since the last end_round
  bool independent_ = true;
  bool has_colour_matrix_ = false;
  std::shared_ptr<const CameraResponse> response_;
  std::array<float, 9> colour_matrix_{};
  SpectralBuckets spectral_;
  // [pixel][bucket][3]: as Pixel's sum_wl, round_wl and weight_sum, of the radiance at the
  // wavelengths that fell in the bucket and of their weights.
  std::vector<double> bucket_sums_;
  std::vector<float> m_sum_;  // [pixel][image][channel]
  std::vector<int> m_count_;  // [pixel][image]
};

}  // namespace bpm
