// The film's spectral response: how radiance at a path's wavelengths becomes the image's linear
// sRGB. By default the CIE 1931 matching functions (base/color.h, pbrt-v4's "cie1931" sensor); a
// named camera sensor (pbrt-v4's film "sensor") weighs the radiance by the camera's measured red,
// green and blue sensitivities and maps them to CIE XYZ by a 3 x 3 matrix, pbrt-v4's PixelSensor:
// fitted by least squares so that training reflectances lit by the white-balance illuminant D(T)
// (6500 K unless the film's "whitebalance" says) come out as their colours under D65, scaled so
// that the camera's green of that illuminant gives its luminance. pbrt-v4 trains on the 24 patches
// of a ColorChecker chart; bpm trains on 27 smooth reflectances of its own (the sigmoid spectra
// of the colours with channels 0.05, 0.45 and 0.85), so colours may differ by a percent.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "base/color.h"

namespace bpm {

class CameraResponse {
 public:
  // The named sensor balanced for D(white_balance); none if the name is unknown.
  static std::optional<CameraResponse> named(const std::string& name, float white_balance);
  // pbrt-v4's sensor names, in its order ("cie1931" is not among them: it is no camera).
  static std::vector<std::string> names();
  // Linear sRGB of the Monte Carlo estimate L at the wavelengths wl, as spectrum_to_rgb.
  Rgb to_rgb(const Spectrum& L, const Wavelengths& wl) const;
  // The matrix from camera RGB to XYZ (row-major), for tests and the run's record.
  const std::array<double, 9>& xyz_from_camera() const { return xyz_from_camera_; }

 private:
  std::array<double, 9> xyz_from_camera_{};
  std::vector<std::array<float, 3>> weight_;  // per nm over [kLambdaMin, kLambdaMax]
};

namespace camera_curves {
// 380 to 720 nm in 10 nm steps.
constexpr int kSamples = 35;
struct CameraCurves {
  const char* name;
  float rgb[3][kSamples];
};
extern const CameraCurves kCameras[];
extern const int kCameraCount;
}  // namespace camera_curves

}  // namespace bpm
