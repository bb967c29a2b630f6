#include "film/film.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace bpm {
namespace {

// Calls f(i) for every pixel i, in parallel.
template <class F>
void for_pixels(size_t n, F&& f) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i < r.end(); ++i) f(i);
                    });
}

// eq. (5): RMS^2 = (1/N) (mean(L^2) - mean(L)^2), with Bessel's correction: the standard error of
// the mean of N pass estimates whose sum and sum of squares are given.
float standard_error(double sum, double sum2, int passes) {
  if (passes < 2) return 0;
  double n = passes, mean = sum / n;
  double var = std::fmax(0.0, (sum2 / n - mean * mean)) * n / (n - 1);
  return float(std::sqrt(var / n));
}

// The square of one pixel's or sensor's bias beyond its noise, from the mean b of its bias
// estimates and that mean's standard error se: b^2 less what noise alone gives b^2 on average
// (se^2) and two standard deviations of it (2 sqrt(2) se^2), never below zero. Over an even photon
// density each photon weighs +-2 in the r^2 bias estimate and 1 in the value, so the estimate is
// twice as noisy as the value (se = 2 se_value). Pure noise (b / se standard normal) then adds
// E[max(0, z^2 - k)] se^2 on average: with k = 1 (the noise's mean alone) 0.48 se^2, stating
// twice the actual error where there is no bias; with k = 1 + sqrt 2 0.20 se^2 (1.34 times it);
// with k = 1 + 2 sqrt 2 0.088 se^2 (1.16 times it). A bias is counted from 2 se on (where the
// value's noise is about 4 times smaller), nearly in full from several se.
double bias_beyond_noise(double b, double se) {
  return std::fmax(0.0, b * b - (1 + 2 * std::sqrt(2.0)) * se * se);
}

// The error of the average of m independent estimates value(k) from their spread: the standard
// deviation between them over sqrt(m). None while some value(k) is none (an image or stream
// without a pass yet).
template <class Value>
std::optional<double> spread_error(int m, Value&& value) {
  constexpr int kMost = 64;  // --m-images is at most this
  double v[kMost], mean = 0, var = 0;
  if (m < 2 || m > kMost) return std::nullopt;
  for (int k = 0; k < m; ++k) {
    const std::optional<double> x = value(k);
    if (!x) return std::nullopt;
    v[k] = *x;
    mean += *x / m;
  }
  for (int k = 0; k < m; ++k) var += (v[k] - mean) * (v[k] - mean);
  return std::sqrt(var / (m - 1) / m);
}

}  // namespace

Film::Film(int width, int height, int m_images, size_t sensors)
    : width_(width),
      height_(height),
      pixels_(size_t(width) * height),
      sensors_(sensors),
      m_(m_images > 1 ? m_images : 0) {
  m_sum_.assign(pixels_.size() * size_t(m_) * kChannels, 0.0f);
  m_count_.assign(pixels_.size() * size_t(m_), 0);
}

double Film::sensor_mean(size_t i) const {
  return sensors_[i].passes > 0 ? sensors_[i].sum / sensors_[i].passes : 0;
}

double Film::sensor_bias(size_t i) const {
  return sensors_[i].passes > 0 ? sensors_[i].bias_sum / sensors_[i].passes : 0;
}

double Film::sensor_total_error(size_t i) const {
  const SensorSums& s = sensors_[i];
  const double se = sensor_standard_error(i), b = sensor_bias(i);
  const double b_se = standard_error(s.bias_sum, s.bias_sum2, s.passes);
  return std::sqrt(se * se + bias_beyond_noise(b, b_se));
}

double Film::sensor_relative_error() const {
  double e2 = 0, v2 = 0;
  for (size_t i = 0; i < sensors_.size(); ++i) {
    e2 += std::pow(sensor_total_error(i), 2);
    v2 += std::pow(sensor_mean(i), 2);
  }
  return v2 > 0 ? std::sqrt(e2 / v2) : 0;
}

double Film::sensor_standard_error(size_t i) const {
  const SensorSums& s = sensors_[i];
  if (!independent_) {
    const std::optional<double> e = spread_error(kStreams, [&](int k) -> std::optional<double> {
      if (s.stream_passes[k] == 0) return std::nullopt;
      return s.stream_sum[k] / s.stream_passes[k];
    });
    if (e) return *e;
  }
  return standard_error(s.sum, s.sum2, s.passes);
}

void Film::end_round() {
  const size_t nb = size_t(spectral_.count);
  for_pixels(pixels_.size(), [&](size_t i) {
    Pixel& p = pixels_[i];
    const double w = open_weight(p), n = std::max(1, p.round_passes);
    if (w > 0) {
      for (int c = 0; c < kChannels; ++c) p.sum_wl[c] += w * p.round_wl[c] / n;
      for (size_t b = i * nb; b < (i + 1) * nb; ++b)
        bucket_sums_[3 * b] += w * bucket_sums_[3 * b + 1] / n;
      p.sum_w += w;
      p.sum_w2_n += w * w / n;
    }
    for (int c = 0; c < kChannels; ++c) p.round_wl[c] = 0;
    p.round_passes = 0;
    for (size_t b = i * nb; b < (i + 1) * nb; ++b) bucket_sums_[3 * b + 1] = 0;
  });
  round_length_ = 0;
}

double Film::mean(size_t i, int c) const {
  const Pixel& p = pixels_[i];
  if (p.weight_sum == 0) return 0;
  return per_pass(p, p.sum_wl[c], p.round_wl[c]) / (p.weight_sum / p.passes);
}

Image Film::image(float scale) const {
  Image img;
  img.width = width_;
  img.height = height_;
  img.rgb.resize(pixels_.size() * 3);
  for_pixels(pixels_.size(), [&](size_t i) {
    for (int c = 0; c < 3; ++c) img.rgb[3 * i + c] = float(scale * mean(i, c));
  });
  return img;
}

float Film::noise(size_t i, int c) const {
  // The error of the mean of the passes (eq. 5, or the M images' spread), times what weighing
  // the rounds by their lengths rather than by their passes makes of it: with n passes of
  // variance V, the rounds' weights w_r over n_r passes each give V sum w_r^2 / n_r / (sum w_r)^2
  // for V / n (1 where every pass sampled the pixel).
  const Pixel& p = pixels_[i];
  const double w = open_weight(p), total = p.sum_w + w;
  const double w2_n = p.sum_w2_n + (w > 0 ? w * w / std::max(1, p.round_passes) : 0.0);
  const double rounds = total > 0 ? std::sqrt(double(p.passes) * w2_n) / total : 1.0;
  if (!independent_) {
    const std::optional<float> e = image_spread(i, c);
    if (e) return float(*e * rounds);
  }
  return float(standard_error(p.sum_e[c], p.sum_e2[c], p.passes) * rounds);
}

std::vector<float> Film::rms_rgb() const {
  std::vector<float> out(pixels_.size() * 3, 0.0f);
  for_pixels(pixels_.size(), [&](size_t i) {
    for (int c = 0; c < 3; ++c) out[3 * i + c] = noise(i, c);
  });
  return out;
}

std::vector<float> Film::rms() const {
  std::vector<float> out(pixels_.size(), 0.0f);
  for_pixels(pixels_.size(), [&](size_t i) { out[i] = noise(i, kY); });
  return out;
}

std::vector<float> Film::luminance_image() const {
  std::vector<float> out(pixels_.size(), 0.0f);
  for_pixels(pixels_.size(), [&](size_t i) { out[i] = float(mean(i, kY)); });
  return out;
}

std::vector<float> Film::bias_luminance() const {
  std::vector<float> out(pixels_.size(), 0.0f);
  for (size_t i = 0; i < pixels_.size(); ++i) {
    const Pixel& p = pixels_[i];
    if (p.bias_passes > 0) out[i] = float(p.sum_b[kY] / p.bias_passes);
  }
  return out;
}

std::vector<float> Film::total_rms_luminance() const {
  std::vector<float> out = rms();
  for_pixels(pixels_.size(), [&](size_t i) {
    const Pixel& p = pixels_[i];
    if (p.bias_passes == 0) return;
    const double b = p.sum_b[kY] / p.bias_passes;
    const double se = standard_error(p.sum_b[kY], p.sum_b2[kY], p.bias_passes);
    out[i] = float(std::sqrt(double(out[i]) * out[i] + bias_beyond_noise(b, se)));
  });
  return out;
}

namespace {

// sqrt(sum of term(i, c) / sum of mean_ic^2) over the channels c of the pixels i that have passes
// (eq. 4 with term = RMS_ic^2); 0 where either sum is not positive. Summed by fixed blocks of
// pixels in parallel, then over the blocks in order: the same bits for any thread count.
template <class Pixels, class Term>
double relative_to_means(const Pixels& pixels, Term&& term) {
  constexpr size_t kBlock = 4096;
  const size_t n = pixels.size(), blocks = (n + kBlock - 1) / kBlock;
  std::vector<double> num(blocks, 0.0), den(blocks, 0.0);
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    for (size_t i = b * kBlock; i < std::min(n, (b + 1) * kBlock); ++i) {
      const auto& p = pixels[i];
      if (p.passes == 0) continue;
      for (int c = 0; c < 3; ++c) {
        const double mean = p.sum_e[c] / p.passes;
        den[b] += mean * mean;
        num[b] += term(i, c);
      }
    }
  });
  double total_num = 0, total_den = 0;
  for (size_t b = 0; b < blocks; ++b) {
    total_num += num[b];
    total_den += den[b];
  }
  return total_den > 0 && total_num > 0 ? std::sqrt(total_num / total_den) : 0;
}

}  // namespace

double Film::delta_rgb(const std::vector<float>& r) const {
  return relative_to_means(pixels_,
                           [&](size_t i, int c) { return double(r[3 * i + c]) * r[3 * i + c]; });
}

double Film::relative_error() const { return delta_rgb(rms_rgb()); }

bool Film::has_bias() const {
  for (const Pixel& p : pixels_)
    if (p.bias_passes > 0) return true;
  return false;
}

std::vector<float> Film::bias_rgb() const {
  std::vector<float> out(pixels_.size() * 3, 0.0f);
  for (size_t i = 0; i < pixels_.size(); ++i) {
    const Pixel& p = pixels_[i];
    if (p.bias_passes == 0) continue;
    for (int c = 0; c < 3; ++c) out[3 * i + c] = float(p.sum_b[c] / p.bias_passes);
  }
  return out;
}

std::vector<float> Film::bias_standard_error_rgb() const {
  std::vector<float> out(pixels_.size() * 3, 0.0f);
  for (size_t i = 0; i < pixels_.size(); ++i) {
    const Pixel& p = pixels_[i];
    for (int c = 0; c < 3; ++c)
      out[3 * i + c] = standard_error(p.sum_b[c], p.sum_b2[c], p.bias_passes);
  }
  return out;
}

std::vector<float> Film::total_rms_rgb() const {
  std::vector<float> out = rms_rgb();
  for_pixels(pixels_.size(), [&](size_t i) {
    const Pixel& p = pixels_[i];
    if (p.bias_passes == 0) return;
    for (int c = 0; c < 3; ++c) {
      double b = p.sum_b[c] / p.bias_passes;
      double se = standard_error(p.sum_b[c], p.sum_b2[c], p.bias_passes);
      double rms = out[3 * i + c];
      out[3 * i + c] = float(std::sqrt(rms * rms + bias_beyond_noise(b, se)));
    }
  });
  return out;
}

double Film::relative_error_bias() const {
  return relative_to_means(pixels_, [&](size_t i, int c) {
    const Pixel& p = pixels_[i];
    if (p.bias_passes == 0) return 0.0;
    const double b = p.sum_b[c] / p.bias_passes;
    const double se = standard_error(p.sum_b[c], p.sum_b2[c], p.bias_passes);
    return b * b - se * se;
  });
}

double Film::relative_error_total() const {
  double noise = relative_error(), bias = relative_error_bias();
  return std::sqrt(noise * noise + bias * bias);
}

double Film::relative_error_luminance() const {
  std::vector<float> r = rms();
  double num = 0, den = 0;
  for (size_t i = 0; i < pixels_.size(); ++i) {
    const Pixel& p = pixels_[i];
    if (p.passes == 0) continue;
    double mean = p.sum_e[kY] / p.passes;
    num += double(r[i]) * r[i];
    den += mean * mean;
  }
  return den > 0 ? std::sqrt(num / den) : 0;  // eq. (4)
}

std::optional<float> Film::image_spread(size_t i, int c) const {
  if (m_ == 0) return std::nullopt;
  const int* count = &m_count_[i * size_t(m_)];
  const std::optional<double> e = spread_error(m_, [&](int k) -> std::optional<double> {
    if (count[k] == 0) return std::nullopt;
    return double(m_sum_[kChannels * (i * m_ + k) + c]) / count[k];
  });
  return e ? std::optional<float>(float(*e)) : std::nullopt;
}

std::vector<float> Film::rms_m_images_rgb() const {
  std::vector<float> out(pixels_.size() * 3, 0.0f);
  for_pixels(pixels_.size(), [&](size_t i) {
    for (int c = 0; c < 3; ++c) out[3 * i + c] = image_spread(i, c).value_or(0.0f);
  });
  return out;
}

std::vector<float> Film::rms_m_images() const {
  std::vector<float> out(pixels_.size(), 0.0f);
  for_pixels(pixels_.size(), [&](size_t i) { out[i] = image_spread(i, kY).value_or(0.0f); });
  return out;
}

double Film::relative_error_m_images() const { return m_ == 0 ? 0 : delta_rgb(rms_m_images_rgb()); }

std::vector<float> Film::pass_counts() const {
  std::vector<float> out(pixels_.size());
  for (size_t i = 0; i < pixels_.size(); ++i) out[i] = float(pixels_[i].passes);
  return out;
}

uint64_t Film::dropped_samples() const {
  uint64_t n = 0;
  for (const Pixel& p : pixels_) n += uint64_t(p.dropped);
  return n;
}

std::vector<int> Film::lit_pass_counts() const {
  std::vector<int> out(pixels_.size());
  for_pixels(pixels_.size(), [&](size_t i) { out[i] = pixels_[i].lit_passes; });
  return out;
}

void Film::add(const Film& o) {
  BPM_CHECK(o.width_ == width_ && o.height_ == height_ && o.m_ == m_);
  for (size_t i = 0; i < pixels_.size(); ++i) {
    Pixel& p = pixels_[i];
    const Pixel& q = o.pixels_[i];
    for (int c = 0; c < kChannels; ++c) {
      p.sum_wl[c] += q.sum_wl[c];
      p.sum_e[c] += q.sum_e[c];
      p.sum_e2[c] += q.sum_e2[c];
      p.sum_b[c] += q.sum_b[c];
      p.sum_b2[c] += q.sum_b2[c];
      p.round_wl[c] += q.round_wl[c];
    }
    p.sum_w += q.sum_w;
    p.sum_w2_n += q.sum_w2_n;
    p.weight_sum += q.weight_sum;
    p.round_passes += q.round_passes;
    p.passes += q.passes;
    p.lit_passes += q.lit_passes;
    p.dropped += q.dropped;
    p.bias_passes += q.bias_passes;
  }
  BPM_CHECK(o.sensors_.size() == sensors_.size());
  for (size_t i = 0; i < sensors_.size(); ++i) {
    sensors_[i].sum += o.sensors_[i].sum;
    sensors_[i].sum2 += o.sensors_[i].sum2;
    sensors_[i].bias_sum += o.sensors_[i].bias_sum;
    sensors_[i].bias_sum2 += o.sensors_[i].bias_sum2;
    sensors_[i].passes += o.sensors_[i].passes;
    for (int k = 0; k < kStreams; ++k) {
      sensors_[i].stream_sum[k] += o.sensors_[i].stream_sum[k];
      sensors_[i].stream_passes[k] += o.sensors_[i].stream_passes[k];
    }
  }
  BPM_CHECK(o.spectral_ == spectral_);
  for (size_t i = 0; i < bucket_sums_.size(); ++i) bucket_sums_[i] += o.bucket_sums_[i];
  round_length_ += o.round_length_;
  for (size_t i = 0; i < m_sum_.size(); ++i) m_sum_[i] += o.m_sum_[i];
  for (size_t i = 0; i < m_count_.size(); ++i) m_count_[i] += o.m_count_[i];
}

void Film::clear() {
  std::fill(pixels_.begin(), pixels_.end(), Pixel{});
  std::fill(sensors_.begin(), sensors_.end(), SensorSums{});
  std::fill(bucket_sums_.begin(), bucket_sums_.end(), 0.0);
  round_length_ = 0;
  std::fill(m_sum_.begin(), m_sum_.end(), 0.0f);
  std::fill(m_count_.begin(), m_count_.end(), 0);
}

void Film::save(ByteWriter& w) const {
  w.put(int32_t(width_));
  w.put(int32_t(height_));
  w.put(int32_t(m_));
  w.put_vector(pixels_);
  w.put_vector(m_sum_);
  w.put_vector(m_count_);
  w.put_vector(sensors_);
  w.put_vector(bucket_sums_);
  w.put(int32_t(round_length_));
}

void Film::load(ByteReader& r) {
  const int w = r.get<int32_t>(), h = r.get<int32_t>(), m = r.get<int32_t>();
  if (w != width_ || h != height_)
    throw Error(r.what() + " holds a " + std::to_string(w) + "x" + std::to_string(h) +
                " film, this render's is " + std::to_string(width_) + "x" +
                std::to_string(height_));
  if (m != m_)
    throw Error(r.what() + " keeps " + std::to_string(m) + " M-images, this render " +
                std::to_string(m_) + " (--m-images)");
  std::vector<Pixel> pixels = r.get_vector<Pixel>();
  std::vector<float> m_sum = r.get_vector<float>();
  std::vector<int> m_count = r.get_vector<int>();
  std::vector<SensorSums> sensors = r.get_vector<SensorSums>();
  std::vector<double> buckets = r.get_vector<double>();
  const int round_length = r.get<int32_t>();
  if (buckets.size() != bucket_sums_.size())
    throw Error(r.what() + " keeps " + std::to_string(buckets.size()) +
                " spectral sums, this render's film " + std::to_string(bucket_sums_.size()));
  if (pixels.size() != pixels_.size() || m_sum.size() != m_sum_.size() ||
      m_count.size() != m_count_.size())
    throw Error(r.what() + " is truncated or corrupt (film sizes)");
  if (sensors.size() != sensors_.size())
    throw Error(r.what() + " holds " + std::to_string(sensors.size()) + " sensors, this render " +
                std::to_string(sensors_.size()) + " (--sensors)");
  sensors_ = std::move(sensors);
  pixels_ = std::move(pixels);
  m_sum_ = std::move(m_sum);
  m_count_ = std::move(m_count);
  bucket_sums_ = std::move(buckets);
  round_length_ = round_length;
}

std::vector<float> Film::bucket_image(int b) const {
  std::vector<float> out(pixels_.size());
  const size_t n = size_t(spectral_.count);
  for_pixels(pixels_.size(), [&](size_t i) {
    const Pixel& p = pixels_[i];
    const double* sums = &bucket_sums_[3 * (i * n + size_t(b))];
    out[i] = sums[2] != 0 ? float(per_pass(p, sums[0], sums[1]) / (sums[2] / p.passes)) : 0.0f;
  });
  return out;
}

}  // namespace bpm
