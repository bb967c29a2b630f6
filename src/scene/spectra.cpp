#include "scene/spectra.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "film/camera_response.h"

namespace bpm {

std::optional<SpectrumCurve> named_spectrum(const std::string& name, SpectrumKind kind) {
  // Metals: the complex index of refraction at 450, 550 and 650 nm of the measured data pbrt-v4
  // tabulates, joined linearly (bpm does not ship the full tables). Glasses: index at the d line.
  struct Metal {
    const char* name;
    double v450, v550, v650;
  };
  static const Metal metals[] = {
      {"metal-Cu-eta", 1.102212, 0.924033, 0.200438}, {"metal-Cu-k", 2.142188, 2.452848, 3.912949},
      {"metal-Au-eta", 1.442479, 0.374957, 0.143119}, {"metal-Au-k", 1.603215, 2.385721, 3.983160},
      {"metal-Ag-eta", 0.138342, 0.116723, 0.155265}, {"metal-Ag-k", 2.146961, 3.122249, 4.828181},
      {"metal-Al-eta", 0.521229, 0.880369, 1.657460}, {"metal-Al-k", 4.837001, 6.269523, 9.223869},
      {"metal-CuZn-eta", 1.094, 0.527, 0.444},        {"metal-CuZn-k", 1.829, 2.765, 3.695},
      {"metal-MgO-eta", 1.7497, 1.7373, 1.7357},      {"metal-MgO-k", 0, 0, 0},
      {"metal-TiO2-eta", 3.1520, 2.9568, 2.8717},     {"metal-TiO2-k", 0, 0, 0},
  };
  for (const Metal& m : metals)
    if (name == m.name)
      return SpectrumCurve::from_pairs({450, m.v450, 550, m.v550, 650, m.v650}, kind);
  // Glasses: Schott's Sellmeier dispersion formula, n^2 = 1 + sum B_i l^2 / (l^2 - C_i) (l in um),
  // with the catalogue coefficients of the glasses pbrt-v4 names (its "glass-F5", "-F10" and
  // "-F11" are Schott SF5, SF10 and SF11). Each gives its catalogue n_d at 587.56 nm.
  struct Glass {
    const char* name;
    double b[3], c[3];
  };
  static const Glass glasses[] = {
      {"glass-BK7",
       {1.03961212, 0.231792344, 1.01046945},
       {0.00600069867, 0.0200179144, 103.560653}},
      {"glass-BAF10",
       {1.5851495, 0.143559385, 1.08521269},
       {0.00926681282, 0.0424489805, 105.613573}},
      {"glass-FK51A",
       {0.971247817, 0.216901417, 0.904651666},
       {0.00472301995, 0.0153575612, 168.68133}},
      {"glass-LASF9",
       {2.00029547, 0.298926886, 1.80691843},
       {0.0121426017, 0.0538736236, 156.530829}},
      {"glass-F5", {1.52481889, 0.187085527, 1.42729015}, {0.011254756, 0.0588995392, 129.141675}},
      {"glass-F10",
       {1.62153902, 0.256287842, 1.64447552},
       {0.0122241457, 0.0595736775, 147.468793}},
      {"glass-F11", {1.73759695, 0.313747346, 1.89878101}, {0.013188707, 0.0623068142, 155.23629}},
  };
  for (const Glass& g : glasses) {
    if (name != g.name) continue;
    std::vector<float> values;
    for (float lambda = kLambdaMin; lambda <= kLambdaMax; lambda += 1) {
      double l2 = double(lambda) * lambda * 1e-6, n2 = 1;
      for (int i = 0; i < 3; ++i) n2 += g.b[i] * l2 / (l2 - g.c[i]);
      values.push_back(float(std::sqrt(n2)));
    }
    return SpectrumCurve::from_table(std::move(values), SpectrumKind::kUnbounded);
  }
  // The camera sensors' measured sensitivities (film/camera_response.h), NAME_r, _g and _b,
  // zero beyond 380 to 720 nm as pbrt-v4 has them.
  for (int i = 0; i < camera_curves::kCameraCount; ++i) {
    const camera_curves::CameraCurves& cam = camera_curves::kCameras[i];
    for (int c = 0; c < 3; ++c) {
      if (name != std::string(cam.name) + "_" + "rgb"[c]) continue;
      std::vector<double> pairs{375, 0};
      for (int k = 0; k < camera_curves::kSamples; ++k)
        pairs.insert(pairs.end(), {380.0 + 10 * k, double(cam.rgb[c][k])});
      pairs.insert(pairs.end(), {725, 0});
      return SpectrumCurve::from_pairs(pairs, kind);
    }
  }
  if (kind == SpectrumKind::kIlluminant) {
    if (name == "stdillum-D65") return SpectrumCurve::from_rgb(Rgb(1.0f), kind);
    if (name == "stdillum-A") return SpectrumCurve::blackbody(2856);
    if (name == "stdillum-D50")
      return SpectrumCurve::blackbody(5003);  // its CCT; not the daylight curve
  }
  return std::nullopt;
}

std::optional<SpectrumCurve> get_spectrum(const ParamSet& ps, const std::string& name,
                                          SpectrumKind kind, const std::string& directory,
                                          std::vector<std::string>* files_read) {
  const Param* p = ps.find_any(name);
  if (!p) return std::nullopt;
  p->used = true;
  SpectrumCurve s;
  // pbrt-v4 normalises every light spectrum except an RGB one to unit luminance.
  auto unit_luminance = [kind](SpectrumCurve c) {
    float y = c.luminance();
    return kind == SpectrumKind::kIlluminant && y > 0 ? c.scaled(1 / y) : c;
  };
  if (p->type == "rgb") {
    if (p->numbers.size() != 3)
      throw Error(p->loc, "parameter \"" + name + "\" of type rgb needs 3 values; got " +
                              std::to_string(p->numbers.size()));
    Rgb rgb(float(p->numbers[0]), float(p->numbers[1]), float(p->numbers[2]));
    if (!rgb.is_finite() || rgb.has_negative())
      throw Error(p->loc, "parameter \"" + name + "\" has a negative or non-finite value");
    if (kind == SpectrumKind::kAlbedo && rgb.max_component() > 1)
      throw Error(p->loc, "parameter \"" + name + "\" is a reflectance and must not exceed 1");
    s = SpectrumCurve::from_rgb(rgb, kind);
  } else if (p->type == "blackbody") {
    float T = float(p->numbers[0]);
    if (!(T > 0)) throw Error(p->loc, "blackbody temperature must be positive");
    s = unit_luminance(SpectrumCurve::blackbody(T));
    if (p->numbers.size() == 2) s = s.scaled(float(p->numbers[1]));
  } else if (p->type == "spectrum" && !p->strings.empty()) {
    const std::string& str = p->strings[0];
    if (auto named = named_spectrum(str, kind)) {
      s = unit_luminance(*named);
    } else {
      std::filesystem::path path = std::filesystem::path(str).is_absolute()
                                       ? std::filesystem::path(str)
                                       : std::filesystem::path(directory) / str;
      std::ifstream in(path);
      if (!in)
        throw Error(
            p->loc,
            "\"" + str + "\" is neither a known named spectrum nor a readable spectrum file");
      if (files_read) files_read->push_back(path.string());
      std::vector<double> pairs;
      std::string line;
      while (std::getline(in, line)) {
        if (auto h = line.find('#'); h != std::string::npos) line.resize(h);
        std::istringstream ls(line);
        double v;
        while (ls >> v) pairs.push_back(v);
        if (!ls.eof())
          throw Error(p->loc, "spectrum file \"" + str + "\" holds something other than numbers");
      }
      if (pairs.size() < 2 || pairs.size() % 2)
        throw Error(p->loc, "spectrum file \"" + str + "\" must hold wavelength/value pairs");
      s = unit_luminance(SpectrumCurve::from_pairs(pairs, kind));
    }
  } else if (p->type == "spectrum") {
    for (size_t i = 2; i < p->numbers.size(); i += 2)
      if (p->numbers[i] <= p->numbers[i - 2])
        throw Error(p->loc, "spectrum wavelengths must increase");
    s = unit_luminance(SpectrumCurve::from_pairs(p->numbers, kind));
  } else {
    throw Error(p->loc, "parameter \"" + name + "\" has type \"" + p->type +
                            "\"; expected rgb, spectrum or blackbody");
  }
  if (!s.rgb().is_finite() || !(s.min_value() >= 0) || !std::isfinite(s.max_value()))
    throw Error(p->loc, "parameter \"" + name + "\" has a negative or non-finite value");
  if (kind == SpectrumKind::kAlbedo && s.max_value() > 1.0001f)
    throw Error(p->loc, "parameter \"" + name + "\" is a reflectance and must not exceed 1");
  return s;
}

}  // namespace bpm
