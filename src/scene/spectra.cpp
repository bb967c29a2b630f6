#include "scene/spectra.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace bpm {
namespace {

// CIE 1931 colour matching functions, multi-lobe Gaussian fit of Wyman, Sloan and Shirley,
// "Simple Analytic Approximations to the CIE XYZ Color Matching Functions", JCGT 2013.
double lobe(double l, double mu, double s1, double s2) {
  double t = (l - mu) / (l < mu ? s1 : s2);
  return std::exp(-0.5 * t * t);
}
double cie_x(double l) {
  return 1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) -
         0.065 * lobe(l, 501.1, 20.4, 26.2);
}
double cie_y(double l) { return 0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1); }
double cie_z(double l) { return 1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8); }

// XYZ to linear sRGB (D65 white).
Spectrum xyz_to_srgb(double x, double y, double z) {
  return Spectrum(float(3.2404542 * x - 1.5371385 * y - 0.4985314 * z),
                  float(-0.9692660 * x + 1.8760108 * y + 0.0415560 * z),
                  float(0.0556434 * x - 0.2040259 * y + 1.0572252 * z));
}

template <typename F>
void integrate_xyz(F&& spd, double* X, double* Y, double* Z) {
  *X = *Y = *Z = 0;
  for (double l = 360; l <= 830; l += 1) {
    double v = spd(l);
    *X += v * cie_x(l);
    *Y += v * cie_y(l);
    *Z += v * cie_z(l);
  }
}

// RGB of a spectrum, read according to its kind. Illuminants are normalised to luminance 1;
// reflectance-like spectra are balanced so that a constant spectrum c gives (c, c, c).
template <typename F>
Spectrum spd_to_rgb(F&& spd, SpectrumKind kind) {
  double X, Y, Z;
  integrate_xyz(spd, &X, &Y, &Z);
  if (kind == SpectrumKind::kIlluminant) {
    if (Y <= 0) return Spectrum(0.0f);
    return xyz_to_srgb(X / Y, 1.0, Z / Y);
  }
  double Xe, Ye, Ze;
  integrate_xyz([](double) { return 1.0; }, &Xe, &Ye, &Ze);
  Spectrum rgb = xyz_to_srgb(X / Ye, Y / Ye, Z / Ye);
  Spectrum white = xyz_to_srgb(Xe / Ye, 1.0, Ze / Ye);
  Spectrum out = rgb / white;
  for (int i = 0; i < 3; ++i) out[i] = std::fmax(out[i], 0.0f);
  return out;
}

double planck(double lambda_nm, double T) {
  const double c = 299792458.0, h = 6.62606957e-34, kb = 1.3806488e-23;
  double l = lambda_nm * 1e-9;
  return (2 * h * c * c) / (std::pow(l, 5) * (std::exp((h * c) / (l * kb * T)) - 1));
}

}  // namespace

Spectrum blackbody_rgb(float T) {
  return spd_to_rgb([T](double l) { return planck(l, T); }, SpectrumKind::kIlluminant);
}

Spectrum sampled_spectrum_rgb(const std::vector<double>& pairs, SpectrumKind kind) {
  auto spd = [&pairs](double l) {
    size_t n = pairs.size() / 2;
    if (n == 0 || l < pairs[0] || l > pairs[2 * (n - 1)]) return 0.0;
    for (size_t i = 0; i + 1 < n; ++i) {
      double l0 = pairs[2 * i], l1 = pairs[2 * i + 2];
      if (l >= l0 && l <= l1) {
        double t = l1 > l0 ? (l - l0) / (l1 - l0) : 0;
        return pairs[2 * i + 1] * (1 - t) + pairs[2 * i + 3] * t;
      }
    }
    return pairs[2 * n - 1];
  };
  return spd_to_rgb(spd, kind);
}

std::optional<Spectrum> named_spectrum_rgb(const std::string& name, SpectrumKind kind) {
  // Metals: complex index of refraction reduced to the R, G, B channels (values at about 650,
  // 550 and 450 nm of the measured data pbrt-v4 tabulates). Glasses: index at the d line.
  static const std::map<std::string, Spectrum> table = {
      {"metal-Cu-eta", {0.200438f, 0.924033f, 1.102212f}},
      {"metal-Cu-k", {3.912949f, 2.452848f, 2.142188f}},
      {"metal-Au-eta", {0.143119f, 0.374957f, 1.442479f}},
      {"metal-Au-k", {3.983160f, 2.385721f, 1.603215f}},
      {"metal-Ag-eta", {0.155265f, 0.116723f, 0.138342f}},
      {"metal-Ag-k", {4.828181f, 3.122249f, 2.146961f}},
      {"metal-Al-eta", {1.657460f, 0.880369f, 0.521229f}},
      {"metal-Al-k", {9.223869f, 6.269523f, 4.837001f}},
      {"metal-CuZn-eta", {0.444f, 0.527f, 1.094f}},
      {"metal-CuZn-k", {3.695f, 2.765f, 1.829f}},
      {"metal-MgO-eta", {1.7357f, 1.7373f, 1.7497f}},
      {"metal-MgO-k", {0.0f, 0.0f, 0.0f}},
      {"metal-TiO2-eta", {2.8717f, 2.9568f, 3.1520f}},
      {"metal-TiO2-k", {0.0f, 0.0f, 0.0f}},
      {"glass-BK7", Spectrum(1.5168f)},
      {"glass-BAF10", Spectrum(1.6700f)},
      {"glass-FK51A", Spectrum(1.4866f)},
      {"glass-LASF9", Spectrum(1.8503f)},
      {"glass-F5", Spectrum(1.6034f)},
      {"glass-F10", Spectrum(1.6200f)},
      {"glass-F11", Spectrum(1.6209f)},
  };
  auto it = table.find(name);
  if (it != table.end()) return it->second;
  if (kind == SpectrumKind::kIlluminant) {
    if (name == "stdillum-D65") return Spectrum(1.0f);
    if (name == "stdillum-A") return blackbody_rgb(2856);
    if (name == "stdillum-D50") return blackbody_rgb(5003);
  }
  return std::nullopt;
}

std::optional<Spectrum> get_spectrum(const ParamSet& ps, const std::string& name, SpectrumKind kind,
                                     const std::string& directory) {
  const Param* p = ps.find_any(name);
  if (!p) return std::nullopt;
  p->used = true;
  Spectrum s;
  if (p->type == "rgb") {
    s = Spectrum(float(p->numbers[0]), float(p->numbers[1]), float(p->numbers[2]));
  } else if (p->type == "blackbody") {
    float T = float(p->numbers[0]);
    if (!(T > 0)) throw Error(p->loc, "blackbody temperature must be positive");
    s = blackbody_rgb(T);
    if (p->numbers.size() == 2) s *= float(p->numbers[1]);
  } else if (p->type == "spectrum" && !p->strings.empty()) {
    const std::string& str = p->strings[0];
    if (auto named = named_spectrum_rgb(str, kind)) {
      s = *named;
    } else {
      std::filesystem::path path = std::filesystem::path(str).is_absolute()
                                       ? std::filesystem::path(str)
                                       : std::filesystem::path(directory) / str;
      std::ifstream in(path);
      if (!in)
        throw Error(p->loc, "\"" + str + "\" is neither a known named spectrum nor a readable spectrum file");
      std::vector<double> pairs;
      std::string line;
      while (std::getline(in, line)) {
        if (auto h = line.find('#'); h != std::string::npos) line.resize(h);
        std::istringstream ls(line);
        double v;
        while (ls >> v) pairs.push_back(v);
        if (!ls.eof()) throw Error(p->loc, "spectrum file \"" + str + "\" holds something other than numbers");
      }
      if (pairs.size() < 2 || pairs.size() % 2)
        throw Error(p->loc, "spectrum file \"" + str + "\" must hold wavelength/value pairs");
      s = sampled_spectrum_rgb(pairs, kind);
    }
  } else if (p->type == "spectrum") {
    for (size_t i = 2; i < p->numbers.size(); i += 2)
      if (p->numbers[i] <= p->numbers[i - 2])
        throw Error(p->loc, "spectrum wavelengths must increase");
    s = sampled_spectrum_rgb(p->numbers, kind);
  } else {
    throw Error(p->loc, "parameter \"" + name + "\" has type \"" + p->type +
                            "\"; expected rgb, spectrum or blackbody");
  }
  if (!s.is_finite() || s.has_negative())
    throw Error(p->loc, "parameter \"" + name + "\" has a negative or non-finite value");
  if (kind == SpectrumKind::kAlbedo && s.max_component() > 1)
    throw Error(p->loc, "parameter \"" + name + "\" is a reflectance and must not exceed 1");
  return s;
}

}  // namespace bpm
