// Bump and normal maps against closed forms: a diffuse square under a distant light straight above,
// its shading normal tilted by alpha, shows L = rho E cos(alpha) / pi, in every integrator.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "base/error.h"
#include "test_util.h"

namespace bpm {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;

// Writes a float image (PFM, rows from the bottom as that format keeps them) of w x h texels,
// rgb(x, y) per texel with y from the top.
template <class F>
std::string write_pfm(const std::string& name, int w, int h, F&& rgb) {
  const fs::path dir = fs::temp_directory_path() / ("bpm_bump_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path path = dir / name;
  std::ofstream out(path, std::ios::binary);
  out << "PF\n" << w << " " << h << "\n-1.0\n";
  for (int y = h - 1; y >= 0; --y)
    for (int x = 0; x < w; ++x) {
      const Vec3 c = rgb(x, y);
      const float v[3] = {c.x, c.y, c.z};
      out.write(reinterpret_cast<const char*>(v), sizeof v);
    }
  return path.string();
}

// A camera straight above a square of reflectance 0.5 (uv 0..1 over 2 x 2, dp/du = (2, 0, 0)),
// a distant light of 1000 lux straight down; `material` the square's Material line.
std::string square_scene(const std::string& integrator, const std::string& material) {
  return R"(LookAt 0 0 3  0 0 0  0 1 0
Camera "perspective" "float fov" 10
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
PixelFilter "box"
Integrator ")" +
         integrator +
         R"(" "integer maxdepth" 1
WorldBegin
LightSource "distant" "point3 from" [0 0 1] "point3 to" [0 0 0] "float illuminance" 1000
)" + material +
         R"(
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]  "point2 uv" [0 0  1 0  1 1  0 1]
)";
}

// The mean luminance of the image and its standard error (the mean of the pixels', an upper bound
// whatever their correlation).
void expect_luminance(const std::string& scene, const std::string& integrator, double expected) {
  LoadedScene ls = test::load(scene);
  Film film(ls.film.width, ls.film.height, Film::kStreams);
  render(ls, quiet_options(ls, integrator, 16, 3), &film);
  const std::vector<float> y = film.luminance_image(), e = film.total_rms_luminance();
  double mean = 0, error = 0;
  for (size_t i = 0; i < y.size(); ++i) {
    mean += y[i] / double(y.size());
    error += e[i] / double(y.size());
  }
  EXPECT_NEAR(mean, expected, 3 * error + 1e-3 * expected) << integrator;
}

constexpr double kAlpha = 30 * kPi / 180;

// A displacement rising linearly along u, d = a u with a = 2 tan(alpha) (an image ramp, read
// bilinearly between texel centres): dp'/du = (2, 0, a), so the normal tilts by alpha.
TEST(Bump, LinearDisplacementTiltsTheNormal) {
  constexpr int kW = 256;
  const double a = 2 * std::tan(kAlpha);
  const std::string ramp = write_pfm("ramp.pfm", kW, 1, [&](int x, int) {
    const float v = float(a * (x + 0.5) / kW);
    return Vec3(v, v, v);
  });
  const std::string material =
      "Texture \"d\" \"float\" \"imagemap\" \"string filename\" \"" + ramp +
      "\"\nMaterial \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5] \"texture displacement\" \"d\"";
  for (const char* integrator : {"path", "bpm", "fpm"})
    expect_luminance(square_scene(integrator, material), integrator,
                     0.5 * 1000 * std::cos(kAlpha) / kPi);
  // Without the bump the square is lit head-on.
  for (const char* integrator : {"path", "bpm"})
    expect_luminance(
        square_scene(integrator, "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]"),
        integrator, 0.5 * 1000 / kPi);
}

// A normal map of one texel, the tangent-space normal (sin alpha, 0, cos alpha) as 2 rgb - 1.
TEST(Bump, NormalMapTiltsTheNormal) {
  const std::string map = write_pfm("normal.pfm", 1, 1, [&](int, int) {
    return Vec3(float(0.5 + 0.5 * std::sin(kAlpha)), 0.5f, float(0.5 + 0.5 * std::cos(kAlpha)));
  });
  const std::string material =
      "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5] "
      "\"string normalmap\" \"" +
      map + "\"";
  for (const char* integrator : {"path", "bpm", "fpm"})
    expect_luminance(square_scene(integrator, material), integrator,
                     0.5 * 1000 * std::cos(kAlpha) / kPi);
}

// A normal map that is not an image or is not named, and a bump inside a mix, are located errors.
TEST(Bump, BadMapsAreLocatedErrors) {
  const fs::path dir = fs::temp_directory_path() / ("bpm_bump_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "text.png") << "not an image";
  auto error_of = [](const std::string& material) {
    try {
      test::load(square_scene("path", material));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  std::string e =
      error_of("Material \"diffuse\" \"string normalmap\" \"" + (dir / "text.png").string() + "\"");
  EXPECT_NE(e.find("normalmap"), std::string::npos) << e;
  EXPECT_NE(e.find(":8:"), std::string::npos) << e;
  EXPECT_NE(e.find("text.png"), std::string::npos) << e;
  e = error_of("Material \"diffuse\" \"string normalmap\" \"\"");
  EXPECT_NE(e.find("must name an image"), std::string::npos) << e;
  e = error_of(
      "MakeNamedMaterial \"a\" \"string type\" \"diffuse\" \"float displacement\" 0.1\n"
      "MakeNamedMaterial \"b\" \"string type\" \"diffuse\"\n"
      "Material \"mix\" \"string materials\" [\"a\" \"b\"]");
  EXPECT_NE(e.find("inside a mix"), std::string::npos) << e;
}

}  // namespace
}  // namespace bpm

namespace bpm {
namespace {

// A dielectric's roughness from a float texture (a "scale" texture of constant 0.2: a node
// evaluated per surface point) renders as the constant roughness 0.2 does, in path and bpm.
TEST(TexturedRoughness, DielectricTextureOfAConstantRendersAsTheConstant) {
  auto image = [](const std::string& integrator, const std::string& rough) {
    const LoadedScene ls = test::load(R"(LookAt 0 2 -3  0 0 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 16 "integer yresolution" 12
Integrator ")" + integrator + R"(" "integer maxdepth" 6
WorldBegin
LightSource "point" "point3 from" [0 3 0] "rgb I" [8 8 8]
Texture "r" "float" "scale" "float tex" 0.2 "float scale" 1
Material "dielectric" )" + rough + R"(
Shape "sphere" "float radius" 0.6
Material "diffuse"
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point3 P" [-3 -0.6 -3  3 -0.6 -3  3 -0.6 3  -3 -0.6 3]
)");
    return test::render_film(ls, 8, 0, 2).image();
  };
  for (const char* integrator : {"path", "bpm"}) {
    const Image a = image(integrator, "\"float roughness\" 0.2");
    const Image b = image(integrator, "\"texture roughness\" \"r\"");
    double diff = 0, sum = 0;
    for (size_t i = 0; i < a.rgb.size(); ++i) {
      diff += std::fabs(a.rgb[i] - b.rgb[i]);
      sum += std::fabs(a.rgb[i]);
    }
    EXPECT_LT(diff, 1e-4 * sum) << integrator;
  }
}

}  // namespace
}  // namespace bpm
