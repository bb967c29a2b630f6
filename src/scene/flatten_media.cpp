// The media shapes, lights and the camera refer to: pbrt-v4's "homogeneous" (with its named
// presets), "uniformgrid", "rgbgrid" and "cloud" media (scene/medium.h).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "base/noise.h"
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

float cloud_density(Vec3 p, float density, float wispiness, float frequency) {
  Vec3 q = p * frequency;
  float step = 0.05f * wispiness, scale = 10;
  for (int i = 0; i < 2 && wispiness > 0; ++i) {  // wisps: q pushed along the noise's slope
    q += perlin_noise_slope(q * scale) * step;
    step *= 0.5f;
    scale *= 1.99f;
  }
  float d = 0, weight = 0.5f;
  scale = 1;
  for (int i = 0; i < 5; ++i) {  // five octaves
    d += weight * perlin_noise(q * scale);
    weight *= 0.5f;
    scale *= 1.99f;
  }
  d = std::clamp((1 - p.y) * 4.5f * density * d, 0.0f, 1.0f);  // thinner with height
  d += 2 * std::max(0.0f, 0.5f - p.y);                         // a solid base below y = 0.5
  return std::clamp(d, 0.0f, 1.0f);
}

// pbrt-v4's "cloud": cloud_density on the box [p0, p1] of the medium's space, 0 outside (media.h,
// CloudMedium). Our media take exact optical depths, which a procedural density does not give, so
// the density is tabulated on a grid of the uniformgrid kind: kCloudSamplesPerCycle samples per
// unit of the noise's base frequency along each axis (at most kMaxCloudSamples), the first and
// last on the box's faces, interpolated between them. The three coarsest octaves (nine tenths of
// the noise's amplitude) are resolved with 8 to 32 samples per period; the two finest, and the
// wisps, are smoothed. The grid's own box reaches half a sample spacing past [p0, p1], where its
// density falls to 0 (pbrt-v4's is 0 at once: this matters only where the medium's shape is
// larger than the cloud's box).
std::shared_ptr<const DensityGrid> Flattener::cloud_grid(const MediumEntity& m) {
  constexpr float kCloudSamplesPerCycle = 32;
  constexpr int kMaxCloudSamples = 256;
  // At most about 4 million samples in all (the default cloud's 160^3; 16 MB, 2 s to read on 2
  // cores): a finer request is coarsened evenly. Under the fuzzer, whose hang timeout the
  // sanitizers' slowness would reach, far fewer.
#ifdef BPM_FUZZING
  constexpr double kMaxCloudSamplesInAll = 1 << 15;
#else
  constexpr double kMaxCloudSamplesInAll = 1 << 22;
#endif
  const ParamSet& ps = m.params;
  const float density = ps.get_float("density", 1), wispiness = ps.get_float("wispiness", 1),
              frequency = ps.get_float("frequency", 5);
  ps.require("density", density >= 0 && std::isfinite(density), "must not be negative", m.loc);
  ps.require("wispiness", wispiness >= 0 && std::isfinite(wispiness), "must not be negative",
             m.loc);
  ps.require("frequency", frequency > 0 && frequency <= 1e4f, "must lie in (0, 1e4]", m.loc);
  const Vec3 p0 = ps.get_point3("p0", {0, 0, 0}), p1 = ps.get_point3("p1", {1, 1, 1});
  ps.require("p1", p1.x > p0.x && p1.y > p0.y && p1.z > p0.z,
             "must exceed p0 along every axis (the cloud's box)", m.loc);
  const Vec3 extent = p1 - p0;
  double want[3];
  for (int a = 0; a < 3; ++a)
    want[a] = std::clamp(std::ceil(double(extent[a]) * frequency * kCloudSamplesPerCycle), 2.0,
                         double(kMaxCloudSamples));
  const double coarsen =
      std::min(1.0, std::cbrt(kMaxCloudSamplesInAll / (want[0] * want[1] * want[2])));
  int n[3];
  for (int a = 0; a < 3; ++a) n[a] = int(std::max(2.0, std::floor(want[a] * coarsen)));
  const Vec3 spacing(extent.x / float(n[0] - 1), extent.y / float(n[1] - 1),
                     extent.z / float(n[2] - 1));
  std::vector<float> values(size_t(n[0]) * size_t(n[1]) * size_t(n[2]));
  tbb::parallel_for(0, n[2], [&](int k) {
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const Vec3 p = p0 + Vec3(float(i) * spacing.x, float(j) * spacing.y, float(k) * spacing.z);
        values[(size_t(k) * size_t(n[1]) + size_t(j)) * size_t(n[0]) + size_t(i)] =
            cloud_density(p, density, wispiness, frequency);
      }
  });
  return std::make_shared<DensityGrid>(n[0], n[1], n[2], std::move(values), p0 - spacing * 0.5f,
                                       p1 + spacing * 0.5f, m.world_from_medium);
}

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

// A glowing uniformgrid's "Lescale": nx x ny x nz non-negative values on the density's box, or
// when not given pbrt-v4's one voxel of 1 (media.cpp, GridMedium::Create), which interpolated as
// the grid's samples are fades from 1 at the box's centre to 1/8 at its corners.
std::shared_ptr<const DensityGrid> Flattener::le_scale_grid(const MediumEntity& m) {
  const ParamSet& ps = m.params;
  const GridBox box = grid_box(m);
  const Param* given = ps.find("Lescale", "float");
  if (!given)
    return std::make_shared<DensityGrid>(1, 1, 1, std::vector<float>{1.0f}, box.p0, box.p1,
                                         m.world_from_medium);
  std::vector<float> values = ps.get_floats("Lescale");
  if (values.size() != box.count())
    throw Error(given->loc, "uniformgrid has " + std::to_string(values.size()) +
                                " Lescale values; nx * ny * nz = " + std::to_string(box.count()));
  for (float v : values)
    if (!(v >= 0) || !std::isfinite(v)) throw Error(given->loc, "Lescale must not be negative");
  return std::make_shared<DensityGrid>(box.nx, box.ny, box.nz, std::move(values), box.p0, box.p1,
                                       m.world_from_medium);
}

// A uniformgrid's glow by temperature (pbrt-v4's GridMedium::Create): nx x ny x nz kelvin values
// on the density's box, then (T - "temperatureoffset") * "temperaturescale" (the offset read
// from "temperaturecutoff" when only that is given). Le beside it is an error, as in pbrt-v4.
void Flattener::read_temperature(const MediumEntity& m, Medium* medium) {
  const ParamSet& ps = m.params;
  const Param* given = ps.find("temperature", "float");
  if (!given) return;
  if (const Param* le = ps.find_any("Le"))
    throw Error(le->loc, "a medium glows by \"Le\" or by \"temperature\", not both");
  const GridBox box = grid_box(m);
  std::vector<float> values = ps.get_floats("temperature");
  if (values.size() != box.count())
    throw Error(given->loc,
                "uniformgrid has " + std::to_string(values.size()) +
                    " temperature values; nx * ny * nz = " + std::to_string(box.count()));
  for (float v : values)
    if (!(v >= 0) || !std::isfinite(v))
      throw Error(given->loc, "temperature values must be non-negative (kelvin)");
  const float offset = ps.get_float("temperatureoffset", ps.get_float("temperaturecutoff", 0));
  const float scale = ps.get_float("temperaturescale", 1);
  if (!std::isfinite(offset) || !(scale >= 0) || !std::isfinite(scale))
    throw Error(m.loc, "temperatureoffset must be finite and temperaturescale non-negative");
  medium->temperature = std::make_shared<DensityGrid>(box.nx, box.ny, box.nz, std::move(values),
                                                      box.p0, box.p1, m.world_from_medium);
  medium->temperature_offset = offset;
  medium->temperature_scale = scale;
}

// pbrt-v4's "rgbgrid": per voxel "rgb sigma_a" and "rgb sigma_s" colours (either may be absent:
// 1 everywhere), nx x ny x nz of each, on the box [p0, p1], times "scale", and per voxel "rgb Le"
// colours times one "Lescale" (media.cpp, RGBGridMedium::Create).
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
  const std::vector<Rgb> a = colours("sigma_a"), s = colours("sigma_s"), Le = colours("Le");
  if (a.empty() && s.empty())
    throw Error(m.loc, "rgbgrid medium needs \"rgb sigma_a\" or \"rgb sigma_s\" values");
  if (!Le.empty() && a.empty())
    throw Error(ps.find_any("Le")->loc, "an rgbgrid that glows (\"rgb Le\") needs \"rgb sigma_a\"");
  auto grid = std::make_shared<RgbGrid>(box.nx, box.ny, box.nz, a, s, scale, box.p0, box.p1,
                                        m.world_from_medium);
  if (!Le.empty()) grid->set_glow(Le, ps.get_float("Lescale", 1));
  return grid;
}

// The index of a named medium, -1 for "" (vacuum). Coefficients default to 1 per unit distance
// (times "scale"), g to 0; a preset names measured coefficients in mm^-1; Le (times one Lescale)
// is emitted where sigma_a absorbs (a uniformgrid's times its Lescale grid, or a blackbody by
// temperature instead; an rgbgrid's per voxel). Other types are refused.
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
                          "; homogeneous, uniformgrid, rgbgrid and cloud media are");
  };
  if (m.name == "nanovdb")
    throw unsupported("type \"nanovdb\" (no NanoVDB reader is packaged with Debian's OpenVDB)");
  if (m.name != "homogeneous" && m.name != "uniformgrid" && m.name != "rgbgrid" &&
      m.name != "cloud")
    throw unsupported("type \"" + m.name + "\"");
  // pbrt-v4's cloud has no "scale" (a scene's would be left unused).
  const float scale = m.name == "cloud" ? 1.0f : ps.get_float("scale", 1);
  if (!(scale >= 0) || !std::isfinite(scale))
    throw Error(m.loc, "medium scale must be a non-negative number");
  // Homogeneous and uniformgrid media glow by Le (uniformgrid: times a grid of Lescale values,
  // le_scale_grid), a uniformgrid by temperature in its place, an rgbgrid by a colour of Le per
  // voxel (rgb_grid); a cloud does not glow.
  if (m.name == "cloud" && ps.find_any("Le")) throw unsupported("it emits (Le)");
  std::optional<SpectrumCurve> Le;
  if (m.name == "homogeneous" || m.name == "uniformgrid")
    Le = spectrum_curve(ps, "Le", SpectrumKind::kIlluminant);
  const std::vector<float> le_scale =
      m.name == "uniformgrid" ? std::vector<float>{} : ps.get_floats("Lescale");
  if (le_scale.size() > 1) throw unsupported("it emits by a grid of Lescale values");
  if (!le_scale.empty() && !(le_scale[0] >= 0))
    throw Error(ps.find_any("Lescale")->loc, "Lescale must not be negative");
  const float g = ps.get_float("g", 0);
  if (!(g > -1 && g < 1)) throw Error(ps.find_any("g")->loc, "g must lie in (-1, 1)");
  Medium medium;
  medium.name = name;
  medium.sigma_a = medium.sigma_s = SpectrumCurve(1.0f);
  medium.g = g;
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
  if (m.name == "cloud") medium.grid = cloud_grid(m);
  if (m.name == "uniformgrid") read_temperature(m, &medium);
  if (m.name == "uniformgrid" && ((Le && !Le->is_black()) || medium.temperature))
    medium.le_scale = le_scale_grid(m);
  if (Le && !Le->is_black()) medium.Le = Le->scaled(le_scale.empty() ? 1.0f : le_scale[0]);
  ps.warn_unused("medium \"" + name + "\"");
  scene().media.push_back(std::move(medium));
  return medium_ids_[name] = int(scene().media.size()) - 1;
}

}  // namespace bpm::flatten_internal
