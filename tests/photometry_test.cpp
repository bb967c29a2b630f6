// Photometry in absolute units: the luminance channel Y (cd/m^2) of every integrator against
// closed forms, with lights stated in pbrt-v4's photometric terms (a light's "power" in lumens,
// "illuminance" in lux, emission spectra normalised to unit luminance). Each case compares the
// mean of Y over the image with its expected value within three of the film's own standard errors
// (taken as fully correlated between pixels, since the photon methods share an iteration's
// wavelengths and photons), plus 1e-3 for the spectral fit of a white reflectance.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "test_util.h"

namespace bpm {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Measured {
  double mean = 0, expected = 0, error = 0;  // error: the mean of the per-pixel standard errors
};

// Renders the scene with the integrator and compares Y with expected(x, y) at each pixel's centre
// (x, y in [-1, 1] across the image).
Measured measure(const std::string& scene, const std::string& integrator, int passes,
                 const std::function<double(double, double)>& expected) {
  LoadedScene ls = test::load(scene);
  Film film(ls.film.width, ls.film.height);
  RenderOptions opt = quiet_options(ls, integrator, passes, 7);
  render(ls, opt, &film);
  const std::vector<float> y = film.luminance_image(), rms = film.rms();
  Measured m;
  const int w = film.width(), h = film.height();
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const size_t p = size_t(j) * w + i;
      m.mean += y[p];
      m.error += rms[p];
      m.expected += expected(-1 + (2 * i + 1.0) / w, -1 + (2 * j + 1.0) / h);
    }
  const double n = double(w) * h;
  m.mean /= n;
  m.error /= n;
  m.expected /= n;
  return m;
}

void expect_agrees(const Measured& m, const std::string& what) {
  EXPECT_NEAR(m.mean, m.expected, 3 * m.error + 1e-3 * m.expected)
      << what << ": Y " << m.mean << " cd/m^2 against " << m.expected << " (standard error "
      << m.error << ")";
}

// A camera straight above a white plane at height 1.5, looking down with a field of view of 2
// degrees; the light of `light` above the plane's centre.
std::string plane_scene(const std::string& integrator, const std::string& light,
                        const std::string& reflectance) {
  return R"(LookAt 0 0 1.5  0 0 0  0 1 0
Camera "perspective" "float fov" 2
Film "rgb" "integer xresolution" 12 "integer yresolution" 12
PixelFilter "box"
Integrator ")" +
         integrator +
         R"(" "integer maxdepth" 1
WorldBegin
)" + light +
         "\nMaterial \"diffuse\" \"rgb reflectance\" [" + reflectance + "]\n" +
         R"(Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [-10 -10 0  10 -10 0  10 10 0  -10 10 0]
)";
}

// Half the side of the plane's patch the camera sees.
const double kHalf = 1.5 * std::tan(1.0 * kPi / 180);

// A point light of 1000 lm at 1 m above a white plane: E = I cos(theta) / r^2 with I = 1000 /
// (4 pi) cd, and L = rho E / pi.
TEST(Photometry, PointLightOverAPlane) {
  const double intensity = 1000 / (4 * kPi);
  auto expected = [&](double x, double y) {
    const double r2 = 1 + kHalf * kHalf * (x * x + y * y);
    return intensity / std::pow(r2, 1.5) / kPi;
  };
  for (const char* integrator : {"path", "bpm", "fpm"}) {
    const std::string scene = plane_scene(
        integrator, R"(LightSource "point" "point3 from" [0 0 1] "float power" 1000)", "1 1 1");
    expect_agrees(measure(scene, integrator, 32, expected), integrator);
  }
}

// A distant light of 1000 lux falling straight onto a plane of reflectance 0.5: L = 0.5 E / pi,
// whatever the light's spectrum (here a 3000 K blackbody).
TEST(Photometry, DistantLightIlluminance) {
  auto expected = [](double, double) { return 0.5 * 1000 / kPi; };
  for (const char* integrator : {"path", "bpm"}) {
    const std::string scene = plane_scene(
        integrator,
        R"(LightSource "distant" "point3 from" [0 0 1] "point3 to" [0 0 0] "blackbody L" 3000 "float illuminance" 1000)",
        "0.5 0.5 0.5");
    expect_agrees(measure(scene, integrator, 16, expected), integrator);
  }
}

// An emitter seen directly: a blackbody spectrum is normalised to unit luminance before "scale",
// so "scale" 3 is 3 cd/m^2; an RGB emission's luminance is the sRGB luminance of the RGB.
TEST(Photometry, EmitterSeenDirectly) {
  auto emitter = [](const std::string& L) {
    return R"(LookAt 0 0 1  0 0 0  0 1 0
Camera "perspective" "float fov" 10
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
Integrator "path" "integer maxdepth" 1
WorldBegin
AreaLightSource "diffuse" )" +
           L + R"(
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]
)";
  };
  expect_agrees(measure(emitter(R"("blackbody L" 5000 "float scale" 3)"), "path", 16,
                        [](double, double) { return 3.0; }),
                "blackbody");
  const double rgb_luminance = 0.2126 * 1 + 0.7152 * 0.5 + 0.0722 * 0.25;
  expect_agrees(measure(emitter(R"("rgb L" [1 0.5 0.25])"), "path", 16,
                        [&](double, double) { return rgb_luminance; }),
                "rgb");
}

// The luminance and the image agree: for grey light, Y equals the sRGB luminance of R, G, B
// (the film's imaging ratio aside).
TEST(Photometry, LuminanceMatchesTheColoursLuminance) {
  LoadedScene ls = test::load(plane_scene(
      "path", R"(LightSource "point" "point3 from" [0 0 1] "float power" 1000)", "0.6 0.6 0.6"));
  Film film = test::render_film(ls, 16);
  const Image img = film.image();
  const std::vector<float> y = film.luminance_image();
  double from_rgb = 0, direct = 0;
  for (size_t p = 0; p < y.size(); ++p) {
    const Rgb c = img.at(int(p % img.width), int(p / img.width));
    from_rgb += 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    direct += y[p];
  }
  EXPECT_NEAR(direct / from_rgb, 1, 5e-3);
}

}  // namespace
}  // namespace bpm
