// Spectral rendering support, following pbrt-v4's model (Pharr, Jakob, Humphreys, 4th ed., ch. 4):
// - a path samples eight wavelengths (Wavelengths) and carries its values there (Spectrum);
// - scene colours become smooth spectra (SpectrumCurve): an RGB reflectance is the sigmoid of a
//   quadratic (Jakob and Hanika 2019, "A Low-Dimensional Function Space for Efficient Spectral
//   Upsampling") fitted so that it reproduces the RGB under the sRGB white (D65); an RGB light is
//   such a curve times the D65 illuminant;
// - the film projects the sampled values onto the CIE 1931 matching functions and converts to
//   linear sRGB.
// bpm's colour matching functions are the multi-lobe fit of Wyman, Sloan and Shirley (JCGT 2013);
// every conversion uses the same functions, so an RGB round trip is exact and a constant spectrum
// of 1 under D65 is white (1, 1, 1).
#pragma once
#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "base/spectrum.h"

namespace bpm {

constexpr float kLambdaMin = 360, kLambdaMax = 830;

struct Wavelengths {
  std::array<float, Spectrum::kChannels> lambda{};
  std::array<float, Spectrum::kChannels> pdf{};  // density of each wavelength (per nm)
};

// The estimate of a path that from some vertex on follows the first (hero) wavelength alone,
// because what it met there sends each wavelength its own way (dispersion): the others are
// dropped and the hero's value is scaled by the number of wavelengths, as pbrt-v4's
// TerminateSecondary does through the densities. The hero alone is an unbiased estimate because
// its wavelength has the full sampling density (each channel's does).
inline Spectrum hero_wavelength_only(const Spectrum& s) {
  Spectrum r;
  r[0] = s[0] * Spectrum::kChannels;
  return r;
}

// Spectrum::kChannels wavelengths stratified over [kLambdaMin, kLambdaMax] from one uniform number,
// each drawn with a density that follows the eye's sensitivity (a sech^2 lobe about 540 nm).
Wavelengths sample_wavelengths(float u);
// The same stratification with a uniform density over [lo, hi] (pbrt-v4's spectral film).
Wavelengths sample_wavelengths_uniform(float u, float lo, float hi);
float wavelength_pdf(float lambda);

// Linear sRGB of the Monte Carlo estimate L at the wavelengths wl (the film's sensor, pbrt-v4's
// "cie1931").
Rgb spectrum_to_rgb(const Spectrum& L, const Wavelengths& wl);
// The CIE daylight illuminant D(T), as pbrt-v4's Spectra::D has it: at the temperature corrected
// for the revised second radiation constant (T 1.4388 / 1.4380), the daylight basis S0 + M1 S1 +
// M2 S2 at the CIE formula's chromaticity; below 4000 K a blackbody (1 at its peak). Relative
// values, 1 near 560 nm.
float daylight_spectrum(float temperature, float lambda);
// Planck's law at wavelength lambda (nm) and temperature T (kelvin), 1 at the curve's peak
// (Wien's law), as pbrt-v4's BlackbodySpectrum.
float blackbody(float lambda, float temperature);
// The integral of the CIE ybar matching function over [kLambdaMin, kLambdaMax] in nm (about
// 106.86). A spectrum s has luminance (integral of s ybar) / this here; pbrt-v4's film reads
// (integral of s ybar) itself, so an emission spectrum that pbrt-v4 does not normalise (the
// glow of a temperature grid, an rgbgrid's Le) is this many times brighter in our units.
double ybar_integral();
// pbrt-v4's film "whitebalance" of temperature T (kelvin) for its cie1931 sensor, as a matrix on
// linear sRGB (row-major): a Bradford adaptation from the white of D(T) (daylight_spectrum) to
// sRGB's D65 white.
std::array<float, 9> white_balance_srgb(float temperature);

// A 3 x 3 matrix, row-major, and its inverse; XYZ to linear sRGB (IEC 61966-2-1).
using Mat3 = std::array<double, 9>;
Mat3 inverse(const Mat3& m);
void xyz_to_srgb(const double xyz[3], double rgb[3]);

// The photopic luminance of the estimate L: the integral of L times the CIE 1931 ybar over that of
// ybar, with no white balance. Light stated in pbrt-v4's photometric terms (a light's "power" in
// lumens, "illuminance" in lux, a spectrum normalised to unit luminance) gives it in cd/m^2.
float spectrum_to_luminance(const Spectrum& L, const Wavelengths& wl);

// How a stated colour is read (as pbrt-v4's SpectrumType): reflectances are bounded by 1,
// unbounded values (eta, k) may be anything non-negative, illuminants are emission spectra.
enum class SpectrumKind { kAlbedo, kUnbounded, kIlluminant };

// A spectral distribution from the scene description, evaluated at a path's wavelengths.
class SpectrumCurve {
 public:
  SpectrumCurve() = default;  // zero everywhere
  explicit SpectrumCurve(float constant);

  // The smooth spectrum whose colour is rgb (see the top of this file). An albedo must lie in
  // [0, 1]; an illuminant rgb is the colour of the light, D65 for (1, 1, 1).
  static SpectrumCurve from_rgb(Rgb rgb, SpectrumKind kind);
  // Values at 1 nm steps over [kLambdaMin, kLambdaMax], linearly interpolated.
  static SpectrumCurve from_table(std::vector<float> values_per_nm, SpectrumKind kind);
  // Piecewise linear through (wavelength nm, value) pairs, constant beyond the ends.
  static SpectrumCurve from_pairs(const std::vector<double>& lambda_value_pairs, SpectrumKind kind);
  // Planck's law at the temperature, 1 at its peak.
  static SpectrumCurve blackbody(float temperature_kelvin);

  float value(float lambda) const;
  Spectrum sample(const Wavelengths& wl) const;
  // Linear sRGB: the colour of a reflectance lit by D65 (albedo and unbounded), or of the light
  // (illuminant). Cached at construction.
  Rgb rgb() const { return rgb_; }
  // Luminance relative to the matching functions, integral of s * ybar over integral of ybar.
  float luminance() const;
  // Extremes over [kLambdaMin, kLambdaMax] at 1 nm (NaN if a value is NaN); for checking input.
  float min_value() const;
  float max_value() const;
  SpectrumCurve scaled(float s) const;
  bool is_black() const { return kind_ == Kind::kZero || scale_ == 0; }
  // The same values at every wavelength, by construction (same kind, parameters and table).
  bool same_curve(const SpectrumCurve& o) const {
    return kind_ == o.kind_ && scale_ == o.scale_ && coeff_ == o.coeff_ &&
           times_d65_ == o.times_d65_ && table_ == o.table_;
  }
  bool is_constant() const { return kind_ == Kind::kZero || kind_ == Kind::kConstant; }

 private:
  enum class Kind { kZero, kConstant, kSigmoid, kTable };
  float raw(float lambda) const;
  void finish(SpectrumKind kind);

  Kind kind_ = Kind::kZero;
  float scale_ = 0;
  std::array<float, 3> coeff_{};  // sigmoid polynomial in normalised wavelength
  bool times_d65_ = false;        // multiplied by the D65 illuminant (unit luminance)
  std::shared_ptr<const std::vector<float>> table_;
  Rgb rgb_;
};

// Sigmoid-polynomial coefficients of a reflectance with colour rgb in [0, 1]^3 (exposed for tests);
// returns the largest remaining channel error.
float fit_sigmoid(Rgb rgb, std::array<float, 3>* coeff);
float sigmoid_spectrum(const std::array<float, 3>& coeff, float lambda);
// The same at u = normalised_lambda(lambda) (0 to 1 over the visible range), for a caller that
// evaluates many spectra at the same wavelengths.
float normalised_lambda(float lambda);
inline float sigmoid_spectrum_at(const std::array<float, 3>& c, float u) {
  const float x = (c[0] * u + c[1]) * u + c[2];
  return 0.5f + x / (2 * std::sqrt(1 + x * x));
}
// The same coefficients interpolated in a table of fits over the colour cube, built on the first
// call (about 2 s of CPU, 1 s on two cores): what per-texel colours use.
std::array<float, 3> sigmoid_coefficients_lookup(Rgb rgb);
// Builds that table now, if it is not yet built: loading an image for per-texel colours calls it,
// so that a render's time (and its budget) does not include it.
void prepare_texel_spectra();
// A colour read at render time (an image texel) as a spectrum at the wavelengths wl, through the
// table: an albedo is clamped to [0, 1]; see SpectrumCurve::from_rgb for the other kinds.
Spectrum rgb_texel_spectrum(Rgb rgb, SpectrumKind kind, const Wavelengths& wl);

// The CIE standard illuminant D65 scaled to unit luminance, and the matching functions.
float d65_unit(float lambda);
float cie_x(float lambda);
float cie_y(float lambda);
float cie_z(float lambda);

}  // namespace bpm
