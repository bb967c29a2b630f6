// Trowbridge-Reitz (GGX) microfacet distribution with visible-normal sampling (Heitz 2018),
// in the parameterisation pbrt-v4 uses (its util/scattering.h), so rough materials match it.
#pragma once
#include <algorithm>
#include <cmath>

#include "base/vec.h"

namespace bpm {

inline float cos2_theta(Vec3 w) { return w.z * w.z; }
inline float sin2_theta(Vec3 w) { return std::fmax(0.0f, 1 - cos2_theta(w)); }
inline float tan2_theta(Vec3 w) { return sin2_theta(w) / cos2_theta(w); }
inline float cos_phi(Vec3 w) {
  float s = std::sqrt(sin2_theta(w));
  return s == 0 ? 1 : std::clamp(w.x / s, -1.0f, 1.0f);
}
inline float sin_phi(Vec3 w) {
  float s = std::sqrt(sin2_theta(w));
  return s == 0 ? 0 : std::clamp(w.y / s, -1.0f, 1.0f);
}
inline bool same_hemisphere(Vec3 a, Vec3 b) { return a.z * b.z > 0; }

class TrowbridgeReitz {
 public:
  TrowbridgeReitz(float ax, float ay)
      : ax_(std::fmax(ax, 1e-4f)), ay_(std::fmax(ay, 1e-4f)), isotropic_(ax_ == ay_) {}

  float d(Vec3 wm) const {
    float t2 = tan2_theta(wm);
    if (std::isinf(t2)) return 0;
    float c4 = cos2_theta(wm) * cos2_theta(wm);
    if (c4 < 1e-16f) return 0;
    // cos^2 phi + sin^2 phi = 1: an isotropic lobe needs no azimuth.
    float e;
    if (isotropic_) {
      e = t2 / (ax_ * ax_);
    } else {
      float cp = cos_phi(wm), sp = sin_phi(wm);
      e = t2 * (cp * cp / (ax_ * ax_) + sp * sp / (ay_ * ay_));
    }
    return 1 / (kPi * ax_ * ay_ * c4 * (1 + e) * (1 + e));
  }
  float lambda(Vec3 w) const {
    float t2 = tan2_theta(w);
    if (std::isinf(t2)) return 0;
    float a2;
    if (isotropic_) {
      a2 = ax_ * ax_;
    } else {
      float cp = cos_phi(w), sp = sin_phi(w);
      a2 = ax_ * ax_ * cp * cp + ay_ * ay_ * sp * sp;
    }
    return (std::sqrt(1 + a2 * t2) - 1) / 2;
  }
  float g1(Vec3 w) const { return 1 / (1 + lambda(w)); }
  float g(Vec3 wo, Vec3 wi) const { return g(lambda(wo), wi); }
  // The same, with lambda(wo) at hand.
  float g(float lambda_wo, Vec3 wi) const { return 1 / (1 + lambda_wo + lambda(wi)); }
  // Density of visible normals wm seen from w.
  float d_visible(Vec3 w, Vec3 wm) const { return d_visible(w, wm, d(wm), lambda(w)); }
  // The same, from d(wm) and lambda(w) at hand (a sample's value needs them again).
  static float d_visible(Vec3 w, Vec3 wm, float d_wm, float lambda_w) {
    return d_wm * std::fabs(dot(w, wm)) / ((1 + lambda_w) * std::fabs(w.z));
  }
  Vec3 sample_wm(Vec3 w, Vec2 u) const {
    Vec3 wh = normalize(Vec3(ax_ * w.x, ay_ * w.y, w.z));
    if (wh.z < 0) wh = -wh;
    Vec3 t1 = wh.z < 0.99999f ? normalize(cross(Vec3(0, 0, 1), wh)) : Vec3(1, 0, 0);
    Vec3 t2 = cross(wh, t1);
    float r = std::sqrt(u.x), phi = 2 * kPi * u.y;
    float px = r * std::cos(phi), py = r * std::sin(phi);
    float h = std::sqrt(1 - px * px);
    float s = (1 + wh.z) / 2;
    py = (1 - s) * h + s * py;
    float pz = std::sqrt(std::fmax(0.0f, 1 - px * px - py * py));
    Vec3 nh = t1 * px + t2 * py + wh * pz;
    return normalize(Vec3(ax_ * nh.x, ay_ * nh.y, std::fmax(1e-6f, nh.z)));
  }

 private:
  float ax_, ay_;
  bool isotropic_;
};

}  // namespace bpm
