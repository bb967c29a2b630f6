// pbrt-v4's participating media as the integrators see them: absorption and scattering
// coefficients per unit density, a Henyey-Greenstein phase function, and a density that is 1
// everywhere ("homogeneous") or read from a grid of samples on a box ("uniformgrid").
//
// Everything the integrators need from a medium is its optical depth along a ray: light that
// crosses it keeps exp(-sigma_t tau) with tau the integral of the density along the way, and a
// free flight is drawn in tau (where the density only stretches distances) and mapped back to a
// distance. pbrt-v4 interpolates the grid trilinearly between samples at voxel centres, zero
// beyond the outermost ones (util/containers.h, SampledGrid::Lookup); along a straight line
// through one cell of that lattice the density is then a cubic, whose integral Simpson's 3/8 rule
// gives exactly. So depths, transmittances and free flights through a grid are exact (to
// rounding) and cost no random numbers: the same estimators as in a homogeneous medium, only with
// distances measured in tau.
#pragma once
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "base/color.h"
#include "base/ray.h"
#include "base/spectrum.h"
#include "base/transform.h"

namespace bpm {

// Density samples at the centres of nx x ny x nz voxels filling the box [p0, p1] of the medium's
// space, x fastest (pbrt-v4's "uniformgrid" order).
struct DensityGrid {
  int nx = 1, ny = 1, nz = 1;
  std::vector<float> values;
  // World to lattice coordinates, where sample (i, j, k) sits at (i, j, k): the box spans
  // [-0.5, n - 0.5] along each axis.
  Transform lattice_from_world;

  DensityGrid(int nx, int ny, int nz, std::vector<float> values, Vec3 p0, Vec3 p1,
              const Transform& world_from_medium);
  // A sample; 0 beyond the grid.
  float at(int i, int j, int k) const {
    if (i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz) return 0;
    return values[(size_t(k) * size_t(ny) + size_t(j)) * size_t(nx) + size_t(i)];
  }
  // The density at a world point (0 outside the box).
  float density(Vec3 p) const;
  // The integral of the density along o + d t (d of unit length) over [t0, t1] (t1 may be kInf).
  float depth(const Ray& ray, float t0, float t1) const;
  // The distance t in [0, t_max] at which the depth from 0 reaches tau; negative when the depth up
  // to t_max stays below it.
  float distance_at_depth(const Ray& ray, float tau, float t_max) const;
};

// pbrt-v4's "rgbgrid": per voxel colours of sigma_a and sigma_s (unbounded spectra, as
// SpectrumCurve::from_rgb makes them), interpolated between voxel centres as the density grid's
// samples, times `scale`; a colour not given is 1 everywhere in the box. Along a line through one
// lattice cell each wavelength's sigma_t is again a cubic: depths are exact per wavelength.
struct RgbGrid {
  // A colour as a sigmoid spectrum: scale * sigmoid(polynomial(lambda)).
  struct Voxel {
    std::array<float, 3> coeff{};
    float scale = 0;
  };
  int nx = 1, ny = 1, nz = 1;
  std::vector<Voxel> sigma_a, sigma_s;  // empty: 1 (before `scale`) everywhere in the box
  float scale = 1;
  bool scatters = true;
  // pbrt-v4's per-voxel "Le" colours (illuminant spectra: the sigmoid times D65, not normalised)
  // times one "Lescale": a point emits sigma_a(x) Le(x) per unit length. Empty: no glow.
  std::vector<Voxel> Le;
  float le_scale = 1;
  Transform lattice_from_world;  // as DensityGrid's

  RgbGrid(int nx, int ny, int nz, const std::vector<Rgb>& sigma_a, const std::vector<Rgb>& sigma_s,
          float scale, Vec3 p0, Vec3 p1, const Transform& world_from_medium);
  // Sets the glow: nx ny nz colours of Le (none negative) times le_scale.
  void set_glow(const std::vector<Rgb>& Le, float le_scale);
  bool glows() const { return !Le.empty() && le_scale > 0; }
  // sigma_a and sigma_s at a world point (0 outside the box).
  void coefficients(Vec3 p, const Wavelengths& wl, Spectrum* sigma_a, Spectrum* sigma_s) const;
  // The emitted radiance per unit of sigma_a at a world point, in our units (pbrt-v4 does not
  // normalise it: its film reads it ybar_integral() times brighter than a light's spectrum).
  Spectrum glow(Vec3 p, const Wavelengths& wl) const;
  // The optical depth of sigma_t along o + d t (d of unit length) over [t0, t1], per wavelength.
  Spectrum depth(const Ray& ray, float t0, float t1, const Wavelengths& wl) const;
  // The distance in [0, t_max] at which wavelength `channel`'s depth from 0 reaches tau; negative
  // when it stays below.
  float distance_at_depth(const Ray& ray, int channel, float tau, float t_max,
                          const Wavelengths& wl) const;
  // Both in one walk: the distance at which wavelength `channel`'s depth reaches tau (negative
  // when it stays below), and in *depth every wavelength's depth up to there (or up to t_max).
  float flight(const Ray& ray, int channel, float tau, float t_max, const Wavelengths& wl,
               Spectrum* depth) const;
};

struct Medium {
  std::string name;
  // Per unit density (pbrt-v4's "scale" applied).
  SpectrumCurve sigma_a, sigma_s;
  float g = 0;
  std::shared_ptr<const DensityGrid> grid;  // none: density 1 everywhere
  // An rgbgrid's coefficients, which replace all of the above but g (sigma_a and sigma_s are 1).
  std::shared_ptr<const RgbGrid> rgb_grid;
  // The radiance emitted where sigma_a absorbs (pbrt-v4's Le times Lescale, normalised as a
  // light's spectrum): a point emits sigma_a(x) Le per unit length (not with rgbgrid), times
  // le_scale(x) where a uniformgrid has that grid (pbrt-v4's LeScale).
  SpectrumCurve Le;
  std::shared_ptr<const DensityGrid> le_scale;
  // A uniformgrid that glows by temperature emits, in place of Le, a blackbody (1 at its peak,
  // not normalised: times ybar_integral() in our units) at (T(x) - offset) * scale kelvin, none
  // at 100 K or less (pbrt-v4's GridMedium), times le_scale(x).
  std::shared_ptr<const DensityGrid> temperature;
  float temperature_offset = 0, temperature_scale = 1;

  bool emits() const { return !Le.is_black() || temperature || (rgb_grid && rgb_grid->glows()); }
  // The glow per unit of sigma_a at a point of a uniformgrid with an Lescale grid (le_scale set).
  Spectrum varying_glow(Vec3 p, const Wavelengths& wl) const {
    const float s = le_scale->density(p);
    if (!(s > 0)) return Spectrum();
    if (!temperature) return Le.sample(wl) * s;
    const float T = (temperature->density(p) - temperature_offset) * temperature_scale;
    Spectrum L;
    if (!(T > 100)) return L;
    const float k = float(ybar_integral()) * s;
    for (int i = 0; i < Spectrum::kChannels; ++i) L[i] = k * blackbody(wl.lambda[i], T);
    return L;
  }

  bool scatters() const { return rgb_grid ? rgb_grid->scatters : !sigma_s.is_black(); }
  float density(Vec3 p) const { return grid ? grid->density(p) : 1.0f; }
  // The optical depth in density units along a unit ray over [t0, t1] (see the top of the file).
  float depth(const Ray& ray, float t0, float t1) const {
    return grid ? grid->depth(ray, t0, t1) : t1 - t0;
  }
  float distance_at_depth(const Ray& ray, float tau, float t_max) const {
    if (grid) return grid->distance_at_depth(ray, tau, t_max);
    return tau <= t_max ? tau : -1.0f;
  }
  // sigma_s at a point over sigma_s as given: the density, or an rgbgrid's sigma_s there.
  Spectrum relative_scattering(Vec3 p, const Wavelengths& wl) const {
    if (!rgb_grid) return Spectrum(density(p));
    Spectrum a, s;
    rgb_grid->coefficients(p, wl, &a, &s);
    return s;
  }
};

// pbrt-v4's named scattering media (media.cpp, GetMediumScatteringProperties: Jensen et al. 2001,
// Narasimhan et al. 2006): sigma_prime_s and sigma_a in mm^-1 as linear sRGB. False for an
// unknown name.
bool medium_preset(const std::string& name, Rgb* sigma_s, Rgb* sigma_a);
// The preset names, comma-separated, for messages.
std::string medium_preset_names();

}  // namespace bpm
