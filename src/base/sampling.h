// Sampling routines; each says in its name the measure of the density it returns.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "base/vec.h"

namespace bpm {

// (cos a, sin a) for |a| <= pi/4 from their Taylor series (truncated below 2e-9; evaluated in
// float, within about an ulp), without the range reduction of a library call: the concentric
// disk's angles lie in this range.
inline Vec2 cos_sin_quarter_turn(float a) {
  const float a2 = a * a;
  const float s =
      a * (1 + a2 * (-1.f / 6 + a2 * (1.f / 120 + a2 * (-1.f / 5040 + a2 * (1.f / 362880)))));
  const float c =
      1 + a2 * (-0.5f +
                a2 * (1.f / 24 + a2 * (-1.f / 720 + a2 * (1.f / 40320 + a2 * (-1.f / 3628800)))));
  return {c, s};
}

inline Vec2 sample_uniform_disk_concentric(Vec2 u) {
  float ox = 2 * u.x - 1, oy = 2 * u.y - 1;
  if (ox == 0 && oy == 0) return {0, 0};
  if (std::fabs(ox) > std::fabs(oy)) {  // theta = (pi/4)(oy/ox)
    const Vec2 cs = cos_sin_quarter_turn((kPi / 4) * (oy / ox));
    return {ox * cs.x, ox * cs.y};
  }
  // theta = pi/2 - a with a = (pi/4)(ox/oy): cos theta = sin a, sin theta = cos a.
  const Vec2 cs = cos_sin_quarter_turn((kPi / 4) * (ox / oy));
  return {oy * cs.y, oy * cs.x};
}

// Cosine-weighted direction about +z; pdf_solid_angle = cos(theta) / pi.
inline Vec3 sample_cosine_hemisphere(Vec2 u) {
  Vec2 d = sample_uniform_disk_concentric(u);
  float z = std::sqrt(std::fmax(0.0f, 1 - d.x * d.x - d.y * d.y));
  return {d.x, d.y, z};
}
inline float cosine_hemisphere_pdf_solid_angle(float cos_theta) { return cos_theta * kInvPi; }

inline Vec3 sample_uniform_sphere(Vec2 u) {
  float z = 1 - 2 * u.x;
  float r = std::sqrt(std::fmax(0.0f, 1 - z * z));
  float phi = 2 * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
constexpr float kUniformSpherePdfSolidAngle = 1 / (4 * kPi);

// Uniform direction inside a cone about +z with cos of the half angle cos_max.
inline Vec3 sample_uniform_cone(Vec2 u, float cos_max) {
  float cos_t = (1 - u.x) + u.x * cos_max;
  float sin_t = std::sqrt(std::fmax(0.0f, 1 - cos_t * cos_t));
  float phi = u.y * 2 * kPi;
  return {std::cos(phi) * sin_t, std::sin(phi) * sin_t, cos_t};
}
inline float uniform_cone_pdf_solid_angle(float cos_max) { return 1 / (2 * kPi * (1 - cos_max)); }

// Uniform point on a triangle, returned as barycentrics (b0, b1); b2 = 1 - b0 - b1.
inline Vec2 sample_uniform_triangle(Vec2 u) {
  float b0, b1;
  if (u.x < u.y) {
    b0 = u.x / 2;
    b1 = u.y - b0;
  } else {
    b1 = u.y / 2;
    b0 = u.x - b1;
  }
  return {b0, b1};
}

// The van der Corput sequence: i's bits mirrored about the binary point (the base-2 radical
// inverse), as 32 bits and as a number in [0, 1). The first 2^k values fall one in each interval of
// width 2^-k.
inline uint32_t van_der_corput_bits(uint32_t i) {
  i = (i << 16) | (i >> 16);
  i = ((i & 0x00ff00ffu) << 8) | ((i & 0xff00ff00u) >> 8);
  i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
  i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
  return ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
}
inline double radical_inverse_base2(uint32_t i) { return double(van_der_corput_bits(i)) * 0x1p-32; }

// A depth in [0, whole] (whole > 0) drawn by the uniform u from the exponential density cut at
// whole, exp(-tau) / (1 - exp(-whole)): a free flight conditioned to end within `whole`.
inline float sample_truncated_exponential(float u, float whole) {
  return std::min(float(-std::log1p(u * std::expm1(-double(whole)))), whole);
}

// The van der Corput sequence under a nested uniform (Owen) scramble keyed by `seed`, after Burley
// (2020, "Practical hash-based Owen scrambling"): i goes through a permutation in which each bit
// depends on the bits below it only, then is mirrored. The first 2^k values still fall one in
// each interval of width 2^-k, now each at a random place within its interval; for a uniformly
// random seed each value alone is uniform.
inline uint32_t owen_van_der_corput_bits(uint32_t i, uint32_t seed) {
  i += seed;
  i ^= i * 0x6c50b47cu;
  i ^= i * 0xb82f1e52u;
  i ^= i * 0xc7afe638u;
  i ^= i * 0x8d22f6e6u;
  return van_der_corput_bits(i);
}

// The second dimension of the Sobol sequence, as 32 bits: with the van der Corput sequence it
// forms a (0,2)-sequence: the first 2^k points put one point in every rectangle of area 2^-k
// whose sides are powers of two.
inline uint32_t sobol2_bits(uint32_t i) {
  uint32_t v = 1u << 31, r = 0;
  for (; i; i >>= 1, v ^= v >> 1)
    if (i & 1) r ^= v;
  return r;
}

// The Henyey-Greenstein phase function of asymmetry g in (-1, 1), per steradian, at the cosine
// between the directions of travel before and after scattering (g > 0 scatters forward).
inline float henyey_greenstein(float cos_theta, float g) {
  const float d = 1 + g * g - 2 * g * cos_theta;
  return (1 - g * g) / (4 * 3.14159265358979f * d * std::sqrt(std::fmax(d, 1e-12f)));
}

// A new direction of travel after scattering from `travel` (unit), drawn with density
// henyey_greenstein(dot(travel, new), g) exactly.
Vec3 sample_henyey_greenstein(Vec3 travel, float g, Vec2 u);

inline float power_heuristic(float pdf_a, float pdf_b) {
  float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  if (std::isinf(a)) return 1;
  return a + b > 0 ? a / (a + b) : 0;
}

// Discrete distribution by inverse CDF over non-negative weights.
class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(const std::vector<float>& weights);
  bool empty() const { return pmf_.empty(); }
  int size() const { return static_cast<int>(pmf_.size()); }
  // Returns an index with probability pmf(index); u is remapped to [0,1) for reuse.
  int sample(float u, float* pmf_out = nullptr, float* u_remapped = nullptr) const;
  float pmf(int i) const { return pmf_[i]; }
  double total() const { return total_; }

 private:
  std::vector<float> pmf_;
  std::vector<double> cdf_;
  double total_ = 0;
};

// Discrete distribution by Walker's alias method (Vose's construction): a draw costs two look-ups
// whatever the number of entries, where the inverse CDF costs a binary search. For large tables
// drawn often (the emission guide's cells). The bin comes from 32 random bits, so every bin is
// equally likely to within n / 2^32; zero-weight entries are never drawn.
class AliasTable {
 public:
  AliasTable() = default;
  explicit AliasTable(const std::vector<float>& weights);
  bool empty() const { return bins_.empty(); }
  int size() const { return static_cast<int>(bins_.size()); }
  // An index with probability pmf(index), from 32 uniform bits and a uniform coin in [0, 1).
  int sample(uint32_t bits, float coin, float* pmf_out = nullptr) const {
    const uint32_t i = uint32_t((uint64_t(bits) * bins_.size()) >> 32);
    const Bin& b = bins_[i];
    const uint32_t k = coin < b.keep ? i : b.alias;
    if (pmf_out) *pmf_out = bins_[k].pmf;
    return int(k);
  }
  float pmf(int i) const { return bins_[size_t(i)].pmf; }
  // A bin's parts, for a caller that keeps its own copy of the table with more in each bin.
  float keep(int i) const { return bins_[size_t(i)].keep; }
  uint32_t alias(int i) const { return bins_[size_t(i)].alias; }

 private:
  struct Bin {
    float keep;      // probability of keeping this bin's own index
    uint32_t alias;  // the index drawn otherwise
    float pmf;       // this index's probability
  };
  std::vector<Bin> bins_;
};

// Piecewise-constant density over [0, 1]^2 on a w x h grid of non-negative weights (row-major,
// row 0 at the smallest y); an all-zero grid is uniform.
class Distribution2D {
 public:
  Distribution2D() = default;
  Distribution2D(const std::vector<float>& weights, int w, int h);
  bool empty() const { return rows_.empty(); }
  // A point with density pdf (over the unit square's area).
  Vec2 sample(Vec2 u, float* pdf) const;
  float pdf(Vec2 p) const;

 private:
  int w_ = 0, h_ = 0;
  Distribution1D marginal_;
  std::vector<Distribution1D> rows_;
};

// Clarberg's equal-area map between the unit square and the unit sphere (an octahedron unfolded:
// the square's centre is +z, its corners -z), the layout of pbrt-v4's environment images. Equal
// areas of the square map to equal solid angles: d omega = 4 pi du dv.
Vec3 equal_area_square_to_sphere(Vec2 p);
Vec2 equal_area_sphere_to_square(Vec3 d);
// The solid angle of one cell of row `row` of a width x height latitude-longitude grid (rows of
// equal polar angle from the pole at row 0, every cell of a row the same).
inline double latlong_cell_solid_angle(int row, int width, int height) {
  const double t0 = 3.14159265358979323846 * row / height,
               t1 = 3.14159265358979323846 * (row + 1) / height;
  return 2 * 3.14159265358979323846 / width * (std::cos(t0) - std::cos(t1));
}

// A point of the square's neighbourhood folded back into it as the sphere continues across each
// edge (mirrored about the edge's middle), for lookups a little outside the square.
Vec2 wrap_equal_area_square(Vec2 p);

}  // namespace bpm
