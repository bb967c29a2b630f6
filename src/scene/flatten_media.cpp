// The media shapes, lights and the camera refer to: pbrt-v4's "homogeneous" (with its named
// presets), "uniformgrid" and "rgbgrid" media (scene/medium.h).
#include <cmath>
#include <string>

#include "scene/flatten_internal.h"

namespace bpm::flatten_internal {

namespace {

// A grid's size and box, shared by "uniformgrid" and "rgbgrid": nx x ny x nz samples (1 each by
// default) on the box [p0, p1] of the medium's space ((0,0,0) to (1,1,1)).
struct GridBox {
  int nx, ny, nz;
  Vec3 p0, p1;
  uint64_t count() const { return uint64_t(nx) * uint64_t(ny) * uint64_t(nz); }
};

GridBox grid_box(const MediumEntity& m) {
  const ParamSet& ps = m.params;
  for (const char* n : {"nx", "ny", "nz"})
    ps.require(n, ps.get_int(n, 1) >= 1, "must be at least 1", m.loc);
  GridBox b{ps.get_int("nx", 1), ps.get_int("ny", 1), ps.get_int("nz", 1),
            ps.get_point3("p0", {0, 0, 0}), ps.get_point3("p1", {1, 1, 1})};
  ps.require("p1", b.p1.x > b.p0.x && b.p1.y > b.p0.y && b.p1.z > b.p0.z,
             "must exceed p0 along every axis (the grid's box)", m.loc);
  return b;
}

}  // namespace

// pbrt-v4's "uniformgrid" density: nx x ny x nz non-negative values on the box [p0, p1] of the
// medium's space (media.cpp, GridMedium::Create).
std::shared_ptr<const DensityGrid> Flattener::density_grid(const MediumEntity& m) {
  const ParamSet& ps = m.params;
  const Param* density = ps.find("density", "float");
  if (!density) throw Error(m.loc, "uniformgrid medium needs \"float density\" values");
  const GridBox box = grid_box(m);
  std::vector<float> values = ps.get_floats("density");
  const uint64_t expected = box.count();
  if (values.size() != expected)
    throw Error(density->loc, "uniformgrid has " + std::to_string(values.size()) +
                                  " density values; nx * ny * nz = " + std::to_string(expected));
  for (float v : values)
    if (!(v >= 0)) throw Error(density->loc, "density values must not be negative");
  return std::make_shared<DensityGrid>(box.nx, box.ny, box.nz, std::move(values), box.p0, box.p1,
                                       m.world_from_medium);
}

// pbrt-v4's "rgbgrid": per voxel "rgb sigma_a" and "rgb sigma_s" colours (either may be absent:
// 1 everywhere), nx x ny x nz of each, on the box [p0, p1], times "scale" (media.cpp,
// RGBGridMedium::Create).
std::shared_ptr<const RgbGrid> Flattener::rgb_grid(const MediumEntity& m, float scale) {
  const ParamSet& ps = m.params;
  const GridBox box = grid_box(m);
  const uint64_t expected = box.count();
  auto colours = [&](const char* name) {
    std::vector<Rgb> out;
    const Param* p = ps.find(name, "rgb");
    if (!p) return out;
    p->used = true;
    if (p->numbers.size() != 3 * expected)
      throw Error(p->loc, std::string("rgbgrid has ") + std::to_string(p->numbers.size() / 3) +
                              " " + name + " colours; nx * ny * nz = " + std::to_string(expected));
    for (size_t i = 0; i < expected; ++i) {
      const Rgb c(float(p->numbers[3 * i]), float(p->numbers[3 * i + 1]),
                  float(p->numbers[3 * i + 2]));
      if (!(c.min_component() >= 0) || !c.is_finite())
        throw Error(p->loc, std::string(name) + " colours must be finite and not negative");
      out.push_back(c);
    }
    return out;
  };
  const std::vector<Rgb> a = colours("sigma_a"), s = colours("sigma_s");
  if (a.empty() && s.empty())
    throw Error(m.loc, "rgbgrid medium needs \"rgb sigma_a\" or \"rgb sigma_s\" values");
  return std::make_shared<RgbGrid>(box.nx, box.ny, box.nz, a, s, scale, box.p0, box.p1,
                                   m.world_from_medium);
}

// The index of a named medium, -1 for "" (vacuum). Coefficients default to 1 per unit distance
// (times "scale"), g to 0; a preset names measured coefficients in mm^-1; Le (times one Lescale)
// is emitted where sigma_a absorbs. Other types, grids' and temperature's emission are refused.
int Flattener::medium_id(const std::string& name, const FileLoc& loc) {
  if (name.empty()) return -1;
  if (auto it = medium_ids_.find(name); it != medium_ids_.end()) return it->second;
  auto e = parsed_.media.find(name);
  if (e == parsed_.media.end()) throw Error(loc, "unknown medium \"" + name + "\"");
  const MediumEntity& m = e->second;
  const ParamSet& ps = m.params;
  auto unsupported = [&](const std::string& why) {
    return Error(loc, "medium \"" + name + "\" (defined at " + m.loc.str() +
                          ") is not supported: " + why +
                          "; homogeneous, uniformgrid and rgbgrid media are");
  };
  if (m.name == "nanovdb")
    throw unsupported("type \"nanovdb\" (no NanoVDB reader is packaged with Debian's OpenVDB)");
  if (m.name != "homogeneous" && m.name != "uniformgrid" && m.name != "rgbgrid")
    throw unsupported("type \"" + m.name + "\"");
  const float scale = ps.get_float("scale", 1);
  if (!(scale >= 0) || !std::isfinite(scale))
    throw Error(m.loc, "medium scale must be a non-negative number");
  // pbrt-v4 scales a grid's emission by a grid of its own (Lescale, one voxel when not given,
  // which then fades toward the box's corners): only homogeneous media emit here.
  if (m.name != "homogeneous" && ps.find_any("Le")) throw unsupported("it emits (Le)");
  if (ps.find_any("temperature")) throw unsupported("it emits (temperature)");
  std::optional<SpectrumCurve> Le;
  if (m.name == "homogeneous") Le = spectrum_curve(ps, "Le", SpectrumKind::kIlluminant);
  const std::vector<float> le_scale = ps.get_floats("Lescale");
  if (le_scale.size() > 1) throw unsupported("it emits by a grid of Lescale values");
  if (!le_scale.empty() && !(le_scale[0] >= 0))
    throw Error(ps.find_any("Lescale")->loc, "Lescale must not be negative");
  const float g = ps.get_float("g", 0);
  if (!(g > -1 && g < 1)) throw Error(ps.find_any("g")->loc, "g must lie in (-1, 1)");
  Medium medium{name, SpectrumCurve(1.0f), SpectrumCurve(1.0f), g, nullptr, nullptr, {}};
  if (m.name == "rgbgrid") {
    medium.rgb_grid = rgb_grid(m, scale);
    ps.warn_unused("medium \"" + name + "\"");
    scene().media.push_back(std::move(medium));
    return medium_ids_[name] = int(scene().media.size()) - 1;
  }
  std::optional<SpectrumCurve> sigma_a, sigma_s;
  const std::string preset = m.name == "homogeneous" ? ps.get_string("preset", "") : "";
  if (!preset.empty()) {
    Rgb s, a;
    if (!medium_preset(preset, &s, &a))
      throw Error(ps.find_any("preset")->loc,
                  "unknown medium preset \"" + preset + "\"; known: " + medium_preset_names());
    sigma_a = SpectrumCurve::from_rgb(a, SpectrumKind::kUnbounded);
    sigma_s = SpectrumCurve::from_rgb(s, SpectrumKind::kUnbounded);
  } else {
    sigma_a = spectrum_curve(ps, "sigma_a", SpectrumKind::kUnbounded);
    sigma_s = spectrum_curve(ps, "sigma_s", SpectrumKind::kUnbounded);
  }
  if (sigma_a) medium.sigma_a = *sigma_a;
  if (sigma_s) medium.sigma_s = *sigma_s;
  if (!(medium.sigma_a.min_value() >= 0)) throw Error(m.loc, "sigma_a must not be negative");
  if (!(medium.sigma_s.min_value() >= 0)) throw Error(m.loc, "sigma_s must not be negative");
  medium.sigma_a = medium.sigma_a.scaled(scale);
  medium.sigma_s = medium.sigma_s.scaled(scale);
  if (m.name == "uniformgrid") medium.grid = density_grid(m);
  if (Le && !Le->is_black()) medium.Le = Le->scaled(le_scale.empty() ? 1.0f : le_scale[0]);
  ps.warn_unused("medium \"" + name + "\"");
  scene().media.push_back(std::move(medium));
  return medium_ids_[name] = int(scene().media.size()) - 1;
}

}  // namespace bpm::flatten_internal
