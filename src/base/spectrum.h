// Radiometric quantities. bpm transports three sRGB-primaries channels; every integrator uses
// Spectrum only through these operations, so a spectral (sampled wavelengths) type with the same
// interface can replace it without touching integrator code.
#pragma once
#include <array>
#include <cmath>

namespace bpm {

struct Spectrum {
  static constexpr int kChannels = 3;
  std::array<float, kChannels> c{0, 0, 0};

  constexpr Spectrum() = default;
  constexpr explicit Spectrum(float v) : c{v, v, v} {}
  constexpr Spectrum(float r, float g, float b) : c{r, g, b} {}

  float operator[](int i) const { return c[i]; }
  float& operator[](int i) { return c[i]; }

  Spectrum& operator+=(const Spectrum& o) { for (int i = 0; i < kChannels; ++i) c[i] += o.c[i]; return *this; }
  Spectrum& operator*=(const Spectrum& o) { for (int i = 0; i < kChannels; ++i) c[i] *= o.c[i]; return *this; }
  Spectrum& operator*=(float s) { for (float& v : c) v *= s; return *this; }
  Spectrum& operator/=(float s) { return *this *= 1.0f / s; }

  bool is_black() const { return c[0] == 0 && c[1] == 0 && c[2] == 0; }
  float max_component() const { return std::fmax(c[0], std::fmax(c[1], c[2])); }
  float min_component() const { return std::fmin(c[0], std::fmin(c[1], c[2])); }
  float average() const { return (c[0] + c[1] + c[2]) / 3.0f; }
  // Luminance Y of linear sRGB (Rec. 709 primaries, D65).
  float luminance() const { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }
  bool is_finite() const { return std::isfinite(c[0]) && std::isfinite(c[1]) && std::isfinite(c[2]); }
  bool has_negative() const { return c[0] < 0 || c[1] < 0 || c[2] < 0; }
};

inline Spectrum operator+(Spectrum a, const Spectrum& b) { return a += b; }
inline Spectrum operator-(Spectrum a, const Spectrum& b) {
  for (int i = 0; i < Spectrum::kChannels; ++i) a[i] -= b[i];
  return a;
}
inline Spectrum operator*(Spectrum a, const Spectrum& b) { return a *= b; }
inline Spectrum operator*(Spectrum a, float s) { return a *= s; }
inline Spectrum operator*(float s, Spectrum a) { return a *= s; }
inline Spectrum operator/(Spectrum a, float s) { return a /= s; }
inline Spectrum operator/(Spectrum a, const Spectrum& b) {
  for (int i = 0; i < Spectrum::kChannels; ++i) a[i] = b[i] != 0 ? a[i] / b[i] : 0;
  return a;
}
inline Spectrum sqrt(Spectrum a) {
  for (float& v : a.c) v = std::sqrt(v);
  return a;
}

}  // namespace bpm
