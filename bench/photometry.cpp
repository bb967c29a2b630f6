// Photometry against closed forms, in absolute units: for each case and integrator, the value
// expected, the mean over several seeds of what the render reports (cd/m^2 of the luminance
// channel at the image's centre pixels, or lux at a sensor), the error it states (its standard
// error, and for the photon methods its bias estimate), the error it actually makes (the RMS over
// the seeds of value - expected) and their ratio. Prints figures; never fails.
//   photometry [--seeds N] [--passes N]
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>

#include "path/sensors.h"
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

// The luminance at the image's central 2 x 2 pixels (a camera looking straight down at a
// point), and its standard error there (with the bias estimate, for the photon methods).
Reading centre_luminance(const Film& film) {
  const int w = film.width(), h = film.height();
  const std::vector<float> y = film.luminance_image(), total = film.total_rms_luminance();
  Reading r;
  double var = 0;
  for (int j = h / 2 - 1; j <= h / 2; ++j)
    for (int i = w / 2 - 1; i <= w / 2; ++i) {
      r.value += y[size_t(j) * w + i] / 4;
      var += double(total[size_t(j) * w + i]) * total[size_t(j) * w + i] / 16;
    }
  r.stated = std::sqrt(var);
  return r;
}

struct Case {
  const char* name;
  std::string scene;
  std::vector<Sensor> sensors;  // empty: the luminance at the image's centre
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
       1000 / (4 * kPi) / kPi},
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
  };
}

}  // namespace

int main(int argc, char** argv) {
  int seeds = 8, passes = 64;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--seeds")) seeds = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--passes")) passes = std::atoi(argv[i + 1]);
  }
  std::printf(
      "photometry: %d seeds of %d passes each; value and errors in cd/m^2 (luminance) or "
      "lux (sensors)\n\n",
      seeds, passes);
  std::printf("%-58s %-5s %10s %10s %10s %10s %7s\n", "case", "", "expected", "mean", "stated",
              "measured", "ratio");
  for (const Case& c : cases()) {
    const LoadedScene ls = flatten_scene(parse_scene_string(c.scene));
    // Sensors are estimated by the path tracer's estimator whatever the integrator: path alone.
    const std::vector<std::string> integrators =
        c.sensors.empty() ? std::vector<std::string>{"path", "bpm", "fpm"}
                          : std::vector<std::string>{"path"};
    for (const std::string& integrator : integrators) {
      double sum = 0, stated2 = 0, error2 = 0;
      for (int s = 0; s < seeds; ++s) {
        Film film(ls.film.width, ls.film.height, 0, c.sensors.size());
        RenderOptions opt = quiet_options(ls, integrator, passes, uint64_t(101 + s));
        opt.sensors = c.sensors;
        opt.image = c.sensors.empty();
        render(ls, opt, &film);
        Reading r = c.sensors.empty() ? centre_luminance(film)
                                      : Reading{film.sensor_mean(0), film.sensor_standard_error(0)};
        sum += r.value;
        stated2 += r.stated * r.stated;
        error2 += (r.value - c.expected) * (r.value - c.expected);
      }
      const double stated = std::sqrt(stated2 / seeds), measured = std::sqrt(error2 / seeds);
      std::printf("%-58s %-5s %10.5g %10.5g %10.3g %10.3g %7.2f\n", c.name, integrator.c_str(),
                  c.expected, sum / seeds, stated, measured, stated / measured);
    }
  }
  std::printf(
      "\n(stated: the RMS over seeds of the error each render reports; measured: the RMS "
      "over seeds of value - expected; ratio: stated / measured, 1 when the estimate is "
      "honest)\n");
  return 0;
}
