// Illuminance sensors against closed forms (lux, with lights in pbrt-v4's photometric terms): the
// inverse-square law of a point light at points on and above a plane, and the integrating sphere,
// whose illuminance from interreflection is rho Phi / (A (1 - rho)) everywhere. Each sensor's
// value must lie within three of its own standard errors (plus a relative 1e-4 for the sensor's
// lift off its surface, 1e-6 of the scene's radius) of the closed form.
#include "path/sensors.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "test_util.h"

namespace bpm {
namespace {

constexpr double kPi = 3.14159265358979323846;

Film render_sensors(const std::string& scene, const std::vector<Sensor>& sensors, int passes,
                    const std::string& integrator = "path", bool image = false) {
  LoadedScene ls = test::load(scene);
  Film film(ls.film.width, ls.film.height, 0, sensors.size());
  RenderOptions opt = quiet_options(ls, integrator, passes, 5);
  opt.sensors = sensors;
  opt.image = image;
  render(ls, opt, &film);
  return film;
}

void expect_lux(const Film& film, size_t i, double expected, const std::string& what) {
  EXPECT_NEAR(film.sensor_mean(i), expected, 3 * film.sensor_standard_error(i) + 1e-4 * expected)
      << what << ": " << film.sensor_mean(i) << " lux (standard error "
      << film.sensor_standard_error(i) << ") against " << expected;
}

const char* kPlane = R"(LookAt 0 0 3  0 0 0  0 1 0
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
Integrator "path" "integer maxdepth" 1
WorldBegin
LightSource "point" "point3 from" [0 0 1] "float power" 1000
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [-10 -10 0  10 -10 0  10 10 0  -10 10 0]
)";

// E = I cos(theta) / d^2 with I = 1000 / (4 pi) cd, on the plane and in mid-air above it.
TEST(Sensors, PointLightFollowsTheInverseSquareLaw) {
  const std::vector<Sensor> sensors =
      parse_sensors("0 0 0 0 0 1\n0.5 0 0 0 0 1\n0 0 0.5 0 0 1\n-0.3 0.4 0.2 0 0 1\n", "s.txt");
  const Film film = render_sensors(kPlane, sensors, 256);
  const double intensity = 1000 / (4 * kPi);
  for (size_t i = 0; i < sensors.size(); ++i) {
    const Vec3 d = Vec3(0, 0, 1) - sensors[i].p;
    const double r = length(d);
    expect_lux(film, i, intensity * (d.z / r) / (r * r), "sensor " + std::to_string(i));
  }
}

// A sphere of radius 1 and reflectance 0.5 around a 1000 lm point light at its centre: a sensor
// on the wall gets Phi / A directly and rho Phi / (A (1 - rho)) by interreflection, Phi / (A (1 -
// rho)) in all; one in mid-air facing away from the light sees the wall's uniform radiance,
// rho Phi / (A (1 - rho)).
TEST(Sensors, IntegratingSphere) {
  const std::string scene = R"(LookAt 0 0 -0.5  0 0 1  0 1 0
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
Integrator "path" "integer maxdepth" 60
WorldBegin
LightSource "point" "point3 from" [0 0 0] "float power" 1000
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "sphere" "float radius" 1
)";
  const std::vector<Sensor> sensors =
      parse_sensors("1 0 0  -1 0 0\n0 -0.6 0.3  0 -1 0\n", "sphere.txt");
  const Film film = render_sensors(scene, sensors, 256);
  const double area = 4 * kPi, rho = 0.5, phi = 1000;
  expect_lux(film, 0, phi / (area * (1 - rho)), "on the wall");
  expect_lux(film, 1, rho * phi / (area * (1 - rho)), "in mid-air, away from the light");
}

// The sensors' estimates depend on the seed and the pass only: the same with any integrator
// rendering the image, and without an image.
TEST(Sensors, EstimatesDoNotDependOnTheImage) {
  const std::vector<Sensor> sensors = parse_sensors("grid -1 -1 0.1  2 0 0  0 2 0  3 2\n", "g");
  ASSERT_EQ(sensors.size(), 6u);
  EXPECT_NEAR(sensors[4].p.x, 0, 1e-6);
  EXPECT_NEAR(sensors[4].p.y, 0.5, 1e-6);
  EXPECT_NEAR(sensors[4].n.z, 1, 1e-6);
  const Film alone = render_sensors(kPlane, sensors, 8);
  for (const char* integrator : {"path", "bpm", "fpm"}) {
    const Film with = render_sensors(kPlane, sensors, 8, integrator, true);
    for (size_t i = 0; i < sensors.size(); ++i)
      EXPECT_EQ(with.sensor_mean(i), alone.sensor_mean(i)) << integrator << " sensor " << i;
  }
}

std::string sensor_error(const std::string& text) {
  try {
    parse_sensors(text, "s.txt");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Sensors, BadFilesAreLocatedErrors) {
  EXPECT_NE(sensor_error("0 0 0 0 0 1\n1 2 x 0 0 1\n").find("s.txt:2:5: \"x\" is not a number"),
            std::string::npos);
  EXPECT_NE(sensor_error("# comment\n1 2 3 0 0\n").find("s.txt:2:1: a sensor needs 6 numbers"),
            std::string::npos);
  EXPECT_NE(sensor_error("1 2 3 0 0 0\n").find("normal must not be zero"), std::string::npos);
  EXPECT_NE(sensor_error("grid 0 0 0 1 0 0 2 0 0 3 3\n").find("must not be parallel"),
            std::string::npos);
  EXPECT_NE(sensor_error("grid 0 0 0 1 0 0 0 1 0 3 0.5\n").find("cell counts"), std::string::npos);
  EXPECT_NE(sensor_error("grid 0 0 0 1 0 0 0 1 0 1e4 1e4\n").find("more than 10^7 sensors"),
            std::string::npos);
  EXPECT_NE(sensor_error("\n# nothing\n").find("holds no sensor"), std::string::npos);
  EXPECT_EQ(parse_sensors("1 2 3 0 0 2 # up\n", "s").at(0).n.z, 1.0f);
  // Lines of white space other than blanks and tabs (a vertical tab, a form feed) are empty.
  EXPECT_EQ(parse_sensors("\v\n\f \n1 2 3 0 0 1\n", "s").size(), 1u);
}

}  // namespace
}  // namespace bpm
