#include "film/camera_response.h"

#include <algorithm>
#include <cmath>

namespace bpm {
namespace {

// A camera's channel c at lambda: linear between the 10 nm samples, 0 outside them.
double curve(const camera_curves::CameraCurves& cam, int c, double lambda) {
  const double x = (lambda - 380) / 10;
  if (x < 0 || x > camera_curves::kSamples - 1) return 0;
  const int i = std::min(int(x), camera_curves::kSamples - 2);
  const double t = x - i;
  const float* v = cam.rgb[c];
  return v[i] * (1 - t) + v[i + 1] * t;
}

// The training reflectances: sigmoid spectra of the 27 colours with channels 0.05, 0.45, 0.85.
std::vector<std::array<float, 3>> training_coefficients() {
  std::vector<std::array<float, 3>> out;
  const float levels[3] = {0.05f, 0.45f, 0.85f};
  for (float r : levels)
    for (float g : levels)
      for (float b : levels) {
        std::array<float, 3> c;
        fit_sigmoid(Rgb(r, g, b), &c);
        out.push_back(c);
      }
  return out;
}

// pbrt-v4's PixelSensor fit: camera RGB of each reflectance under the sensor illuminant over the
// camera's green of that illuminant; XYZ of the reflectance under D65 over its Y, times the
// illuminant's Y over its camera green; XYZ = M RGB by least squares.
Mat3 fit_xyz_from_camera(const camera_curves::CameraCurves& cam, float white_balance) {
  const SpectrumCurve d65 = SpectrumCurve::from_rgb(Rgb(1, 1, 1), SpectrumKind::kIlluminant);
  double illum_g = 0, illum_y = 0, d65_y = 0;
  for (double l = kLambdaMin; l <= kLambdaMax; l += 1) {
    const double s = daylight_spectrum(white_balance, float(l));
    illum_g += curve(cam, 1, l) * s;
    illum_y += cie_y(float(l)) * s;
    d65_y += cie_y(float(l)) * d65.value(float(l));
  }
  double ctc[9] = {}, xtc[9] = {};  // C^T C and X^T C over the training set
  for (const auto& coeff : training_coefficients()) {
    double rgb[3] = {}, xyz[3] = {};
    for (double l = kLambdaMin; l <= kLambdaMax; l += 1) {
      const double rho = sigmoid_spectrum(coeff, float(l));
      const double s = daylight_spectrum(white_balance, float(l)) * rho,
                   e = d65.value(float(l)) * rho;
      for (int c = 0; c < 3; ++c) rgb[c] += curve(cam, c, l) * s;
      xyz[0] += cie_x(float(l)) * e;
      xyz[1] += cie_y(float(l)) * e;
      xyz[2] += cie_z(float(l)) * e;
    }
    for (int c = 0; c < 3; ++c) {
      rgb[c] /= illum_g;
      xyz[c] *= (illum_y / illum_g) / d65_y;
    }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        ctc[3 * i + j] += rgb[i] * rgb[j];
        xtc[3 * i + j] += xyz[i] * rgb[j];
      }
  }
  const Mat3 inv =
      inverse({ctc[0], ctc[1], ctc[2], ctc[3], ctc[4], ctc[5], ctc[6], ctc[7], ctc[8]});
  Mat3 m{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) m[size_t(3 * i + j)] += xtc[3 * i + k] * inv[size_t(3 * k + j)];
  return m;
}

}  // namespace

std::vector<std::string> CameraResponse::names() {
  std::vector<std::string> out;
  for (int i = 0; i < camera_curves::kCameraCount; ++i)
    out.push_back(camera_curves::kCameras[i].name);
  return out;
}

std::optional<CameraResponse> CameraResponse::named(const std::string& name, float white_balance) {
  const camera_curves::CameraCurves* cam = nullptr;
  for (int i = 0; i < camera_curves::kCameraCount; ++i)
    if (name == camera_curves::kCameras[i].name) cam = &camera_curves::kCameras[i];
  if (!cam) return std::nullopt;
  CameraResponse r;
  r.xyz_from_camera_ = fit_xyz_from_camera(*cam, white_balance);
  // The same normalisation and per-channel white correction as spectrum_to_rgb's weights: XYZ
  // over the integral of ybar, sRGB over that of the D65 white.
  double y_integral = 0, white_xyz[3] = {};
  const SpectrumCurve d65 = SpectrumCurve::from_rgb(Rgb(1, 1, 1), SpectrumKind::kIlluminant);
  for (double l = kLambdaMin; l <= kLambdaMax; l += 1) y_integral += cie_y(float(l));
  for (double l = kLambdaMin; l <= kLambdaMax; l += 1) {
    white_xyz[0] += d65.value(float(l)) * cie_x(float(l)) / y_integral;
    white_xyz[1] += d65.value(float(l)) * cie_y(float(l)) / y_integral;
    white_xyz[2] += d65.value(float(l)) * cie_z(float(l)) / y_integral;
  }
  double white[3];
  xyz_to_srgb(white_xyz, white);
  const Mat3& m = r.xyz_from_camera_;
  for (double l = kLambdaMin; l <= kLambdaMax; l += 1) {
    const double cam_rgb[3] = {curve(*cam, 0, l), curve(*cam, 1, l), curve(*cam, 2, l)};
    double xyz[3], rgb[3];
    for (int i = 0; i < 3; ++i)
      xyz[i] = (m[size_t(3 * i)] * cam_rgb[0] + m[size_t(3 * i + 1)] * cam_rgb[1] +
                m[size_t(3 * i + 2)] * cam_rgb[2]) /
               y_integral;
    xyz_to_srgb(xyz, rgb);
    r.weight_.push_back(
        {float(rgb[0] / white[0]), float(rgb[1] / white[1]), float(rgb[2] / white[2])});
  }
  return r;
}

Rgb CameraResponse::to_rgb(const Spectrum& L, const Wavelengths& wl) const {
  Rgb out;
  for (int i = 0; i < Spectrum::kChannels; ++i) {
    if (L[i] == 0 || wl.pdf[i] == 0) continue;
    const float x = std::clamp(wl.lambda[i] - kLambdaMin, 0.0f, kLambdaMax - kLambdaMin);
    const size_t k = std::min(size_t(x), weight_.size() - 2);
    const float t = x - float(k);
    const float s = L[i] / (wl.pdf[i] * Spectrum::kChannels);
    for (int c = 0; c < 3; ++c)
      out[c] += (weight_[k][size_t(c)] * (1 - t) + weight_[k + 1][size_t(c)] * t) * s;
  }
  return out;
}

}  // namespace bpm
