// Illuminance sensors against closed forms (lux, with lights in pbrt-v4's photometric terms), with
// every integrator: the inverse-square law of a point light at points on and above a plane, the
// integrating sphere, whose illuminance from interreflection is rho Phi / (A (1 - rho))
// everywhere, and the caustic under a glass slab, whose illuminance is the light's less the
// slab's Fresnel reflections. Each sensor's value must lie within three of its own standard
// errors plus its bias estimate (the photon methods'; plus a relative 1e-4 for the sensor's lift
// off its surface, 1e-6 of the scene's radius) of the closed form.
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
  EXPECT_NEAR(film.sensor_mean(i), expected,
              3 * film.sensor_standard_error(i) + std::fabs(film.sensor_bias(i)) + 1e-4 * expected)
      << what << ": " << film.sensor_mean(i) << " lux (standard error "
      << film.sensor_standard_error(i) << ", bias " << film.sensor_bias(i) << ") against "
      << expected;
}

// The same tests with each integrator.
class SensorsBy : public ::testing::TestWithParam<const char*> {};
INSTANTIATE_TEST_SUITE_P(Integrators, SensorsBy, ::testing::Values("path", "bpm", "fpm"));

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
TEST_P(SensorsBy, PointLightFollowsTheInverseSquareLaw) {
  const std::vector<Sensor> sensors =
      parse_sensors("0 0 0 0 0 1\n0.5 0 0 0 0 1\n0 0 0.5 0 0 1\n-0.3 0.4 0.2 0 0 1\n", "s.txt");
  const Film film = render_sensors(kPlane, sensors, 64, GetParam());
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
TEST_P(SensorsBy, IntegratingSphere) {
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
  const Film film = render_sensors(scene, sensors, 64, GetParam());
  const double area = 4 * kPi, rho = 0.5, phi = 1000;
  expect_lux(film, 0, phi / (area * (1 - rho)), "on the wall");
  expect_lux(film, 1, rho * phi / (area * (1 - rho)), "in mid-air, away from the light");
}

// A Lambertian rectangle of luminance 100 cd/m^2 (a blackbody scaled to it): at a point facing it
// on a parallel plane, under one corner, and at a point on a perpendicular plane, in front of one
// corner, the illuminance is pi L F with F the configuration factor of the point to the rectangle
// (the closed forms of heat transfer's catalogues, checked by quadrature).
TEST_P(SensorsBy, LambertianRectangleFollowsTheConfigurationFactors) {
  const std::string scene = R"(LookAt 0.5 -3 1  0.5 1 1  0 0 1
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
  // The first rectangle, 1 x 2, 1.5 over the point (0, 0, 0) facing +y; the second, 1 wide along
  // z and 2 high along y, stands in the plane x = 101.5, 1.5 from the point (100, -10, 0) facing
  // +y (each point sees the other's rectangle behind it, or 10^-5 of its own).
  const std::vector<Sensor> sensors = parse_sensors("0 0 0  0 1 0\n100 -10 0  0 1 0\n", "s");
  const Film film = render_sensors(scene, sensors, 64, GetParam());
  auto parallel = [](double a, double b, double c) {
    const double A = a / c, B = b / c, sa = std::sqrt(1 + A * A), sb = std::sqrt(1 + B * B);
    return (A / sa * std::atan(B / sa) + B / sb * std::atan(A / sb)) / (2 * kPi);
  };
  auto perpendicular = [](double a, double b, double c) {
    const double d = std::sqrt(c * c + b * b);
    return (std::atan(a / c) - c / d * std::atan(a / d)) / (2 * kPi);
  };
  expect_lux(film, 0, kPi * 100 * parallel(1, 2, 1.5), "parallel");
  expect_lux(film, 1, kPi * 100 * perpendicular(1, 2, 1.5), "perpendicular");
}

// A distant light of 1000 lux straight down through a horizontal glass slab (eta 1.5) onto a
// black floor: under the slab the illuminance is 1000 (1 - R)^2 (1 + R^2) with R = ((eta - 1) /
// (eta + 1))^2, the light that crosses both faces directly or after one reflection at each (the
// paths of at most maxdepth 5 bounces), on the floor and in mid-air; above the slab, facing up, it
// is the light's 1000 lux. A caustic of a delta light: the path tracer cannot see it (it is
// tested above the slab only); the photon methods must.
TEST_P(SensorsBy, GlassSlabTransmitsLessItsFresnelReflections) {
  const std::string scene = R"(LookAt 0 4 0.01  0 0 0  0 1 0
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
Integrator "path" "integer maxdepth" 5
WorldBegin
LightSource "distant" "point3 from" [0 10 0] "point3 to" [0 0 0] "float illuminance" 1000
Material "diffuse" "rgb reflectance" [0 0 0]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [-5 0 -5  5 0 -5  5 0 5  -5 0 5]
Material "dielectric" "float eta" 1.5
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3  4 6 5 4 7 6  0 5 1 0 4 5  1 6 2 1 5 6
                                        2 7 3 2 6 7  3 4 0 3 7 4]
  "point3 P" [-5 1 -5  5 1 -5  5 1 5  -5 1 5  -5 1.1 -5  5 1.1 -5  5 1.1 5  -5 1.1 5]
)";
  const std::vector<Sensor> sensors =
      parse_sensors("0 0 0  0 1 0\n0.7 0 -0.3  0 1 0\n0.2 0.5 0.1  0 1 0\n0 1.5 0  0 1 0\n", "s");
  const std::string integrator = GetParam();
  const Film film = render_sensors(scene, sensors, 32, integrator);
  const double R = 0.04, through = 1000 * (1 - R) * (1 - R) * (1 + R * R);
  expect_lux(film, 3, 1000, "above the slab");
  if (integrator == "path") return;
  expect_lux(film, 0, through, "on the floor");
  expect_lux(film, 1, through, "on the floor, off centre");
  expect_lux(film, 2, through, "in mid-air under the slab");
}

// A sensor stands in the medium around it: a point light 1 above a box of absorbing medium
// (sigma_a 0.7, an interface surface around it, the camera outside), sensors inside it facing up.
// The light reaches each through the box's top, exp(-sigma l) with l the length of its way inside:
// E = I cos(theta) / d^2 exp(-sigma d (1 - z) / (2 - z)).
TEST_P(SensorsBy, SensorsInsideAMediumAreAttenuated) {
  const std::string scene = R"(LookAt 0 -4 3  0 0 0  0 0 1
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
Integrator "path" "integer maxdepth" 1
WorldBegin
MakeNamedMedium "ink" "string type" "homogeneous" "rgb sigma_a" [0.7 0.7 0.7]
  "rgb sigma_s" [0 0 0]
LightSource "point" "point3 from" [0 0 2] "float power" 1000
AttributeBegin
  MediumInterface "ink" ""
  Material "interface"
  Shape "trianglemesh" "integer indices" [0 2 1 0 3 2  4 5 6 4 6 7  0 1 5 0 5 4  1 2 6 1 6 5
                                          2 3 7 2 7 6  3 0 4 3 4 7]
    "point3 P" [-2 -2 -1  2 -2 -1  2 2 -1  -2 2 -1  -2 -2 1  2 -2 1  2 2 1  -2 2 1]
AttributeEnd
)";
  const std::vector<Sensor> sensors = parse_sensors("0 0 0 0 0 1\n0.5 0 0.4 0 0 1\n", "s.txt");
  const Film film = render_sensors(scene, sensors, 32, GetParam());
  const double intensity = 1000 / (4 * kPi), sigma = 0.7;
  for (size_t i = 0; i < sensors.size(); ++i) {
    const Vec3 d = Vec3(0, 0, 2) - sensors[i].p;
    const double r = length(d), z = sensors[i].p.z;
    expect_lux(film, i, intensity * (d.z / r) / (r * r) * std::exp(-sigma * r * (1 - z) / (2 - z)),
               "sensor " + std::to_string(i));
  }
}

// The path tracer's sensors in a scattering medium: a closed sphere whose wall emits radiance 1
// and reflects nothing, filled with a medium that scatters without absorbing (albedo 1, g 0.6),
// has the radiance 1 everywhere and in every direction, so a sensor anywhere in it reads what it
// reads in the same sphere empty.
TEST(Sensors, PathSensorsInAnAlbedoOneFurnace) {
  const std::vector<Sensor> sensors = parse_sensors("0 0 0 0 0 1\n0.5 0.3 -0.8 1 0 0\n", "s.txt");
  const Film empty = render_sensors(test::albedo_one_furnace("0 0 0", 8), sensors, 128);
  const Film fog = render_sensors(test::albedo_one_furnace("1 1 1", 8), sensors, 512);
  for (size_t i = 0; i < sensors.size(); ++i) {
    const double e = std::hypot(fog.sensor_standard_error(i), empty.sensor_standard_error(i));
    EXPECT_NEAR(fog.sensor_mean(i), empty.sensor_mean(i), 4 * e) << "sensor " << i;
    EXPECT_LT(e, 0.01 * empty.sensor_mean(i)) << "sensor " << i;
  }
}

// --accuracy bounds the sensors' delta (eq. 4 over them) too: without an image it alone ends the
// render.
TEST_P(SensorsBy, AccuracyBoundsTheSensorsError) {
  const std::vector<Sensor> sensors = parse_sensors("0 0 0 0 0 1\n0.5 0 0 0 0 1\n", "s.txt");
  LoadedScene ls = test::load(kPlane);
  RenderOptions opt = quiet_options(ls, GetParam(), 1 << 20, 5);
  opt.sensors = sensors;
  opt.image = false;
  opt.accuracy = 0.002;
  Film film(ls.film.width, ls.film.height, 0, sensors.size());
  const RenderStats st = render(ls, opt, &film);
  EXPECT_EQ(st.stop_reason, "accuracy");
  EXPECT_LE(film.sensor_relative_error(), 0.002);
  EXPECT_GT(film.sensor_relative_error(), 0);
}

// The sensors' estimates depend on the seed and the pass only, not on the threads; the path
// tracer's are the same with an image and without one.
TEST_P(SensorsBy, EstimatesDoNotDependOnThreadsOrTheImage) {
  const std::vector<Sensor> sensors = parse_sensors("grid -1 -1 0.1  2 0 0  0 2 0  3 2\n", "g");
  ASSERT_EQ(sensors.size(), 6u);
  EXPECT_NEAR(sensors[4].p.x, 0, 1e-6);
  EXPECT_NEAR(sensors[4].p.y, 0.5, 1e-6);
  EXPECT_NEAR(sensors[4].n.z, 1, 1e-6);
  EXPECT_NEAR(sensors[4].cell, 2.0 / 3, 1e-6);
  LoadedScene ls = test::load(kPlane);
  RenderOptions opt = quiet_options(ls, GetParam(), 4, 5);
  opt.sensors = sensors;
  Film one(ls.film.width, ls.film.height, 0, sensors.size()), two = one, alone = one;
  opt.threads = 1;
  render(ls, opt, &one);
  opt.threads = 2;
  render(ls, opt, &two);
  opt.image = false;
  render(ls, opt, &alone);
  for (size_t i = 0; i < sensors.size(); ++i) {
    EXPECT_EQ(one.sensor_mean(i), two.sensor_mean(i)) << "sensor " << i;
    if (std::string(GetParam()) == "path") {
      EXPECT_EQ(one.sensor_mean(i), alone.sensor_mean(i)) << "sensor " << i;
    }
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
