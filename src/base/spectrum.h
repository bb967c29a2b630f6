// Radiometric quantities. Light is transported spectrally, as in pbrt-v4: every camera or light
// path carries its values at a handful of sampled wavelengths (Spectrum), and only the film turns
// them into colour (Rgb, linear sRGB primaries). Both are small fixed-size vectors with the same
// element-wise operations.
#pragma once
#include <array>
#include <cmath>

namespace bpm {

template <int N>
struct Channels {
  static constexpr int kChannels = N;
  std::array<float, N> c{};

  constexpr Channels() = default;
  constexpr explicit Channels(float v) { c.fill(v); }
  constexpr Channels(float r, float g, float b) requires(N == 3) : c{r, g, b} {}

  float operator[](int i) const { return c[i]; }
  float& operator[](int i) { return c[i]; }

  Channels& operator+=(const Channels& o) {
    for (int i = 0; i < N; ++i) c[i] += o.c[i];
    return *this;
  }
  Channels& operator-=(const Channels& o) {
    for (int i = 0; i < N; ++i) c[i] -= o.c[i];
    return *this;
  }
  Channels& operator*=(const Channels& o) {
    for (int i = 0; i < N; ++i) c[i] *= o.c[i];
    return *this;
  }
  Channels& operator*=(float s) {
    for (float& v : c) v *= s;
    return *this;
  }
  Channels& operator/=(float s) { return *this *= 1.0f / s; }

  bool is_black() const {
    for (float v : c)
      if (v != 0) return false;
    return true;
  }
  // As std::fmax and std::fmin over the channels (a NaN channel is ignored unless all are NaN),
  // written out so that they compile to max and min instructions instead of library calls.
  float max_component() const {
    float m = c[0];
    for (float v : c) m = v > m || m != m ? v : m;
    return m;
  }
  float min_component() const {
    float m = c[0];
    for (float v : c) m = v < m || m != m ? v : m;
    return m;
  }
  float average() const {
    float s = 0;
    for (float v : c) s += v;
    return s / N;
  }
  // Luminance Y of linear sRGB (Rec. 709 primaries, D65).
  float luminance() const requires(N == 3) {
    return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
  }
  bool is_finite() const {
    for (float v : c)
      if (!std::isfinite(v)) return false;
    return true;
  }
  // Negative values set to zero.
  Channels clamped_zero() const {
    Channels r = *this;
    for (float& v : r.c) v = v > 0 ? v : 0.0f;  // NaN to 0, as std::fmax(0, v)
    return r;
  }
  bool has_negative() const {
    for (float v : c)
      if (v < 0) return true;
    return false;
  }
};

template <int N>
Channels<N> operator+(Channels<N> a, const Channels<N>& b) {
  return a += b;
}
template <int N>
Channels<N> operator-(Channels<N> a, const Channels<N>& b) {
  return a -= b;
}
template <int N>
Channels<N> operator*(Channels<N> a, const Channels<N>& b) {
  return a *= b;
}
template <int N>
Channels<N> operator*(Channels<N> a, float s) {
  return a *= s;
}
template <int N>
Channels<N> operator*(float s, Channels<N> a) {
  return a *= s;
}
template <int N>
Channels<N> operator/(Channels<N> a, float s) {
  return a /= s;
}
// Element-wise quotient; 0 where the divisor is 0.
template <int N>
Channels<N> operator/(Channels<N> a, const Channels<N>& b) {
  for (int i = 0; i < N; ++i) a[i] = b[i] != 0 ? a[i] / b[i] : 0;
  return a;
}
template <int N>
Channels<N> sqrt(Channels<N> a) {
  for (float& v : a.c) v = std::sqrt(v);
  return a;
}

// Linear sRGB: images, and the colours a scene file states.
using Rgb = Channels<3>;
// Values at the wavelengths a path samples (Wavelengths in base/color.h). Eight, where pbrt-v4
// takes four: the photon methods share one set of wavelengths between all the paths of an
// iteration, so the set's colour error is common to the whole image; eight stratified wavelengths
// keep it within a per cent or so after a few tens of iterations, for about 9% more time per
// iteration (16 cost 35-45%).
using Spectrum = Channels<8>;

}  // namespace bpm
