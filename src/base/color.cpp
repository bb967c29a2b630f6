#include "base/color.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "base/vec.h"

namespace bpm {

void xyz_to_srgb(const double xyz[3], double rgb[3]) {
  rgb[0] = 3.2404542 * xyz[0] - 1.5371385 * xyz[1] - 0.4985314 * xyz[2];
  rgb[1] = -0.9692660 * xyz[0] + 1.8760108 * xyz[1] + 0.0415560 * xyz[2];
  rgb[2] = 0.0556434 * xyz[0] - 0.2040259 * xyz[1] + 1.0572252 * xyz[2];
}

Mat3 inverse(const Mat3& m) {
  const double det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                     m[2] * (m[3] * m[7] - m[4] * m[6]);
  const Mat3 adj{m[4] * m[8] - m[5] * m[7], m[2] * m[7] - m[1] * m[8], m[1] * m[5] - m[2] * m[4],
                 m[5] * m[6] - m[3] * m[8], m[0] * m[8] - m[2] * m[6], m[2] * m[3] - m[0] * m[5],
                 m[3] * m[7] - m[4] * m[6], m[1] * m[6] - m[0] * m[7], m[0] * m[4] - m[1] * m[3]};
  Mat3 r;
  for (int i = 0; i < 9; ++i) r[i] = adj[i] / det;
  return r;
}

namespace {

constexpr int kTableSize = int(kLambdaMax - kLambdaMin) + 1;  // 1 nm steps, both ends included

double lobe(double l, double mu, double s1, double s2) {
  double t = (l - mu) / (l < mu ? s1 : s2);
  return std::exp(-0.5 * t * t);
}

// CIE standard illuminant D65 (ISO 11664-2), 300 to 830 nm in 10 nm steps, 100 at 560 nm.
constexpr float kD65[] = {
    0.0341f,  3.2945f,  20.236f,  37.0535f, 39.9488f, 44.9117f, 46.6383f, 52.0891f, 49.9755f,
    54.6482f, 82.7549f, 91.486f,  93.4318f, 86.6823f, 104.865f, 117.008f, 117.812f, 114.861f,
    115.923f, 108.811f, 109.354f, 107.802f, 104.79f,  107.689f, 104.405f, 104.046f, 100.0f,
    96.3342f, 95.788f,  88.6856f, 90.0062f, 89.5991f, 87.6987f, 83.2886f, 83.6992f, 80.0268f,
    80.2146f, 82.2778f, 78.2842f, 69.7213f, 71.6091f, 74.349f,  61.604f,  69.8856f, 75.087f,
    63.5927f, 46.4182f, 66.8054f, 63.3828f, 64.304f,  59.4519f, 51.959f,  57.4406f, 60.3125f};

// The CIE daylight basis S0, S1, S2 (CIE 15), 300 to 830 nm in 10 nm steps.
constexpr float kDaylightS0[] = {
    0.04f,  6.0f,   29.6f,  55.3f,  57.3f,  61.8f,  61.5f,  68.8f,  63.4f,  65.8f,  94.8f,
    104.8f, 105.9f, 96.8f,  113.9f, 125.6f, 125.5f, 121.3f, 121.3f, 113.5f, 113.1f, 110.8f,
    106.5f, 108.8f, 105.3f, 104.4f, 100.0f, 96.0f,  95.1f,  89.1f,  90.5f,  90.3f,  88.4f,
    84.0f,  85.1f,  81.9f,  82.6f,  84.9f,  81.3f,  71.9f,  74.3f,  76.4f,  63.3f,  71.7f,
    77.0f,  65.2f,  47.7f,  68.6f,  65.0f,  66.0f,  61.0f,  53.3f,  58.9f,  61.9f};
constexpr float kDaylightS1[] = {
    0.02f,  4.5f,   22.4f,  42.0f,  40.6f,  41.6f,  38.0f,  42.4f,  38.5f,  35.0f,  43.4f,
    46.3f,  43.9f,  37.1f,  36.7f,  35.9f,  32.6f,  27.9f,  24.3f,  20.1f,  16.2f,  13.2f,
    8.6f,   6.1f,   4.2f,   1.9f,   -0.0f,  -1.6f,  -3.5f,  -3.5f,  -5.8f,  -7.2f,  -8.6f,
    -9.5f,  -10.9f, -10.7f, -12.0f, -14.0f, -13.6f, -12.0f, -13.3f, -12.9f, -10.6f, -11.6f,
    -12.2f, -10.2f, -7.8f,  -11.2f, -10.4f, -10.6f, -9.7f,  -8.3f,  -9.3f,  -9.8f};
constexpr float kDaylightS2[] = {0.0f,  2.0f,  4.0f,  8.5f,  7.8f,  6.7f,  5.3f,  6.1f,  3.0f,
                                 1.2f,  -1.1f, -0.5f, -0.7f, -1.2f, -2.6f, -2.9f, -2.8f, -2.6f,
                                 -2.6f, -1.8f, -1.5f, -1.3f, -1.2f, -1.0f, -0.5f, -0.3f, 0.0f,
                                 0.2f,  0.5f,  2.1f,  3.2f,  4.1f,  4.7f,  5.1f,  6.7f,  7.3f,
                                 8.6f,  9.8f,  10.2f, 8.3f,  9.6f,  8.5f,  7.0f,  7.6f,  8.0f,
                                 6.7f,  5.2f,  7.4f,  6.8f,  7.0f,  6.4f,  5.5f,  6.1f,  6.5f};

double daylight_basis(const float* s, double l) {
  double x = (l - 300) / 10;
  int i = std::clamp(int(x), 0, 52);
  double t = std::clamp(x - i, 0.0, 1.0);
  return s[i] * (1 - t) + s[i + 1] * t;
}

double d65_raw(double l) {
  double x = (l - 300) / 10;
  int i = std::clamp(int(x), 0, int(std::size(kD65)) - 2);
  double t = std::clamp(x - i, 0.0, 1.0);
  return kD65[i] * (1 - t) + kD65[i + 1] * t;
}

// Everything the conversions need, tabulated once at 1 nm.
struct Tables {
  double y_integral = 0;                         // integral of ybar
  double d65_scale = 0;                          // D65 raw -> unit luminance
  std::vector<float> d65;                        // unit-luminance D65
  std::vector<std::array<float, 3>> rgb_weight;  // sRGB of a unit spike at lambda, white balanced
  std::vector<std::array<float, 3>> rgb_weight_d65;  // the same times D65: a reflectance's colour
  std::vector<float> luminance_weight;               // ybar / its integral
  // rgb_weight_d65 gathered onto nodes every kNodeStep nm (each 1 nm weight split between its two
  // nodes linearly): the exact colour of the spectrum that is linear between the nodes.
  static constexpr int kNodeStep = 5, kNodes = (kTableSize - 1) / kNodeStep + 1;
  std::array<std::array<double, 3>, kNodes> node_weight_d65{};

  Tables() {
    d65.resize(kTableSize);
    rgb_weight.resize(kTableSize);
    rgb_weight_d65.resize(kTableSize);
    luminance_weight.resize(kTableSize);
    double d65_y = 0, white_xyz[3] = {0, 0, 0};
    for (int i = 0; i < kTableSize; ++i) {
      double l = kLambdaMin + i;
      y_integral += cie_y(float(l));
      d65_y += d65_raw(l) * cie_y(float(l));
    }
    d65_scale = y_integral / d65_y;
    for (int i = 0; i < kTableSize; ++i)
      luminance_weight[i] = float(cie_y(float(kLambdaMin + i)) / y_integral);
    for (int i = 0; i < kTableSize; ++i) {
      double l = kLambdaMin + i;
      d65[i] = float(d65_raw(l) * d65_scale);
      white_xyz[0] += d65[i] * cie_x(float(l)) / y_integral;
      white_xyz[1] += d65[i] * cie_y(float(l)) / y_integral;
      white_xyz[2] += d65[i] * cie_z(float(l)) / y_integral;
    }
    double white[3];
    xyz_to_srgb(white_xyz, white);
    for (int i = 0; i < kTableSize; ++i) {
      double l = kLambdaMin + i;
      double xyz[3] = {cie_x(float(l)) / y_integral, cie_y(float(l)) / y_integral,
                       cie_z(float(l)) / y_integral};
      double rgb[3];
      xyz_to_srgb(xyz, rgb);
      for (int c = 0; c < 3; ++c) {
        rgb_weight[i][c] = float(rgb[c] / white[c]);
        rgb_weight_d65[i][c] = rgb_weight[i][c] * d65[i];
      }
      int j = std::min(i / kNodeStep, kNodes - 2);
      double t = double(i - j * kNodeStep) / kNodeStep;
      for (int c = 0; c < 3; ++c) {
        node_weight_d65[j][c] += (1 - t) * rgb_weight_d65[i][c];
        node_weight_d65[j + 1][c] += t * rgb_weight_d65[i][c];
      }
    }
  }
};

const Tables& tables() {
  static const Tables t;
  return t;
}

template <typename T>
T lerp_table(const std::vector<T>& table, float lambda, T (*mix)(const T&, const T&, float)) {
  float x = std::clamp(lambda - kLambdaMin, 0.0f, float(kTableSize - 1));
  int i = std::min(int(x), kTableSize - 2);
  return mix(table[i], table[i + 1], x - float(i));
}
float mix_float(const float& a, const float& b, float t) { return a + (b - a) * t; }
std::array<float, 3> mix_rgb(const std::array<float, 3>& a, const std::array<float, 3>& b,
                             float t) {
  return {a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t};
}

// Visible-wavelength density: sech^2(a (lambda - mu)) normalised over the range.
constexpr double kPdfA = 0.0072, kPdfMu = 540;
double tanh_lo() { return std::tanh(kPdfA * (kLambdaMin - kPdfMu)); }
double tanh_hi() { return std::tanh(kPdfA * (kLambdaMax - kPdfMu)); }

// Colour (under D65) of the sigmoid spectrum with coefficients c, and its Jacobian: summed at 1 nm,
// or (coarse) with the spectrum sampled every 5 nm and joined linearly, which is five times faster
// and within about 5e-4 of the 1 nm sum.
void sigmoid_rgb(const std::array<double, 3>& c, double rgb[3], double jac[3][3], bool coarse) {
  const Tables& t = tables();
  // Summed in locals: the out-parameters could alias the tables, which would keep every sum in
  // memory.
  double sum[3] = {0, 0, 0}, d[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  const int n = coarse ? Tables::kNodes : kTableSize, step = coarse ? Tables::kNodeStep : 1;
  for (int j = 0; j < n; ++j) {
    double u = normalised_lambda(kLambdaMin + float(j * step));
    double x = (c[0] * u + c[1]) * u + c[2];
    double q = 1 / std::sqrt(1 + x * x);
    double s = 0.5 + 0.5 * x * q;
    double ds = 0.5 * q * q * q;
    double uu = u * u;
    for (int ch = 0; ch < 3; ++ch) {
      double w = coarse ? t.node_weight_d65[j][ch] : double(t.rgb_weight_d65[j][ch]);
      sum[ch] += w * s;
      double wds = w * ds;
      d[ch][0] += wds * uu;
      d[ch][1] += wds * u;
      d[ch][2] += wds;
    }
  }
  for (int ch = 0; ch < 3; ++ch) {
    rgb[ch] = sum[ch];
    for (int k = 0; k < 3; ++k) jac[ch][k] = d[ch][k];
  }
}

bool solve3(double a[3][3], const double b[3], double x[3]) {
  double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
               a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
               a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  if (!(std::fabs(det) > 1e-300)) return false;
  for (int col = 0; col < 3; ++col) {
    double m[3][3];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) m[r][c] = c == col ? b[r] : a[r][c];
    x[col] = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
              m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
              m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])) /
             det;
  }
  return true;
}

double max_abs_residual(const double rgb[3], const double target[3]) {
  return std::max({std::fabs(rgb[0] - target[0]), std::fabs(rgb[1] - target[1]),
                   std::fabs(rgb[2] - target[2])});
}

}  // namespace

float cie_x(float l) {
  return float(1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) -
               0.065 * lobe(l, 501.1, 20.4, 26.2));
}
float cie_y(float l) {
  return float(0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1));
}
float cie_z(float l) {
  return float(1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8));
}

float d65_unit(float lambda) { return lerp_table(tables().d65, lambda, mix_float); }

Wavelengths sample_wavelengths(float u) {
  Wavelengths wl;
  const double lo = tanh_lo(), hi = tanh_hi();
  for (int i = 0; i < Spectrum::kChannels; ++i) {
    double ui = u + double(i) / Spectrum::kChannels;
    if (ui >= 1) ui -= 1;
    double l = kPdfMu + std::atanh(lo + ui * (hi - lo)) / kPdfA;
    wl.lambda[i] = std::clamp(float(l), kLambdaMin, kLambdaMax);
    wl.pdf[i] = wavelength_pdf(wl.lambda[i]);
  }
  return wl;
}

Wavelengths sample_wavelengths_uniform(float u, float lo, float hi) {
  Wavelengths wl;
  for (int i = 0; i < Spectrum::kChannels; ++i) {
    double ui = u + double(i) / Spectrum::kChannels;
    if (ui >= 1) ui -= 1;
    wl.lambda[i] = std::clamp(float(lo + ui * (hi - lo)), lo, hi);
    wl.pdf[i] = 1 / (hi - lo);
  }
  return wl;
}

float wavelength_pdf(float lambda) {
  if (lambda < kLambdaMin || lambda > kLambdaMax) return 0;
  double c = std::cosh(kPdfA * (lambda - kPdfMu));
  return float(kPdfA / (c * c) / (tanh_hi() - tanh_lo()));
}

Rgb spectrum_to_rgb(const Spectrum& L, const Wavelengths& wl) {
  const Tables& t = tables();
  Rgb out;
  for (int i = 0; i < Spectrum::kChannels; ++i) {
    if (L[i] == 0 || wl.pdf[i] == 0) continue;
    std::array<float, 3> w = lerp_table(t.rgb_weight, wl.lambda[i], mix_rgb);
    float s = L[i] / (wl.pdf[i] * Spectrum::kChannels);
    for (int c = 0; c < 3; ++c) out[c] += w[c] * s;
  }
  return out;
}

float spectrum_to_luminance(const Spectrum& L, const Wavelengths& wl) {
  const Tables& t = tables();
  float y = 0;
  for (int i = 0; i < Spectrum::kChannels; ++i) {
    if (L[i] == 0 || wl.pdf[i] == 0) continue;
    y += lerp_table(t.luminance_weight, wl.lambda[i], mix_float) * L[i] /
         (wl.pdf[i] * Spectrum::kChannels);
  }
  return y;
}

float normalised_lambda(float lambda) { return (lambda - kLambdaMin) / (kLambdaMax - kLambdaMin); }

float sigmoid_spectrum(const std::array<float, 3>& c, float lambda) {
  return sigmoid_spectrum_at(c, normalised_lambda(lambda));
}

namespace {

// Sigmoid coefficients with the colour of their spectrum and its Jacobian, so that a solve that
// starts where the last one ended needs no new evaluation.
struct SigmoidFit {
  explicit SigmoidFit(bool coarse) : coarse(coarse) {}
  void set(const std::array<double, 3>& coefficients) {
    c = coefficients;
    sigmoid_rgb(c, rgb, jac, coarse);
  }

  bool coarse;
  std::array<double, 3> c{};
  double rgb[3] = {0, 0, 0}, jac[3][3] = {};
};

// Gauss-Newton with backtracking from fit toward the sigmoid whose colour is target; returns the
// largest remaining channel error.
double gauss_newton(SigmoidFit& fit, const double target[3], int max_iterations) {
  double residual = max_abs_residual(fit.rgb, target);
  for (int iter = 0; iter < max_iterations && residual >= 1e-6; ++iter) {
    double r[3] = {target[0] - fit.rgb[0], target[1] - fit.rgb[1], target[2] - fit.rgb[2]}, d[3];
    double jac[3][3];
    std::copy(&fit.jac[0][0], &fit.jac[0][0] + 9, &jac[0][0]);
    if (!solve3(jac, r, d)) break;
    double scale = 1;
    bool improved = false;
    for (int tries = 0; tries < 12 && !improved; ++tries, scale *= 0.5) {
      SigmoidFit trial(fit.coarse);
      const std::array<double, 3>& c = fit.c;
      trial.set({c[0] + scale * d[0], c[1] + scale * d[1], c[2] + scale * d[2]});
      double trial_residual = max_abs_residual(trial.rgb, target);
      if (trial_residual < residual) {
        fit = trial;
        residual = trial_residual;
        improved = true;
      }
    }
    if (!improved) break;
  }
  return residual;
}

// From the grey of the same mean, moving the target toward rgb in steps so that each solve starts
// close to its answer (saturated colours need large coefficients).
double fit_from_grey(const double target_end[3], SigmoidFit& fit) {
  double grey = std::clamp((target_end[0] + target_end[1] + target_end[2]) / 3.0, 0.02, 0.98);
  fit.set({0, 0, (2 * grey - 1) / (2 * std::sqrt(grey * (1 - grey)))});
  constexpr int kSteps = 8;
  double residual = 0;
  for (int step = 1; step <= kSteps; ++step) {
    double f = double(step) / kSteps, target[3];
    for (int i = 0; i < 3; ++i) target[i] = grey + (target_end[i] - grey) * f;
    residual = gauss_newton(fit, target, 40);
  }
  return residual;
}

// Coefficients for every albedo colour on a grid (pbrt-v4's RGBToSpectrumTable layout): for the
// largest channel l, its value z on kZ nodes crowded toward 0 and 1, and the other two channels as
// fractions x, y of z on kXY uniform nodes. Each fit starts from its neighbour's answer.
class SigmoidTable {
 public:
  static constexpr int kXY = 48, kZ = 48;

  SigmoidTable() {
    for (int k = 0; k < kZ; ++k) z_nodes_[k] = float(smootherstep(double(k) / (kZ - 1)));
    coeff_.resize(size_t(3) * kZ * kXY * kXY);
    // One chain per (l, y): along x at the middle z from a fit from grey, then along z both ways.
    tbb::parallel_for(0, 3 * kXY, [&](int task) {
      int l = task / kXY, yi = task % kXY;
      const int z_mid = kZ / 2;
      SigmoidFit fit(true);
      for (int xi = 0; xi < kXY; ++xi) {
        double target[3];
        node_rgb(l, z_mid, xi, yi, target);
        if (xi == 0 || gauss_newton(fit, target, 40) > 1e-4) fit_from_grey(target, fit);
        const SigmoidFit start = fit;
        at(l, z_mid, yi, xi) = to_float(fit.c);
        for (int dir : {1, -1}) {
          fit = start;
          for (int zi = z_mid + dir; zi >= 0 && zi < kZ; zi += dir) {
            node_rgb(l, zi, xi, yi, target);
            gauss_newton(fit, target, 40);
            at(l, zi, yi, xi) = to_float(fit.c);
          }
        }
        fit = start;
      }
    });
  }

  std::array<float, 3> lookup(Rgb rgb) const {
    int l = rgb[0] >= rgb[1] ? (rgb[0] >= rgb[2] ? 0 : 2) : (rgb[1] >= rgb[2] ? 1 : 2);
    float z = std::clamp(rgb[l], 0.0f, 1.0f);
    if (z <= 0) return {0, 0, -1e4f};
    float x = std::clamp(rgb[(l + 1) % 3] / z, 0.0f, 1.0f) * (kXY - 1);
    float y = std::clamp(rgb[(l + 2) % 3] / z, 0.0f, 1.0f) * (kXY - 1);
    int zi = int(std::upper_bound(z_nodes_.begin(), z_nodes_.end(), z) - z_nodes_.begin()) - 1;
    zi = std::clamp(zi, 0, kZ - 2);
    int xi = std::min(int(x), kXY - 2), yi = std::min(int(y), kXY - 2);
    float fx = x - xi, fy = y - yi;
    float fz = std::clamp((z - z_nodes_[zi]) / (z_nodes_[zi + 1] - z_nodes_[zi]), 0.0f, 1.0f);
    std::array<float, 3> out{};
    for (int dz = 0; dz < 2; ++dz)
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          float w = (dz ? fz : 1 - fz) * (dy ? fy : 1 - fy) * (dx ? fx : 1 - fx);
          const std::array<float, 3>& c = coeff_[index(l, zi + dz, yi + dy, xi + dx)];
          for (int i = 0; i < 3; ++i) out[i] += w * c[i];
        }
    return out;
  }

 private:
  static double smootherstep(double t) {
    double s = t * t * (3 - 2 * t);
    return s * s * (3 - 2 * s);
  }
  // The node's colour, kept a little inside the cube: a sigmoid never reaches 0 or 1.
  void node_rgb(int l, int zi, int xi, int yi, double out[3]) const {
    double z = std::clamp(double(z_nodes_[zi]), 1e-3, 0.999);
    out[l] = z;
    out[(l + 1) % 3] = std::max(z * xi / (kXY - 1), 1e-4);
    out[(l + 2) % 3] = std::max(z * yi / (kXY - 1), 1e-4);
  }
  static std::array<float, 3> to_float(const std::array<double, 3>& c) {
    return {float(c[0]), float(c[1]), float(c[2])};
  }
  static size_t index(int l, int zi, int yi, int xi) {
    return ((size_t(l) * kZ + zi) * kXY + yi) * kXY + xi;
  }
  std::array<float, 3>& at(int l, int zi, int yi, int xi) { return coeff_[index(l, zi, yi, xi)]; }

  std::array<float, kZ> z_nodes_{};
  std::vector<std::array<float, 3>> coeff_;
};

}  // namespace

float fit_sigmoid(Rgb rgb, std::array<float, 3>* coeff) {
  double target[3] = {rgb[0], rgb[1], rgb[2]};
  SigmoidFit fit(false);
  double residual = fit_from_grey(target, fit);
  *coeff = {float(fit.c[0]), float(fit.c[1]), float(fit.c[2])};
  return float(residual);
}

std::array<float, 3> sigmoid_coefficients_lookup(Rgb rgb) {
  static const SigmoidTable table;
  return table.lookup(rgb);
}

void prepare_texel_spectra() { sigmoid_coefficients_lookup(Rgb(0.5f)); }

Spectrum rgb_texel_spectrum(Rgb rgb, SpectrumKind kind, const Wavelengths& wl) {
  Spectrum s;
  if (kind == SpectrumKind::kAlbedo)
    for (int c = 0; c < 3; ++c)
      rgb[c] = std::clamp(rgb[c], 0.0f, 1.0f);  // as pbrt-v4's image textures
  float m = rgb.max_component();
  if (!(m > 0)) return s;
  // A reflectance is looked up as it is; other colours with their largest channel scaled to 0.5.
  float scale = kind == SpectrumKind::kAlbedo ? 1.0f : 2 * m;
  std::array<float, 3> c = sigmoid_coefficients_lookup(rgb / scale);
  for (int i = 0; i < Spectrum::kChannels; ++i) {
    s[i] = scale * sigmoid_spectrum(c, wl.lambda[i]);
    if (kind == SpectrumKind::kIlluminant) s[i] *= d65_unit(wl.lambda[i]);
  }
  return s;
}

SpectrumCurve::SpectrumCurve(float constant)
    : kind_(Kind::kConstant), scale_(constant), rgb_(constant) {}

SpectrumCurve SpectrumCurve::from_rgb(Rgb rgb, SpectrumKind kind) {
  SpectrumCurve s;
  float m = rgb.max_component();
  if (m <= 0) {
    s.times_d65_ = kind == SpectrumKind::kIlluminant;
    return s;
  }
  if (rgb.min_component() == m) {
    s.kind_ = Kind::kConstant;
    s.scale_ = m;
  } else {
    // A reflectance is fitted as it is; other colours are scaled so that their largest channel
    // is 0.5, the middle of the sigmoid's range (pbrt-v4's RGBUnboundedSpectrum).
    float scale = kind == SpectrumKind::kAlbedo ? 1.0f : 2 * m;
    s.kind_ = Kind::kSigmoid;
    s.scale_ = scale;
    fit_sigmoid(rgb / scale, &s.coeff_);
  }
  s.times_d65_ = kind == SpectrumKind::kIlluminant;
  s.finish(kind);
  return s;
}

SpectrumCurve SpectrumCurve::from_table(std::vector<float> values, SpectrumKind kind) {
  SpectrumCurve s;
  values.resize(kTableSize, values.empty() ? 0.0f : values.back());
  s.kind_ = Kind::kTable;
  s.scale_ = 1;
  s.table_ = std::make_shared<const std::vector<float>>(std::move(values));
  s.finish(kind);
  return s;
}

SpectrumCurve SpectrumCurve::from_pairs(const std::vector<double>& pairs, SpectrumKind kind) {
  size_t n = pairs.size() / 2;
  std::vector<float> values(kTableSize, 0.0f);
  for (int i = 0; i < kTableSize && n > 0; ++i) {
    double l = kLambdaMin + i;
    if (l <= pairs[0]) {
      values[i] = float(pairs[1]);
    } else if (l >= pairs[2 * (n - 1)]) {
      values[i] = float(pairs[2 * n - 1]);
    } else {
      size_t j = 0;
      while (j + 2 < n && pairs[2 * (j + 1)] < l) ++j;
      double l0 = pairs[2 * j], l1 = pairs[2 * j + 2];
      double t = l1 > l0 ? (l - l0) / (l1 - l0) : 0;
      values[i] = float(pairs[2 * j + 1] * (1 - t) + pairs[2 * j + 3] * t);
    }
  }
  return from_table(std::move(values), kind);
}

float blackbody(float lambda, float T) {
  if (!(T > 0)) return 0;
  const double c = 299792458.0, h = 6.62606957e-34, kb = 1.3806488e-23;
  auto planck = [&](double l) {
    return (2 * h * c * c) / (std::pow(l, 5) * (std::exp((h * c) / (l * kb * T)) - 1));
  };
  return float(planck(double(lambda) * 1e-9) / planck(2.8977721e-3 / T));
}

double ybar_integral() { return tables().y_integral; }

SpectrumCurve SpectrumCurve::blackbody(float T) {
  std::vector<float> values(kTableSize);
  for (int i = 0; i < kTableSize; ++i) values[i] = bpm::blackbody(kLambdaMin + i, T);
  return from_table(std::move(values), SpectrumKind::kIlluminant);
}

float SpectrumCurve::raw(float lambda) const {
  switch (kind_) {
    case Kind::kZero:
      return 0;
    case Kind::kConstant:
      return 1;
    case Kind::kSigmoid:
      return sigmoid_spectrum(coeff_, lambda);
    case Kind::kTable:
      return lerp_table(*table_, lambda, mix_float);
  }
  return 0;
}

float SpectrumCurve::value(float lambda) const {
  float v = scale_ * raw(lambda);
  return times_d65_ ? v * d65_unit(lambda) : v;
}

Spectrum SpectrumCurve::sample(const Wavelengths& wl) const {
  Spectrum s;
  if (kind_ == Kind::kZero) return s;
  for (int i = 0; i < Spectrum::kChannels; ++i) s[i] = value(wl.lambda[i]);
  return s;
}

float SpectrumCurve::luminance() const {
  double y = 0;
  for (int i = 0; i < kTableSize; ++i) y += value(kLambdaMin + i) * cie_y(kLambdaMin + i);
  return float(y / tables().y_integral);
}

float SpectrumCurve::min_value() const {
  float m = kInf;
  for (int i = 0; i < kTableSize; ++i) {
    float v = value(kLambdaMin + i);
    if (std::isnan(v)) return v;
    m = std::min(m, v);
  }
  return m;
}

float SpectrumCurve::max_value() const {
  float m = -kInf;
  for (int i = 0; i < kTableSize; ++i) {
    float v = value(kLambdaMin + i);
    if (std::isnan(v)) return v;
    m = std::max(m, v);
  }
  return m;
}

SpectrumCurve SpectrumCurve::scaled(float s) const {
  SpectrumCurve out = *this;
  out.scale_ *= s;
  out.rgb_ *= s;
  return out;
}

void SpectrumCurve::finish(SpectrumKind kind) {
  // An illuminant's colour is its own; anything else is seen under D65.
  const Tables& t = tables();
  double rgb[3] = {0, 0, 0};
  for (int i = 0; i < kTableSize; ++i) {
    float v = value(kLambdaMin + i);
    const auto& w = kind == SpectrumKind::kIlluminant ? t.rgb_weight[i] : t.rgb_weight_d65[i];
    for (int c = 0; c < 3; ++c) rgb[c] += v * w[c];
  }
  rgb_ = Rgb(float(rgb[0]), float(rgb[1]), float(rgb[2]));
}

namespace {

Mat3 mul(const Mat3& a, const Mat3& b) {
  Mat3 r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) r[3 * i + j] += a[3 * i + k] * b[3 * k + j];
  return r;
}

// The chromaticity (x, y) of a spectrum's colour, integrated at 1 nm.
std::array<double, 2> chromaticity(const std::function<double(double)>& spd) {
  double X = 0, Y = 0, Z = 0;
  for (int i = 0; i < kTableSize; ++i) {
    const double l = kLambdaMin + i, s = spd(l);
    X += s * cie_x(float(l));
    Y += s * cie_y(float(l));
    Z += s * cie_z(float(l));
  }
  return {X / (X + Y + Z), Y / (X + Y + Z)};
}

}  // namespace

float daylight_spectrum(float temperature, float lambda) {
  const double cct = double(temperature) * 1.4388 / 1.4380, l = lambda;
  if (cct < 4000) {  // the CIE daylight is not defined there: a blackbody
    const double c = 299792458.0, h = 6.62606957e-34, kb = 1.3806488e-23, m = l * 1e-9;
    const double peak = 2.8977721e-3 / cct;  // Wien: 1 at the peak
    auto planck = [&](double w) {
      return 1 / (std::pow(w, 5) * (std::exp((h * c) / (w * kb * cct)) - 1));
    };
    return float(planck(m) / planck(peak));
  }
  const double x =
      cct <= 7000
          ? -4.607e9 / (cct * cct * cct) + 2.9678e6 / (cct * cct) + 0.09911e3 / cct + 0.244063
          : -2.0064e9 / (cct * cct * cct) + 1.9018e6 / (cct * cct) + 0.24748e3 / cct + 0.23704;
  const double y = -3 * x * x + 2.870 * x - 0.275;
  const double M = 0.0241 + 0.2562 * x - 0.7341 * y;
  const double m1 = (-1.3515 - 1.7703 * x + 5.9114 * y) / M,
               m2 = (0.0300 - 31.4424 * x + 30.0717 * y) / M;
  return float(0.01 * (daylight_basis(kDaylightS0, l) + m1 * daylight_basis(kDaylightS1, l) +
                       m2 * daylight_basis(kDaylightS2, l)));
}

std::array<float, 9> white_balance_srgb(float temperature) {
  const std::array<double, 2> src =
      chromaticity([&](double l) { return daylight_spectrum(temperature, float(l)); });
  const std::array<double, 2> dst = chromaticity([](double l) { return d65_raw(l); });
  const Mat3 lms_from_xyz{0.8951, 0.2664, -0.1614, -0.7502, 1.7135,
                          0.0367, 0.0389, -0.0685, 1.0296};
  const Mat3 srgb_from_xyz{3.2404542, -1.5371385, -0.4985314, -0.9692660, 1.8760108,
                           0.0415560, 0.0556434,  -0.2040259, 1.0572252};
  auto lms_of = [&](const std::array<double, 2>& xy) {
    const double xyz[3] = {xy[0] / xy[1], 1, (1 - xy[0] - xy[1]) / xy[1]};
    std::array<double, 3> lms{};
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) lms[size_t(i)] += lms_from_xyz[size_t(3 * i + k)] * xyz[k];
    return lms;
  };
  const std::array<double, 3> s = lms_of(src), d = lms_of(dst);
  const Mat3 scale{d[0] / s[0], 0, 0, 0, d[1] / s[1], 0, 0, 0, d[2] / s[2]};
  const Mat3 m = mul(mul(mul(mul(srgb_from_xyz, inverse(lms_from_xyz)), scale), lms_from_xyz),
                     inverse(srgb_from_xyz));
  std::array<float, 9> out;
  for (int i = 0; i < 9; ++i) out[size_t(i)] = float(m[size_t(i)]);
  return out;
}

}  // namespace bpm
