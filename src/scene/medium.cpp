#include "scene/medium.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "base/error.h"

namespace bpm {

namespace {

// World to lattice coordinates for nx x ny x nz samples at the voxel centres of the box [p0, p1]
// of the medium's space: [0, 1]^3 of the box, then n u - 0.5.
Transform lattice_transform(int nx, int ny, int nz, Vec3 p0, Vec3 p1,
                            const Transform& world_from_medium) {
  const Vec3 size = p1 - p0;
  const Transform unit =
      Transform::scale({1 / size.x, 1 / size.y, 1 / size.z}) * Transform::translate(-p0);
  return Transform::translate({-0.5f, -0.5f, -0.5f}) *
         Transform::scale({float(nx), float(ny), float(nz)}) * unit * world_from_medium.inverse();
}

float axis(Vec3 v, int a) { return a == 0 ? v.x : a == 1 ? v.y : v.z; }

// The 8 samples around one cell of the lattice (a float or a Spectrum each), and the value at a
// point of it (f: the point's offset from the cell's lowest corner, in [0, 1]^3).
template <class T>
struct Cell {
  std::array<T, 8> v;  // index: x + 2 y + 4 z
  template <class Sample>
  Cell(int i, int j, int k, Sample&& sample) {
    for (int c = 0; c < 8; ++c)
      v[size_t(c)] = sample(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
  }
  T at(Vec3 f) const {
    f = {std::clamp(f.x, 0.0f, 1.0f), std::clamp(f.y, 0.0f, 1.0f), std::clamp(f.z, 0.0f, 1.0f)};
    auto lerp = [](float t, const T& a, const T& b) { return a + (b - a) * t; };
    const T x00 = lerp(f.x, v[0], v[1]), x10 = lerp(f.x, v[2], v[3]);
    const T x01 = lerp(f.x, v[4], v[5]), x11 = lerp(f.x, v[6], v[7]);
    return lerp(f.z, lerp(f.y, x00, x10), lerp(f.y, x01, x11));
  }
};

// A straight piece of a ray inside one lattice cell: the cell, and t from ta to tb.
struct LatticePiece {
  int c[3];
  float ta, tb;
  Vec3 go, gd;  // the ray in lattice coordinates
  // The point at a fraction s of the piece, relative to the cell's lowest corner.
  Vec3 at(float s) const {
    return go + gd * (ta + (tb - ta) * s) - Vec3{float(c[0]), float(c[1]), float(c[2])};
  }
  // The piece's values at s = 0, 1/3, 2/3, 1 (a cubic along it) and their integral over it,
  // Simpson's 3/8 rule (exact for a cubic).
  template <class T>
  std::array<T, 4> values(const Cell<T>& cell) const {
    return {cell.at(at(0)), cell.at(at(1.0f / 3)), cell.at(at(2.0f / 3)), cell.at(at(1))};
  }
  template <class T>
  T integral(const std::array<T, 4>& y) const {
    return (y[0] + (y[1] + y[2]) * 3 + y[3]) * ((tb - ta) / 8);
  }
};

// The integral up to s of a cubic on [0, 1] of length h given by its values at s = 0, 1/3, 2/3, 1
// (its coefficients in x = 3 s from Newton's forward differences), and the s at which that
// reaches `depth` (by bisection: the integral of a non-negative function never decreases).
float cubic_integral_up_to(const std::array<float, 4>& y, float h, float s) {
  const float d1 = y[1] - y[0], d2 = y[2] - 2 * y[1] + y[0], d3 = y[3] - 3 * y[2] + 3 * y[1] - y[0];
  const float c0 = y[0], c1 = d1 - d2 / 2 + d3 / 3, c2 = d2 / 2 - d3 / 2, c3 = d3 / 6;
  const float x = 3 * s;
  return h / 3 * x * (c0 + x * (c1 / 2 + x * (c2 / 3 + x * c3 / 4)));
}
float cubic_solve(const std::array<float, 4>& y, float h, float depth) {
  float lo = 0, hi = 1;
  for (int i = 0; i < 30; ++i) {
    const float mid = 0.5f * (lo + hi);
    (cubic_integral_up_to(y, h, mid) < depth ? lo : hi) = mid;
  }
  return 0.5f * (lo + hi);
}

// Calls visit(const LatticePiece&) for each piece of o + d t, t in [t0, t1] clipped to the box of
// an n[0] x n[1] x n[2] lattice, that lies in one cell, in order, until visit returns false.
// Returns where the walk ended: where visit stopped (the piece's start), or where the ray leaves
// the box; negative when it misses the box.
template <class Visit>
float walk_lattice(const Transform& lattice_from_world, const int n[3], const Ray& ray, float t0,
                   float t1, Visit&& visit) {
  LatticePiece piece;
  piece.go = lattice_from_world.point(ray.o);
  piece.gd = lattice_from_world.vector(ray.d);
  const Vec3 go = piece.go, gd = piece.gd;
  float ta = std::max(t0, 0.0f), tb = t1;
  for (int a = 0; a < 3; ++a) {
    const float o = axis(go, a), d = axis(gd, a), lo = -0.5f, hi = float(n[a]) - 0.5f;
    if (d == 0) {
      if (o < lo || o > hi) return -1;
      continue;
    }
    float e0 = (lo - o) / d, e1 = (hi - o) / d;
    if (e0 > e1) std::swap(e0, e1);
    ta = std::max(ta, e0);
    tb = std::min(tb, e1);
  }
  if (!(ta < tb)) return -1;
  float t_next[3], t_step[3];
  int step[3];
  int* c = piece.c;
  for (int a = 0; a < 3; ++a) {
    const float o = axis(go, a), d = axis(gd, a), p = o + d * ta;
    c[a] = int(std::floor(p));
    if (d < 0 && float(c[a]) == p) --c[a];
    c[a] = std::clamp(c[a], -1, n[a] - 1);
    step[a] = d > 0 ? 1 : -1;
    t_step[a] = d != 0 ? std::fabs(1 / d) : kInf;
    t_next[a] = d > 0 ? (float(c[a] + 1) - o) / d : d < 0 ? (float(c[a]) - o) / d : kInf;
  }
  float t = ta;
  while (t < tb) {
    const int a =
        t_next[0] < t_next[1] ? (t_next[0] < t_next[2] ? 0 : 2) : (t_next[1] < t_next[2] ? 1 : 2);
    const float te = std::min(t_next[a], tb);
    if (te > t) {
      piece.ta = t;
      piece.tb = te;
      if (!visit(piece)) return t;
    }
    t = te;
    c[a] += step[a];
    if (c[a] < -1 || c[a] >= n[a]) break;
    t_next[a] += t_step[a];
  }
  return tb;
}

// The lattice cell that holds a lattice point, or false outside the box.
bool cell_of(Vec3 q, const int n[3], int c[3]) {
  for (int a = 0; a < 3; ++a) {
    const float x = axis(q, a);
    if (!(x >= -0.5f && x <= float(n[a]) - 0.5f)) return false;
    c[a] = std::clamp(int(std::floor(x)), -1, n[a] - 1);
  }
  return true;
}

}  // namespace

DensityGrid::DensityGrid(int nx_, int ny_, int nz_, std::vector<float> values_, Vec3 p0, Vec3 p1,
                         const Transform& world_from_medium)
    : nx(nx_),
      ny(ny_),
      nz(nz_),
      values(std::move(values_)),
      lattice_from_world(lattice_transform(nx_, ny_, nz_, p0, p1, world_from_medium)) {
  BPM_CHECK(size_t(nx) * size_t(ny) * size_t(nz) == values.size());
}

float DensityGrid::density(Vec3 p) const {
  const Vec3 q = lattice_from_world.point(p);
  const int n[3] = {nx, ny, nz};
  int c[3];
  if (!cell_of(q, n, c)) return 0;
  const Cell<float> cell(c[0], c[1], c[2], [&](int i, int j, int k) { return at(i, j, k); });
  return cell.at(q - Vec3{float(c[0]), float(c[1]), float(c[2])});
}

float DensityGrid::depth(const Ray& ray, float t0, float t1) const {
  const int n[3] = {nx, ny, nz};
  float depth = 0;
  walk_lattice(lattice_from_world, n, ray, t0, t1, [&](const LatticePiece& p) {
    const Cell<float> cell(p.c[0], p.c[1], p.c[2],
                           [&](int i, int j, int k) { return at(i, j, k); });
    depth += p.integral(p.values(cell));
    return true;
  });
  return depth;
}

float DensityGrid::distance_at_depth(const Ray& ray, float tau, float t_max) const {
  const int n[3] = {nx, ny, nz};
  float depth = 0, t = -1;
  const float end = walk_lattice(lattice_from_world, n, ray, 0, t_max, [&](const LatticePiece& p) {
    const Cell<float> cell(p.c[0], p.c[1], p.c[2],
                           [&](int i, int j, int k) { return at(i, j, k); });
    const std::array<float, 4> y = p.values(cell);
    const float add = p.integral(y);
    if (depth + add >= tau) {
      t = p.ta + (p.tb - p.ta) * cubic_solve(y, p.tb - p.ta, tau - depth);
      return false;
    }
    depth += add;
    return true;
  });
  if (t >= 0) return t;
  // A depth drawn below the whole way's (as computed before) may miss it by rounding.
  return end >= 0 && depth >= tau * (1 - 1e-5f) ? end : -1.0f;
}

namespace {

// Colours as SpectrumCurve::from_rgb's unbounded ones: the largest channel scaled to 0.5 (an
// illuminant's, pbrt-v4's RGBIlluminantSpectrum, is the same curve times D65).
std::vector<RgbGrid::Voxel> rgb_voxels(const std::vector<Rgb>& rgb) {
  std::vector<RgbGrid::Voxel> v(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) {
    const float m = rgb[i].max_component();
    if (!(m > 0)) continue;
    v[i].scale = 2 * m;
    v[i].coeff = sigmoid_coefficients_lookup(rgb[i] / (2 * m));
  }
  return v;
}

}  // namespace

RgbGrid::RgbGrid(int nx_, int ny_, int nz_, const std::vector<Rgb>& a, const std::vector<Rgb>& s,
                 float scale_, Vec3 p0, Vec3 p1, const Transform& world_from_medium)
    : nx(nx_),
      ny(ny_),
      nz(nz_),
      scale(scale_),
      lattice_from_world(lattice_transform(nx_, ny_, nz_, p0, p1, world_from_medium)) {
  sigma_a = rgb_voxels(a);
  sigma_s = rgb_voxels(s);
  scatters = scale > 0 && (s.empty() || std::any_of(s.begin(), s.end(), [](const Rgb& c) {
                             return c.max_component() > 0;
                           }));
}

namespace {

// The wavelengths' places in the sigmoids' polynomial (normalised_lambda), computed once for the
// many voxels of a lookup or a walk.
using LambdaPlaces = std::array<float, Spectrum::kChannels>;
LambdaPlaces places_of(const Wavelengths& wl) {
  LambdaPlaces u;
  for (int c = 0; c < Spectrum::kChannels; ++c) u[size_t(c)] = normalised_lambda(wl.lambda[c]);
  return u;
}

// One voxel's colour at the wavelengths, times `scale`; 1 where the grid gives none, 0 beyond it.
Spectrum voxel_spectrum(const RgbGrid& g, const std::vector<RgbGrid::Voxel>& voxels, int i, int j,
                        int k, const LambdaPlaces& u, float factor) {
  if (voxels.empty()) return Spectrum(factor);
  if (i < 0 || j < 0 || k < 0 || i >= g.nx || j >= g.ny || k >= g.nz) return {};
  const RgbGrid::Voxel& v =
      voxels[(size_t(k) * size_t(g.ny) + size_t(j)) * size_t(g.nx) + size_t(i)];
  Spectrum s;
  if (v.scale == 0) return s;
  for (int c = 0; c < Spectrum::kChannels; ++c)
    s[c] = factor * v.scale * sigmoid_spectrum_at(v.coeff, u[size_t(c)]);
  return s;
}

// sigma_t at the voxels of the cells a walk along one ray crosses, as voxel_spectrum gives it. A
// step to a neighbouring cell keeps the four corners of their shared face: each corner has a slot
// by the parity of its (i, j, k), which such a step leaves the same, so each voxel's spectra are
// computed once per walk (the sigmoids are most of an rgbgrid's cost).
class SigmaTVoxels {
 public:
  SigmaTVoxels(const RgbGrid& g, const Wavelengths& wl) : g_(g), u_(places_of(wl)) {}
  Cell<Spectrum> cell(const int c[3]) {
    return Cell<Spectrum>(c[0], c[1], c[2], [&](int i, int j, int k) { return at(i, j, k); });
  }

 private:
  Spectrum at(int i, int j, int k) {
    const size_t slot = size_t((i & 1) | (j & 1) << 1 | (k & 1) << 2);
    const std::array<int, 3> key{i, j, k};
    if (!known_[slot] || keys_[slot] != key) {
      keys_[slot] = key;
      known_[slot] = true;
      values_[slot] = voxel_spectrum(g_, g_.sigma_a, i, j, k, u_, g_.scale) +
                      voxel_spectrum(g_, g_.sigma_s, i, j, k, u_, g_.scale);
    }
    return values_[slot];
  }
  const RgbGrid& g_;
  const LambdaPlaces u_;
  std::array<std::array<int, 3>, 8> keys_{};
  std::array<bool, 8> known_{};
  std::array<Spectrum, 8> values_{};
};

}  // namespace

void RgbGrid::coefficients(Vec3 p, const Wavelengths& wl, Spectrum* a, Spectrum* s) const {
  const Vec3 q = lattice_from_world.point(p);
  const int n[3] = {nx, ny, nz};
  int c[3];
  *a = *s = Spectrum();
  if (!cell_of(q, n, c)) return;
  const Vec3 f = q - Vec3{float(c[0]), float(c[1]), float(c[2])};
  const LambdaPlaces u = places_of(wl);
  *a = Cell<Spectrum>(c[0], c[1], c[2], [&](int i, int j, int k) {
         return voxel_spectrum(*this, sigma_a, i, j, k, u, scale);
       }).at(f);
  *s = Cell<Spectrum>(c[0], c[1], c[2], [&](int i, int j, int k) {
         return voxel_spectrum(*this, sigma_s, i, j, k, u, scale);
       }).at(f);
}

void RgbGrid::set_glow(const std::vector<Rgb>& colours, float scale_of_le) {
  Le = rgb_voxels(colours);
  le_scale = scale_of_le;
}

Spectrum RgbGrid::glow(Vec3 p, const Wavelengths& wl) const {
  Spectrum e;
  const Vec3 q = lattice_from_world.point(p);
  const int n[3] = {nx, ny, nz};
  int c[3];
  if (!glows() || !cell_of(q, n, c)) return e;
  const Vec3 f = q - Vec3{float(c[0]), float(c[1]), float(c[2])};
  const LambdaPlaces u = places_of(wl);
  e = Cell<Spectrum>(c[0], c[1], c[2], [&](int i, int j, int k) {
        return voxel_spectrum(*this, Le, i, j, k, u, 1);
      }).at(f);
  const float k = le_scale * float(ybar_integral());
  for (int i = 0; i < Spectrum::kChannels; ++i) e[i] *= k * d65_unit(wl.lambda[i]);
  return e;
}

Spectrum RgbGrid::depth(const Ray& ray, float t0, float t1, const Wavelengths& wl) const {
  const int n[3] = {nx, ny, nz};
  Spectrum depth;
  SigmaTVoxels voxels(*this, wl);
  walk_lattice(lattice_from_world, n, ray, t0, t1, [&](const LatticePiece& p) {
    depth += p.integral(p.values(voxels.cell(p.c)));
    return true;
  });
  return depth;
}

float RgbGrid::flight(const Ray& ray, int channel, float tau, float t_max, const Wavelengths& wl,
                      Spectrum* depth) const {
  const int n[3] = {nx, ny, nz};
  float t = -1;
  *depth = Spectrum();
  SigmaTVoxels voxels(*this, wl);
  const float end = walk_lattice(lattice_from_world, n, ray, 0, t_max, [&](const LatticePiece& p) {
    const std::array<Spectrum, 4> ys = p.values(voxels.cell(p.c));
    const Spectrum add = p.integral(ys);
    if ((*depth)[channel] + add[channel] >= tau) {
      const float h = p.tb - p.ta;
      auto channel_values = [&](int k) {
        return std::array<float, 4>{ys[0][k], ys[1][k], ys[2][k], ys[3][k]};
      };
      const float s = cubic_solve(channel_values(channel), h, tau - (*depth)[channel]);
      t = p.ta + h * s;
      for (int k = 0; k < Spectrum::kChannels; ++k)
        (*depth)[k] += cubic_integral_up_to(channel_values(k), h, s);
      return false;
    }
    *depth += add;
    return true;
  });
  if (t >= 0) return t;
  // A depth drawn below the whole way's (as computed before) may miss it by rounding.
  return end >= 0 && (*depth)[channel] >= tau * (1 - 1e-5f) ? end : -1.0f;
}

float RgbGrid::distance_at_depth(const Ray& ray, int channel, float tau, float t_max,
                                 const Wavelengths& wl) const {
  Spectrum depth;
  return flight(ray, channel, tau, t_max, wl, &depth);
}

namespace {

struct Preset {
  const char* name;
  Rgb sigma_prime_s, sigma_a;  // mm^-1
};

// The measurements pbrt-v4 names (see the header).
constexpr Preset kPresets[] = {
    {"Apple", {2.29f, 2.39f, 1.97f}, {0.0030f, 0.0034f, 0.046f}},
    {"Chicken1", {0.15f, 0.21f, 0.38f}, {0.015f, 0.077f, 0.19f}},
    {"Chicken2", {0.19f, 0.25f, 0.32f}, {0.018f, 0.088f, 0.20f}},
    {"Cream", {7.38f, 5.47f, 3.15f}, {0.0002f, 0.0028f, 0.0163f}},
    {"Ketchup", {0.18f, 0.07f, 0.03f}, {0.061f, 0.97f, 1.45f}},
    {"Marble", {2.19f, 2.62f, 3.00f}, {0.0021f, 0.0041f, 0.0071f}},
    {"Potato", {0.68f, 0.70f, 0.55f}, {0.0024f, 0.0090f, 0.12f}},
    {"Skimmilk", {0.70f, 1.22f, 1.90f}, {0.0014f, 0.0025f, 0.0142f}},
    {"Skin1", {0.74f, 0.88f, 1.01f}, {0.032f, 0.17f, 0.48f}},
    {"Skin2", {1.09f, 1.59f, 1.79f}, {0.013f, 0.070f, 0.145f}},
    {"Spectralon", {11.6f, 20.4f, 14.9f}, {0.00f, 0.00f, 0.00f}},
    {"Wholemilk", {2.55f, 3.21f, 3.77f}, {0.0011f, 0.0024f, 0.014f}},
    {"Lowfat Milk", {0.89187f, 1.5136f, 2.532f}, {0.002875f, 0.00575f, 0.0115f}},
    {"Reduced Milk", {2.4858f, 3.1669f, 4.5214f}, {0.0025556f, 0.0051111f, 0.012778f}},
    {"Regular Milk", {4.5513f, 5.8294f, 7.136f}, {0.0015333f, 0.0046f, 0.019933f}},
    {"Espresso", {0.72378f, 0.84557f, 1.0247f}, {4.7984f, 6.5751f, 8.8493f}},
    {"Mint Mocha Coffee", {0.31602f, 0.38538f, 0.48131f}, {3.772f, 5.8228f, 7.82f}},
    {"Lowfat Soy Milk", {0.30576f, 0.34233f, 0.61664f}, {0.0014375f, 0.0071875f, 0.035937f}},
    {"Regular Soy Milk", {0.59223f, 0.73866f, 1.4693f}, {0.0019167f, 0.0095833f, 0.065167f}},
    {"Lowfat Chocolate Milk", {0.64925f, 0.83916f, 1.1057f}, {0.0115f, 0.0368f, 0.1564f}},
    {"Regular Chocolate Milk", {1.4585f, 2.1289f, 2.9527f}, {0.010063f, 0.043125f, 0.14375f}},
    {"Coke", {8.9053e-05f, 8.372e-05f, 0}, {0.10014f, 0.16503f, 0.2468f}},
    {"Pepsi", {6.1697e-05f, 4.2564e-05f, 0}, {0.091641f, 0.14158f, 0.20729f}},
    {"Sprite", {6.0306e-06f, 6.4139e-06f, 6.5504e-06f}, {0.001886f, 0.0018308f, 0.0020025f}},
    {"Gatorade", {0.0024574f, 0.003007f, 0.0037325f}, {0.024794f, 0.019289f, 0.008878f}},
    {"Chardonnay", {1.7982e-05f, 1.3758e-05f, 1.2023e-05f}, {0.010782f, 0.011855f, 0.023997f}},
    {"White Zinfandel", {1.7501e-05f, 1.9069e-05f, 1.288e-05f}, {0.012072f, 0.016184f, 0.019843f}},
    {"Merlot", {2.1129e-05f, 0, 0}, {0.11632f, 0.25191f, 0.29434f}},
    {"Budweiser Beer", {2.4356e-05f, 2.4079e-05f, 1.0564e-05f}, {0.011492f, 0.024911f, 0.057786f}},
    {"Coors Light Beer", {5.0922e-05f, 4.301e-05f, 0}, {0.006164f, 0.013984f, 0.034983f}},
    {"Clorox", {0.0024035f, 0.0031373f, 0.003991f}, {0.0033542f, 0.014892f, 0.026297f}},
    {"Apple Juice", {0.00013612f, 0.00015836f, 0.000227f}, {0.012957f, 0.023741f, 0.052184f}},
    {"Cranberry Juice", {0.00010402f, 0.00011646f, 7.8139e-05f}, {0.039437f, 0.094223f, 0.12426f}},
    {"Grape Juice", {5.382e-05f, 0, 0}, {0.10404f, 0.23958f, 0.29325f}},
    {"Ruby Grapefruit Juice", {0.011002f, 0.010927f, 0.011036f}, {0.085867f, 0.18314f, 0.25262f}},
    {"White Grapefruit Juice", {0.22826f, 0.23998f, 0.32748f}, {0.0138f, 0.018831f, 0.056781f}},
    {"Shampoo", {0.0007176f, 0.0008303f, 0.0009016f}, {0.014107f, 0.045693f, 0.061717f}},
    {"Strawberry Shampoo", {0.00015671f, 0.00015947f, 1.518e-05f}, {0.01449f, 0.05796f, 0.075823f}},
    {"Head & Shoulders Shampoo",
     {0.023805f, 0.028804f, 0.034306f},
     {0.084621f, 0.15688f, 0.20365f}},
    {"Lemon Tea Powder", {0.040224f, 0.045264f, 0.051081f}, {2.4288f, 4.5757f, 7.2127f}},
    {"Orange Powder", {0.00015617f, 0.00017482f, 0.0001762f}, {0.001449f, 0.003441f, 0.007863f}},
    {"Pink Lemonade Powder",
     {0.00012103f, 0.00013073f, 0.00012528f},
     {0.001165f, 0.002366f, 0.003195f}},
    {"Cappuccino Powder", {1.8436f, 2.5851f, 2.1662f}, {35.844f, 49.547f, 61.084f}},
    {"Salt Powder", {0.027333f, 0.032451f, 0.031979f}, {0.28415f, 0.3257f, 0.34148f}},
    {"Sugar Powder", {0.00022272f, 0.00025513f, 0.000271f}, {0.012638f, 0.031051f, 0.050124f}},
    {"Suisse Mocha Powder", {2.7979f, 3.5452f, 4.3365f}, {17.502f, 27.004f, 35.433f}},
    {"Pacific Ocean Surface Water",
     {0.0001764f, 0.00032095f, 0.00019617f},
     {0.031845f, 0.031324f, 0.030147f}},
};

}  // namespace

bool medium_preset(const std::string& name, Rgb* sigma_s, Rgb* sigma_a) {
  for (const Preset& p : kPresets)
    if (name == p.name) {
      *sigma_s = p.sigma_prime_s;
      *sigma_a = p.sigma_a;
      return true;
    }
  return false;
}

std::string medium_preset_names() {
  std::string s;
  for (const Preset& p : kPresets) s += (s.empty() ? "\"" : ", \"") + std::string(p.name) + "\"";
  return s;
}

}  // namespace bpm
