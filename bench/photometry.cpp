// Photometry against closed forms, in absolute units. First, for each case and integrator, the
// value expected, the mean over several seeds of what the render reports (cd/m^2 of the luminance
// channel at the image's centre pixels, or lux at a sensor), the error it states (its standard
// error, and for the photon methods its bias estimate), the error it actually makes (the RMS over
// the seeds of value - expected) and their ratio. Then the sensor cases at equal time: each
// integrator renders the sensors alone (--no-image) for the same seconds, and the RMS errors are
// compared with path's in the same run. Prints figures; never fails.
//   photometry [--seeds N] [--passes N] [--seconds S] [--only TEXT]
// --seconds 0 leaves out the equal-time table; --only keeps the cases whose name holds TEXT.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>

#include "integrator/sensors.h"
#include "render/renderer.h"
#include "scene/flatten.h"
#include "scene/parsed_scene.h"

using namespace bpm;

namespace {

constexpr double kPi = 3.14159265358979323846;

// One render's reading and the error it states.
struct Reading {
  double value = 0, stated = 0;
};

// The luminance of each of the image's central 2 x 2 pixels (a camera looking straight down at a
// point), and the error stated there (standard error, and for the photon methods the bias
// estimate). Read one by one, not averaged: the photon methods' pixels share their iterations'
// wavelengths, so their errors are not independent.
std::vector<Reading> centre_luminance(const Film& film) {
  const int w = film.width(), h = film.height();
  const std::vector<float> y = film.luminance_image(), total = film.total_rms_luminance();
  std::vector<Reading> r;
  for (int j = h / 2 - 1; j <= h / 2; ++j)
    for (int i = w / 2 - 1; i <= w / 2; ++i)
      r.push_back({y[size_t(j) * w + i], total[size_t(j) * w + i]});
  return r;
}

// The plane cases' camera: 1.5 over the plane, a field of view of 0.5 degrees over 8 pixels. A
// central pixel covers [0, s] x [0, s] of the plane (one quadrant about the axis), and reads the
// mean of the luminance over it: for a point source of intensity I at height 1 over a plane of
// reflectance 1, L = I / (pi (1 + x^2 + y^2)^1.5) (midpoint rule, 64 x 64).
double point_plane_pixel(double intensity) {
  const double s = 2 * 1.5 * std::tan(0.25 * kPi / 180) / 8;
  constexpr int kN = 64;
  double sum = 0;
  for (int a = 0; a < kN; ++a)
    for (int b = 0; b < kN; ++b) {
      const double x = (a + 0.5) * s / kN, y = (b + 0.5) * s / kN;
      sum += intensity / (kPi * std::pow(1 + x * x + y * y, 1.5));
    }
  return sum / (kN * kN);
}

struct Case {
  const char* name;
  std::string scene;
  std::vector<Sensor> sensors;  // empty: the luminance of the image's central pixels
  double expected;
};

std::string plane(const std::string& light, const char* reflectance) {
  return R"(LookAt 0 0 1.5  0 0 0  0 1 0
Camera "perspective" "float fov" 0.5
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
PixelFilter "box"
Integrator "path" "integer maxdepth" 1
WorldBegin
)" + light +
         "\nMaterial \"diffuse\" \"rgb reflectance\" [" + reflectance + R"(]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [-10 -10 0  10 -10 0  10 10 0  -10 10 0]
)";
}

// A glass slab (eta 1.5, 0.1 thick, its top 1.1 over a black floor) under `light`: light from
// straight above crosses it with (1 - R)^2 of its power, or (1 - R)^2 R^2 after one reflection at
// each face (maxdepth 5 allows no more), R = ((eta - 1) / (eta + 1))^2; a point source at height
// h looks to a point of the floor straight below it as if at h - t + t / eta (paraxial, exact on
// the axis), or h - t + 3 t / eta after the reflections.
constexpr double kR = 0.04, kSlabT = (1 - kR) * (1 - kR);
std::string slab(const std::string& light) {
  // A film of ordinary size: the photon methods' sensor radii are backward photons' (pixel
  // footprints); only the sensors are rendered.
  return R"(LookAt 0 4 0.01  0 0 0  0 1 0
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 128 "integer yresolution" 128
Integrator "path" "integer maxdepth" 5
WorldBegin
)" + light +
         R"(
Material "diffuse" "rgb reflectance" [0 0 0]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [-5 0 -5  5 0 -5  5 0 5  -5 0 5]
Material "dielectric" "float eta" 1.5
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3  4 6 5 4 7 6  0 5 1 0 4 5  1 6 2 1 5 6
                                        2 7 3 2 6 7  3 4 0 3 7 4]
  "point3 P" [-5 1 -5  5 1 -5  5 1 5  -5 1 5  -5 1.1 -5  5 1.1 -5  5 1.1 5  -5 1.1 5]
)";
}

// Configuration factors of a point to a rectangle a x b: on a plane parallel to it at distance c,
// under one corner; on a perpendicular plane, c from the line where the planes meet, in front of
// one corner (heat transfer's catalogues; tests/sensors_test.cpp checks them by quadrature).
double parallel_factor(double a, double b, double c) {
  const double A = a / c, B = b / c, sa = std::sqrt(1 + A * A), sb = std::sqrt(1 + B * B);
  return (A / sa * std::atan(B / sa) + B / sb * std::atan(A / sb)) / (2 * kPi);
}
double perpendicular_factor(double a, double b, double c) {
  const double d = std::sqrt(c * c + b * b);
  return (std::atan(a / c) - c / d * std::atan(a / d)) / (2 * kPi);
}

// Two Lambertian rectangles of 100 cd/m^2, far apart: 1 x 2 at 1.5 over (0, 0, 0), and 1 x 2 in
// the plane x = 101.5, 1.5 from (100, -10, 0).
const char* const kRectangles = R"(LookAt 0.5 -3 1  0.5 1 1  0 0 1
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
Integrator "path" "integer maxdepth" 5
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "blackbody L" 5000 "float scale" 100 "bool twosided" true
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point3 P" [0 1.5 0  1 1.5 0  1 1.5 2  0 1.5 2]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point3 P" [101.5 -10 0  101.5 -10 1  101.5 -8 1  101.5 -8 0]
AttributeEnd
)";

std::vector<Case> cases() {
  const char* point = R"(LightSource "point" "point3 from" [0 0 1] "float power" 1000)";
  const std::string sphere = R"(LookAt 0 0 -0.5  0 0 1  0 1 0
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
Integrator "path" "integer maxdepth" 60
WorldBegin
LightSource "point" "point3 from" [0 0 0] "float power" 1000
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "sphere" "float radius" 1
)";
  const double area = 4 * kPi;
  return {
      {"point 1000 lm at 1 m, white plane: L = E / pi",
       plane(point, "1 1 1"),
       {},
       point_plane_pixel(1000 / (4 * kPi))},
      {"distant 1000 lx, plane of 0.5: L = 0.5 E / pi",
       plane(
           R"(LightSource "distant" "point3 from" [0 0 1] "point3 to" [0 0 0] "blackbody L" 3000 "float illuminance" 1000)",
           "0.5 0.5 0.5"),
       {},
       0.5 * 1000 / kPi},
      {"sensor 0.5 m off-axis under the point: E = I cos / d^2",
       plane(point, "0.5 0.5 0.5"),
       {{Vec3(0.5f, 0, 0), Vec3(0, 0, 1)}},
       1000 / (4 * kPi) / std::pow(1.25, 1.5)},
      {"integrating sphere, wall: E = Phi / (A (1 - rho))",
       sphere,
       {{Vec3(1, 0, 0), Vec3(-1, 0, 0)}},
       1000 / (area * 0.5)},
      {"integrating sphere, mid-air: E = rho Phi / (A (1 - rho))",
       sphere,
       {{Vec3(0, -0.6f, 0.3f), Vec3(0, -1, 0)}},
       0.5 * 1000 / (area * 0.5)},
      {"integrating sphere, 10 x 10 grid in mid-air facing down", sphere,
       parse_sensors("grid -0.6 -0.3 -0.6  1.2 0 0  0 0 1.2  10 10\n", "grid"),
       0.5 * 1000 / (area * 0.5)},
      {"Lambertian rectangle, parallel plane: E = pi L F",
       kRectangles,
       {{Vec3(0, 0, 0), Vec3(0, 1, 0)}},
       kPi * 100 * parallel_factor(1, 2, 1.5)},
      {"Lambertian rectangle, perpendicular plane: E = pi L F",
       kRectangles,
       {{Vec3(100, -10, 0), Vec3(0, 1, 0)}},
       kPi * 100 * perpendicular_factor(1, 2, 1.5)},
      {"distant 1000 lx through glass slab: E (1-R)^2 (1+R^2)",
       slab(
           R"(LightSource "distant" "point3 from" [0 10 0] "point3 to" [0 0 0] "float illuminance" 1000)"),
       {{Vec3(0, 0, 0), Vec3(0, 1, 0)}},
       1000 * kSlabT * (1 + kR * kR)},
      {"1000 lm sphere 3 m over glass slab (caustic): paraxial",
       slab(R"(AttributeBegin
  AreaLightSource "diffuse" "float power" 1000
  Translate 0 3 0
  Shape "sphere" "float radius" 0.02
AttributeEnd)"),
       {{Vec3(0, 0, 0), Vec3(0, 1, 0)}},
       1000 / (4 * kPi) * kSlabT *
           (1 / std::pow(3 - 0.1 + 0.1 / 1.5, 2) + kR * kR / std::pow(3 - 0.1 + 0.3 / 1.5, 2))},
  };
}

// The RMS over seeds (and sensors) of each render's stated error and of its actual error, and the
// mean value.
struct Summary {
  double mean = 0, stated = 0, measured = 0;
};

Summary run_case(const Case& c, const LoadedScene& ls, const std::string& integrator, int seeds,
                 int passes, double seconds) {
  double sum = 0, stated2 = 0, error2 = 0;
  for (int s = 0; s < seeds; ++s) {
    Film film(ls.film.width, ls.film.height, Film::kStreams, c.sensors.size());
    RenderOptions opt = quiet_options(ls, integrator, passes, uint64_t(101 + s));
    opt.sensors = c.sensors;
    opt.image = c.sensors.empty();
    if (seconds > 0) {
      opt.spp = 1 << 30;
      opt.time_limit_s = seconds;
    }
    render(ls, opt, &film);
    std::vector<Reading> readings;
    if (c.sensors.empty()) readings = centre_luminance(film);
    for (size_t i = 0; i < c.sensors.size(); ++i)
      readings.push_back({film.sensor_mean(i), film.sensor_total_error(i)});
    for (const Reading& r : readings) {
      sum += r.value;
      stated2 += r.stated * r.stated;
      error2 += (r.value - c.expected) * (r.value - c.expected);
    }
  }
  const double n = double(seeds) * double(c.sensors.empty() ? 4 : c.sensors.size());
  return {sum / n, std::sqrt(stated2 / n), std::sqrt(error2 / n)};
}

}  // namespace

int main(int argc, char** argv) {
  int seeds = 8, passes = 64;
  double seconds = 2;
  std::string only;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--seeds")) seeds = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--passes")) passes = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--seconds")) seconds = std::atof(argv[i + 1]);
    if (!std::strcmp(argv[i], "--only")) only = argv[i + 1];
  }
  std::vector<Case> all = cases(), chosen;
  for (const Case& c : all)
    if (std::string(c.name).find(only) != std::string::npos) chosen.push_back(c);
  std::printf(
      "photometry: %d seeds of %d passes each; value and errors in cd/m^2 (luminance) or "
      "lux (sensors)\n\n",
      seeds, passes);
  std::printf("%-58s %-5s %12s %12s %10s %10s %7s\n", "case", "", "expected", "mean", "stated",
              "measured", "ratio");
  const std::vector<std::string> integrators{"path", "bpm", "fpm"};
  for (const Case& c : chosen) {
    const LoadedScene ls = flatten_scene(parse_scene_string(c.scene));
    for (const std::string& integrator : integrators) {
      const Summary m = run_case(c, ls, integrator, seeds, passes, 0);
      std::printf("%-58s %-5s %12.8g %12.8g %10.3g %10.3g %7.2f\n", c.name, integrator.c_str(),
                  c.expected, m.mean, m.stated, m.measured, m.stated / m.measured);
    }
  }
  std::printf(
      "\n(stated: the RMS over seeds of the error each render reports, standard error and bias "
      "estimate; measured: the RMS over seeds of value - expected; ratio: stated / measured, 1 "
      "when the estimate is honest)\n\n");
  if (seconds <= 0) return 0;
  std::printf("sensors alone at equal time: %d seeds of %g s each\n", seeds, seconds);
  std::printf("%-58s %-5s %10s %10s %10s %12s\n", "case", "", "expected", "mean", "measured",
              "path / this");
  for (const Case& c : chosen) {
    if (c.sensors.empty()) continue;
    const LoadedScene ls = flatten_scene(parse_scene_string(c.scene));
    double path_error = 0;
    for (const std::string& integrator : integrators) {
      const Summary m = run_case(c, ls, integrator, seeds, 0, seconds);
      if (integrator == "path") path_error = m.measured;
      std::printf("%-58s %-5s %10.5g %10.5g %10.3g %12.2f\n", c.name, integrator.c_str(),
                  c.expected, m.mean, m.measured, path_error / m.measured);
    }
  }
  std::printf(
      "\n(path / this: path's RMS error over this integrator's, in the same run; above 1: "
      "this one is ahead)\n");
  return 0;
}
