// The realistic camera's lens: its lens file, aperture stop and diaphragm shape, with pbrt-v4's
// parameters and defaults (pbrt-v4's cameras.cpp, RealisticCamera::Create).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "scene/flatten_internal.h"
#include "textures/texture.h"

namespace bpm::flatten_internal {
namespace {

std::string number(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", double(v));
  return buf;
}

namespace fs = std::filesystem;

// Real lens systems have a few dozen interfaces; each camera ray crosses them all.
constexpr size_t kMaxInterfaces = 100;

fs::path scene_path(const std::string& dir, const std::string& file) {
  return fs::path(file).is_absolute() ? fs::path(file) : fs::path(dir) / file;
}

// A lens file: four numbers per element (curvature radius, thickness, index of refraction,
// aperture diameter; lengths in mm), front to rear; '#' starts a comment. pbrt-v4 reads the
// numbers regardless of lines; a count that is not a multiple of four is reported at the first
// line that does not hold four.
std::vector<LensInterface> read_lens_file(const std::string& path, const std::string& shown) {
  std::ifstream in(path);
  if (!in) throw Error("lens file \"" + shown + "\" cannot be read");
  std::vector<float> values;
  int first_odd_line = 0, line_number = 0;
  std::string line;
  while (std::getline(in, line)) {
    ++line_number;
    if (auto h = line.find('#'); h != std::string::npos) line.resize(h);
    std::istringstream ls(line);
    size_t before = values.size();
    double v;
    while (ls >> v) values.push_back(float(v));
    if (!ls.eof()) throw Error(FileLoc{shown, line_number, 1}, "a lens file holds numbers only");
    const size_t n = values.size() - before;
    if (n != 0 && n != 4 && first_odd_line == 0) first_odd_line = line_number;
  }
  if (values.empty()) throw Error(FileLoc{shown, 1, 1}, "the lens file holds no element");
  if (values.size() > 4 * kMaxInterfaces)
    throw Error(FileLoc{shown, 1, 1}, "the lens file holds " + std::to_string(values.size() / 4) +
                                          " elements; at most " + std::to_string(kMaxInterfaces) +
                                          " are read");
  if (values.size() % 4 != 0)
    throw Error(FileLoc{shown, first_odd_line, 1},
                "a lens element takes 4 values (curvature radius, thickness, index of "
                "refraction, aperture diameter); the file holds " +
                    std::to_string(values.size()) + ", not a multiple of 4");
  std::vector<LensInterface> out;
  for (size_t i = 0; i < values.size(); i += 4) {
    for (size_t k = i; k < i + 4; ++k)
      if (!std::isfinite(values[k]))
        throw Error("lens file \"" + shown + "\": element " + std::to_string(i / 4 + 1) +
                    " has a value that is not finite");
    LensInterface e{values[i] / 1000, values[i + 1] / 1000, values[i + 2], values[i + 3] / 2000};
    const std::string which = "lens file \"" + shown + "\": element " + std::to_string(i / 4 + 1);
    if (!(e.thickness >= 0)) throw Error(which + " has a negative thickness");
    if (!(e.eta >= 0)) throw Error(which + " has a negative index of refraction");
    if (!(e.aperture_radius > 0)) throw Error(which + " has no aperture (diameter <= 0)");
    if (!e.is_stop() && std::fabs(e.curvature_radius) < e.aperture_radius)
      throw Error(which + "'s aperture is wider than its sphere");
    out.push_back(e);
  }
  return out;
}

// Whether p lies inside the polygon (nonzero winding).
bool inside_polygon(const std::vector<Vec2>& poly, Vec2 p) {
  int winding = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vec2 a = poly[i], b = poly[(i + 1) % poly.size()];
    const float side = (b.x - a.x) * (p.y - a.y) - (p.x - a.x) * (b.y - a.y);
    if (a.y <= p.y && b.y > p.y && side > 0) ++winding;
    if (a.y > p.y && b.y <= p.y && side < 0) --winding;
  }
  return winding != 0;
}

// pbrt-v4's built-in diaphragms, 256 x 256 over [-1, 1]^2; null when `name` names none. As
// pbrt-v4 flips every aperture image upside down, a shape's +y lies toward the stop's -y.
std::optional<ApertureMask> builtin_aperture(const std::string& name) {
  std::vector<Vec2> poly;
  if (name == "pentagon") {
    const float c1 = (std::sqrt(5.0f) - 1) / 4, c2 = (std::sqrt(5.0f) + 1) / 4;
    const float s1 = std::sqrt(10 + 2 * std::sqrt(5.0f)) / 4,
                s2 = std::sqrt(10 - 2 * std::sqrt(5.0f)) / 4;
    poly = {{0, 1}, {s1, c1}, {s2, -c2}, {-s2, -c2}, {-s1, c1}};
    for (Vec2& v : poly) v = v * 0.8f;
  } else if (name == "star") {
    const float inner = std::cos(radians(72)) / std::cos(radians(36));
    for (int i = 0; i < 10; ++i) {
      const float r = (i & 1) ? 1 : inner, a = kPi * float(i) / 5;
      poly.push_back({r * std::cos(a), r * std::sin(a)});
    }
  } else if (name != "gaussian" && name != "square") {
    return std::nullopt;
  }
  const int n = 256;
  ApertureMask m{n, n, std::vector<float>(size_t(n) * n)};
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const Vec2 p{-1 + 2 * (float(i) + 0.5f) / n, 1 - 2 * (float(j) + 0.5f) / n};
      float v;
      if (name == "gaussian")
        v = std::max(0.0f, std::exp(-(p.x * p.x + p.y * p.y)) - std::exp(-1.0f));
      else if (name == "square")
        v = std::fabs(p.x) < 0.5f && std::fabs(p.y) < 0.5f ? 1 : 0;
      else
        v = inside_polygon(poly, p) ? 1 : 0;
      m.values[size_t(j) * n + size_t(i)] = v;
    }
  return m;
}

// An aperture image: the mean of its colour channels, bottom row first.
ApertureMask image_aperture(const std::string& path) {
  const auto img = read_texture_image(path, TexEncoding{});
  ApertureMask m{img->width, img->height, std::vector<float>(size_t(img->width) * img->height)};
  for (int j = 0; j < img->height; ++j)
    for (int i = 0; i < img->width; ++i) {
      const Rgb c = img->texel(i, img->height - 1 - j, TexWrap::kClamp);
      m.values[size_t(j) * size_t(img->width) + size_t(i)] = c.average();
    }
  return m;
}

}  // namespace

void Flattener::read_lens(const CameraEntity& c) {
  const ParamSet& ps = c.params;
  const std::string file = ps.get_string("lensfile", "");
  if (file.empty())
    throw Error(c.loc, "a realistic camera needs a \"lensfile\" (pbrt-v4's lens description)");
  const fs::path path = scene_path(parsed_.base_directory, file);
  read_data_file(path.string());
  LensSettings s;
  try {
    s.interfaces = read_lens_file(path.string(), file);
  } catch (const Error& e) {
    if (!e.loc().file.empty()) throw;
    throw Error(ps.find_any("lensfile")->loc, e.what());
  }
  const float diameter = ps.get_float("aperturediameter", 1.0f) / 1000;
  if (!(diameter > 0))
    throw Error(ps.find_any("aperturediameter")->loc, "aperturediameter must be positive");
  for (LensInterface& e : s.interfaces) {
    if (!e.is_stop()) continue;
    if (diameter / 2 > e.aperture_radius)
      warning(ps.find_any("aperturediameter")->loc, "aperturediameter " + number(diameter * 1000) +
                                                        " mm is wider than the lens's stop (" +
                                                        number(e.aperture_radius * 2000) +
                                                        " mm); the stop's is used");
    else
      e.aperture_radius = diameter / 2;
  }
  s.focus_distance = ps.get_float("focusdistance", 10);
  if (!(s.focus_distance > 0) || !std::isfinite(s.focus_distance))
    throw Error(ps.find_any("focusdistance")->loc, "focusdistance must be positive and finite");
  s.film_diagonal = parsed_.film.params.get_float("diagonal", 35) / 1000;
  if (!(s.film_diagonal > 0))
    throw Error(parsed_.film.params.find_any("diagonal")->loc, "diagonal must be positive");
  const std::string aperture = ps.get_string("aperture", "");
  if (!aperture.empty()) {
    if (auto builtin = builtin_aperture(aperture)) {
      s.aperture = std::move(*builtin);
    } else {
      const fs::path image = scene_path(parsed_.base_directory, aperture);
      try {
        s.aperture = image_aperture(image.string());
      } catch (const Error& e) {
        throw Error(ps.find_any("aperture")->loc,
                    "aperture \"" + aperture +
                        "\" is neither a built-in shape (gaussian, square, pentagon, star) nor "
                        "a readable image: " +
                        e.what());
      }
      read_data_file(image.string());
    }
    double sum = 0;
    for (float v : s.aperture.values) sum += v;
    if (!(sum > 0) || !std::isfinite(sum))
      throw Error(ps.find_any("aperture")->loc, "aperture \"" + aperture + "\" is all black");
    const float scale = float((kPi / 4) / (sum / double(s.aperture.values.size())));
    for (float& v : s.aperture.values) v = std::max(0.0f, v * scale);
  }
  lens_ = std::move(s);
  lens_loc_ = c.loc;
}

void Flattener::build_lens(LoadedScene* out) {
  if (!lens_) return;
  try {
    out->camera.lens = std::make_shared<const LensSystem>(std::move(*lens_), out->film.full_width,
                                                          out->film.full_height);
  } catch (const Error& e) {
    throw Error(lens_loc_, e.what());
  }
}

}  // namespace bpm::flatten_internal
