// Scattering media in the path integrator against closed forms: transmittance at depth 0 (the
// free-flight sampling's weights, chromatic media included), single scattering of a point light
// seen from inside a medium (next-event estimation through the phase function), and the
// albedo-1 furnace (no light lost or counted twice by the MIS of phase and light sampling).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <sstream>

#include "base/sampling.h"
#include "camera/camera.h"
#include "integrator/direct_light.h"
#include "integrator/sensors.h"
#include "test_util.h"

namespace bpm {
namespace {

using test::load;

Film render_path(const LoadedScene& ls, int spp, uint64_t seed = 1) {
  Film film(ls.film.width, ls.film.height);
  render(ls, quiet_options(ls, "path", spp, seed), &film);
  return film;
}

std::string slab_scene(const std::string& medium, int max_depth) {
  return R"(LookAt 0 0 -4  0 0 0  0 1 0
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 12 "integer yresolution" 12
PixelFilter "box" "float xradius" 0.0001 "float yradius" 0.0001
Integrator "path" "integer maxdepth" )" +
         std::to_string(max_depth) + "\nMakeNamedMedium \"m\" \"string type\" \"homogeneous\" " +
         medium + R"(
WorldBegin
AttributeBegin
  MediumInterface "m" ""
  Material "interface"
  Shape "sphere" "float radius" 1
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [1 1 1]
  Material "diffuse" "rgb reflectance" [0 0 0]
  Shape "trianglemesh" "point3 P" [-9 -9 3  9 -9 3  9 9 3  -9 9 3] "integer indices" [0 2 1 0 3 2]
AttributeEnd
)";
}

// A slab scene's medium defined after WorldBegin, in world space: before it the CTM is the
// camera's (LookAt), which would put a grid's box away from the sphere, as in pbrt-v4.
std::string medium_in_world(std::string scene) {
  const size_t begin = scene.find("MakeNamedMedium"), end = scene.find("\nWorldBegin\n");
  const std::string medium = scene.substr(begin, end - begin);
  scene.erase(begin, end - begin);
  scene.insert(scene.find("WorldBegin\n") + 11, medium + "\n");
  return scene;
}

// A pixel's camera ray (unit direction) and where it enters and leaves the unit sphere at the
// origin (the slab scenes' medium); `grazing` where it passes within a sliver of its edge, whose
// pixels straddle it, `hits` where it crosses it.
struct PixelChord {
  Ray ray;
  float t0 = 0, t1 = 0;
  bool grazing = false, hits = false;
  float length() const { return t1 - t0; }
};
PixelChord pixel_chord(const Camera& cam, int x, int y) {
  PixelChord p;
  const Ray r = cam.generate_ray({x + 0.5f, y + 0.5f}, {0.5f, 0.5f}).ray;
  p.ray = Ray{r.o, normalize(r.d), kInf};
  const float b = dot(r.o, p.ray.d), c = length_squared(r.o) - 1, disc = b * b - c;
  p.grazing = disc > 0 && disc < 0.05f;
  p.hits = disc >= 0.05f;
  if (p.hits) p.t0 = -b - std::sqrt(disc), p.t1 = -b + std::sqrt(disc);
  return p;
}

// Every pixel of a slab scene's film that does not graze the sphere against expected(chord), the
// chord its ray cuts through the sphere (0 for one that misses it), within 5 of its rms; the
// pixels whose rays cross the sphere must be more than 20.
template <class Expected>
void expect_pixels_follow_chords(const LoadedScene& ls, const Film& f, Expected expected) {
  const Image img = f.image();
  const std::vector<float> rms = f.rms();
  const Camera cam(ls.camera, 12, 12);
  int inside = 0;
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 12; ++x) {
      const PixelChord p = pixel_chord(cam, x, y);
      if (p.grazing) continue;
      inside += p.hits;
      EXPECT_NEAR(img.at(x, y).luminance(), expected(p.length()),
                  5 * rms[size_t(y) * 12 + x] + 1e-3f)
          << x << "," << y;
    }
  EXPECT_GT(inside, 20);
}

// At depth 0 only light that crosses the medium unscattered counts: exp(-sigma_t c) through a
// chord c of the sphere, whatever part of sigma_t scatters. A chromatic medium renders as the
// absorbing one with the same sigma_t, channel by channel (the one-sample MIS over wavelengths).
TEST(Media, UnscatteredLightIsBeerLambertOfSigmaT) {
  const LoadedScene grey =
      load(slab_scene("\"rgb sigma_a\" [0.3 0.3 0.3] \"rgb sigma_s\" [0.5 0.5 0.5]", 0));
  expect_pixels_follow_chords(grey, render_path(grey, 64),
                              [](float chord) { return std::exp(-0.8f * chord); });
  const Image chromatic =
      render_path(load(slab_scene("\"rgb sigma_a\" [0 0 0] \"rgb sigma_s\" [0.9 0.2 0.4]", 0)), 256)
          .image();
  const Image absorbing =
      render_path(load(slab_scene("\"rgb sigma_a\" [0.9 0.2 0.4] \"rgb sigma_s\" [0 0 0]", 0)), 256)
          .image();
  for (int c = 0; c < 3; ++c) {
    double a = 0, b = 0;
    for (int y = 0; y < 12; ++y)
      for (int x = 0; x < 12; ++x) a += chromatic.at(x, y)[c], b += absorbing.at(x, y)[c];
    EXPECT_NEAR(a / b, 1, 0.01) << "channel " << c;
  }
}

// The single-scattering test's pixels against the integral along their rays.
void check_single_scattering(const LoadedScene& ls, const Film& film, Vec3 light, float sigma_s,
                             float sigma_t, float g, float R) {
  const Image img = film.image();
  const std::vector<float> rms = film.rms();
  const Camera cam(ls.camera, 8, 8);
  for (int y = 0; y < 8; y += 3)
    for (int x = 0; x < 8; x += 3) {
      const Vec3 d = normalize(cam.generate_ray({x + 0.5f, y + 0.5f}, {0.5f, 0.5f}).ray.d);
      double sum = 0;
      const int n = 30000;
      for (int i = 0; i < n; ++i) {
        const double t = R * (i + 0.5) / n;
        const Vec3 to = light - d * float(t);
        const double r = length(to);
        sum += sigma_s * std::exp(-sigma_t * t) * henyey_greenstein(dot(d, to) / float(r), g) *
               std::exp(-sigma_t * r) / (r * r);
      }
      const double expected = sum * R / n;
      EXPECT_NEAR(img.at(x, y).luminance(), expected, 5 * rms[size_t(y) * 8 + x] + 1e-3 * expected)
          << x << "," << y;
      EXPECT_LT(rms[size_t(y) * 8 + x], 0.03 * expected);
    }
}

// A point light of intensity 1 inside a medium of sigma_s = 0.5, sigma_a = 0.1 and g = 0.4 that
// fills a sphere of radius 3 around the camera; at depth 1 a pixel sees the light scattered once
// along its ray: the integral over t of sigma_s exp(-sigma_t t) HG(cos) exp(-sigma_t r) / r^2,
// r the distance from the ray's point to the light (quadrature at 1e-4 of the sphere's radius).
TEST(Media, SingleScatteringOfAPointLight) {
  const float sigma_s = 0.5f, sigma_t = 0.6f, g = 0.4f, R = 3;
  const Vec3 light(0.4f, 0.3f, 1.2f);
  const LoadedScene ls = load(R"(LookAt 0 0 0  0 0 1  0 1 0
MakeNamedMedium "fog" "string type" "homogeneous" "rgb sigma_a" [0.1 0.1 0.1]
  "rgb sigma_s" [0.5 0.5 0.5] "float g" 0.4
MediumInterface "" "fog"
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
PixelFilter "box" "float xradius" 0.0001 "float yradius" 0.0001
Integrator "path" "integer maxdepth" 1
WorldBegin
LightSource "point" "point3 from" [0.4 0.3 1.2] "rgb I" [1 1 1]
AttributeBegin
  MediumInterface "fog" ""
  Material "interface"
  Shape "sphere" "float radius" 3
AttributeEnd
)");
  // Equiangular sampling along the camera ray shared with free flights (the default), and free
  // flights alone: each is exact on its own.
  // Near the light the first has the lower noise (its density of points falls as the light's
  // does, 1 / r^2).
  double rms_sum[2] = {0, 0};
  for (const bool equiangular : {true, false}) {
    SCOPED_TRACE(equiangular ? "equiangular" : "free flights");
    RenderOptions opt = quiet_options(ls, "path", 4096, 1);
    opt.equiangular = equiangular;
    Film film(8, 8);
    render(ls, opt, &film);
    check_single_scattering(ls, film, light, sigma_s, sigma_t, g, R);
    for (float r : film.rms()) rms_sum[equiangular ? 0 : 1] += r;
  }
  EXPECT_LT(rms_sum[0], 0.8 * rms_sum[1]);
}

// A closed sphere whose wall emits radiance 1 and reflects nothing, filled with a medium that
// scatters without absorbing (albedo 1, g = 0.6): the radiance inside is 1 everywhere and in every
// direction, however often light scatters.
TEST(Media, AlbedoOneFurnace) {
  const LoadedScene ls = load(test::albedo_one_furnace("1 1 1", 8));
  const Film film = render_path(ls, 256);
  const Image img = film.image();
  double mean = 0, var = 0;
  const std::vector<float> rms = film.rms();
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      mean += img.at(x, y).luminance() / 64;
      var += double(rms[size_t(y) * 8 + x]) * rms[size_t(y) * 8 + x] / (64.0 * 64.0);
    }
  EXPECT_NEAR(mean, 1, 5 * std::sqrt(var) + 1e-3);
  EXPECT_LT(std::sqrt(var), 0.01);
}

// A grid of densities (a 3 x 3 x 3 pattern, zero included) on a box, rotated, around the
// camera.
const char* kGridMedium =
    "\"string type\" \"uniformgrid\" \"integer nx\" 3 \"integer ny\" 3 \"integer nz\" 3 "
    "\"point3 p0\" [-1.2 -1.1 -1] \"point3 p1\" [1 1.2 1.1] "
    "\"float density\" [0 1 2 3 0.5 1 2 0 1  1 1 0.2 0 2 3 1 0.5 0  2 0 1 1 3 0.1 0.4 1 2]";

// Direct light is sampled along the camera's rays in media (equiangular sampling, shared with
// free flights by the balance heuristic) or at free-flight points alone: the same image within
// their noise, for point, spot, one-sided quad and sphere lights in a grid medium (and a
// homogeneous one) at depth 2.
TEST(Media, EquiangularSamplingAgreesWithFreeFlights) {
  const std::string lights = R"(
LightSource "point" "point3 from" [0.6 0.3 0.8] "rgb I" [0.3 0.3 0.3]
LightSource "spot" "point3 from" [-0.5 0.5 0.5] "point3 to" [0 -1 1] "rgb I" [1 0.5 0.2]
  "float coneangle" 30
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [2 2 2]
  Material "diffuse" "rgb reflectance" [0 0 0]
  Shape "trianglemesh" "point3 P" [-0.2 0.9 0.2  0.2 0.9 0.2  0.2 0.9 0.6  -0.2 0.9 0.6]
    "integer indices" [0 1 2 0 2 3]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [1 2 3]
  Material "diffuse" "rgb reflectance" [0 0 0]
  Translate -0.5 -0.4 0.7
  Shape "sphere" "float radius" 0.1
AttributeEnd
)";
  for (const std::string& medium :
       {std::string(kGridMedium) + " \"rgb sigma_a\" [0.2 0.3 0.1] \"rgb sigma_s\" [1 0.6 0.8]",
        std::string("\"string type\" \"homogeneous\" \"rgb sigma_a\" [0.05 0.05 0.05] "
                    "\"rgb sigma_s\" [0.4 0.5 0.6]")}) {
    SCOPED_TRACE(medium);
    const LoadedScene ls = load(R"(LookAt 0 0 -0.5  0 0 1  0 1 0
MakeNamedMedium "m" )" + medium +
                                R"( "float g" -0.3
MediumInterface "" "m"
Camera "perspective" "float fov" 60
Film "rgb" "integer xresolution" 10 "integer yresolution" 10
PixelFilter "box" "float xradius" 0.0001 "float yradius" 0.0001
Integrator "path" "integer maxdepth" 2
WorldBegin
AttributeBegin
  MediumInterface "m" ""
  Material "interface"
  Shape "sphere" "float radius" 3
AttributeEnd
)" + lights);
    Film films[2] = {Film(10, 10), Film(10, 10)};
    for (int k = 0; k < 2; ++k) {
      RenderOptions opt = quiet_options(ls, "path", 2048, 5 + uint64_t(k));
      opt.equiangular = k == 0;
      render(ls, opt, &films[k]);
    }
    const Image a = films[0].image(), b = films[1].image();
    const std::vector<float> ra = films[0].rms(), rb = films[1].rms();
    double diff = 0, var = 0;
    for (size_t i = 0; i < ra.size(); ++i) {
      const int x = int(i % 10), y = int(i / 10);
      const double d = a.at(x, y).luminance() - b.at(x, y).luminance();
      const double v = double(ra[i]) * ra[i] + double(rb[i]) * rb[i];
      EXPECT_LT(std::fabs(d), 5 * std::sqrt(v) + 1e-4) << x << "," << y;
      diff += d;
      var += v;
    }
    EXPECT_LT(std::fabs(diff), 4 * std::sqrt(var));
  }
}

// A point drawn on a piece of ray by a free flight conditioned to end there (bpm's splitting in
// media) carries sigma_s T / p: in a medium of albedo 1 its mean weight is the chance of scattering
// on the piece, 1 - exp(-sigma_t L) at each wavelength, and 1 on a piece without end (the camera
// in open fog looking at the sky); chromatic sigma_t, a homogeneous and a grid medium.
TEST(Media, ForcedFreeFlightWeightsAreTheChanceOfScattering) {
  for (const std::string& medium :
       {std::string("\"string type\" \"homogeneous\""), std::string(kGridMedium)}) {
    SCOPED_TRACE(medium);
    const LoadedScene ls = load(R"(LookAt 0 0 -0.5  0 0 1  0 1 0
MakeNamedMedium "m" )" + medium +
                                R"( "rgb sigma_a" [0 0 0] "rgb sigma_s" [0.3 0.8 1.6]
MediumInterface "" "m"
Camera "perspective"
WorldBegin
)");
    const Wavelengths wl = sample_wavelengths(0.37f);
    const Spectrum sigma_t = ls.scene.media[0].sigma_s.sample(wl);
    const Ray ray{Vec3(-0.2f, 0.1f, -1.2f), normalize(Vec3(0.3f, 0.2f, 1)), kInf};
    for (const float length : {0.7f, 2.5f, kInf}) {
      SCOPED_TRACE(length);
      Rng rng(11);
      const int n = 200000;
      std::vector<double> sum(Spectrum::kChannels, 0), sum2(Spectrum::kChannels, 0);
      for (int i = 0; i < n; ++i) {
        Spectrum beta(1.0f);
        float none = -1;
        const float t =
            sample_forced_medium_distance(ls.scene, 0, ray, length, wl, rng, none, beta);
        if (t < 0) continue;
        ASSERT_LE(t, length);
        for (int k = 0; k < Spectrum::kChannels; ++k) {
          sum[size_t(k)] += beta[k];
          sum2[size_t(k)] += double(beta[k]) * beta[k];
        }
      }
      const float tau = ls.scene.media[0].depth(ray, 0, length);
      for (int k = 0; k < Spectrum::kChannels; ++k) {
        const double mean = sum[size_t(k)] / n;
        const double sigma = std::sqrt(std::max(0.0, sum2[size_t(k)] / n - mean * mean) / n);
        EXPECT_NEAR(mean, -std::expm1(-double(sigma_t[k]) * tau), 5 * sigma + 1e-4) << k;
      }
    }
  }
}

// A shadow ray through three spheres of scattering media and one of an absorbing medium, on a
// line: its transmittance is the product of all four; the probability that a free flight gets
// across is that of the scattering ones alone, less the last `certain_last` of them (those that a
// path from the target crosses for certain: bpm's camera rays split there), whatever their number
// (within 1e-3: each crossing of an interface starts a hair past it).
TEST(Media, ShadowRayPassLeavesOutTheStretchesCrossedForCertain) {
  std::string scene = "LookAt 0 0 -4  0 0 0  0 1 0\nCamera \"perspective\"\n";
  const float sigma_s[] = {0.2f, 0.5f, 0.9f};
  for (int i = 0; i < 3; ++i) {
    const std::string v = std::to_string(sigma_s[i]);
    scene += "MakeNamedMedium \"m" + std::to_string(i) +
             "\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.1 0.1 0.1] "
             "\"rgb sigma_s\" [" +
             v + " " + v + " " + v + "]\n";
  }
  scene +=
      "MakeNamedMedium \"dark\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [1 1 1] "
      "\"rgb sigma_s\" [0 0 0]\nWorldBegin\n";
  for (int i = 0; i < 3; ++i)
    scene += "AttributeBegin\nMediumInterface \"m" + std::to_string(i) +
             "\" \"\"\nMaterial \"interface\"\nTranslate 0 0 " + std::to_string(3 * i) +
             "\nShape \"sphere\" \"float radius\" 1\nAttributeEnd\n";
  scene +=
      "AttributeBegin\nMediumInterface \"dark\" \"\"\nMaterial \"interface\"\nTranslate 0 0 "
      "4.5\nShape \"sphere\" \"float radius\" 0.4\nAttributeEnd\n";
  const LoadedScene ls = load(scene);
  const Wavelengths wl = sample_wavelengths(0.3f);
  const Vec3 from(0, 0, -2), to(0, 0, 8);
  double all = 1;
  std::vector<double> chord;  // each scattering sphere's probability, in the ray's order
  for (float s : sigma_s) {
    chord.push_back(std::exp(-2.0 * (s + 0.1)));
    all *= chord.back();
  }
  for (int certain = 0; certain <= 5; ++certain) {
    float pass = -1;
    const Spectrum T = shadow_transmittance(ls.scene, from, to, -1, false, wl, &pass, certain);
    double expected = 1;
    for (int i = 0; i < 3 - certain; ++i) expected *= chord[size_t(i)];
    EXPECT_NEAR(pass, expected, 1e-3 * expected) << certain;
    EXPECT_NEAR(T.average(), all * std::exp(-0.8), 1e-3 * all) << certain;
  }
}

// In a grid medium unscattered light keeps exp(-sigma_t tau), tau the integral of the density
// along the pixel's ray (here by the midpoint rule over the medium's own trilinear density, not
// the lattice walk under test). Chromatic, scattering, depth 0.
TEST(Media, UnscatteredLightThroughAGridIsExpOfItsDepth) {
  std::string scene = slab_scene(
      std::string(kGridMedium) + " \"rgb sigma_a\" [0.3 0.3 0.3] \"rgb sigma_s\" [0.5 0.5 0.5]", 0);
  const std::string homogeneous = "\"string type\" \"homogeneous\" ";
  scene.replace(scene.find(homogeneous), homogeneous.size(), "");
  const LoadedScene ls = load(medium_in_world(scene));
  ASSERT_TRUE(ls.scene.media.at(0).grid);
  const Film f = render_path(ls, 64);
  const Image img = f.image();
  const std::vector<float> rms = f.rms();
  const Camera cam(ls.camera, 12, 12);
  int inside = 0, dense = 0;
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 12; ++x) {
      const PixelChord p = pixel_chord(cam, x, y);
      if (!p.hits) continue;
      double tau = 0;
      const int n = 20000;
      for (int i = 0; i < n; ++i)
        tau += ls.scene.media[0].density(p.ray.o +
                                         p.ray.d * (p.t0 + p.length() * (float(i) + 0.5f) / n));
      tau *= double(p.length()) / n;
      EXPECT_NEAR(img.at(x, y).luminance(), std::exp(-0.8 * tau),
                  5 * rms[size_t(y) * 12 + x] + 1e-3f)
          << x << "," << y << " tau " << tau;
      ++inside;
      dense += tau > 0.2;
    }
  EXPECT_GT(inside, 20);
  EXPECT_GT(dense, 20);  // the grid's box holds the sphere: the chords cross its density
}

// The albedo-1 furnace with a grid medium: free flights, shadow rays and phase sampling through
// a heterogeneous medium keep radiance 1.
TEST(Media, AlbedoOneFurnaceWithAGridMedium) {
  const LoadedScene ls = load(test::albedo_one_furnace_of(
      std::string(kGridMedium) +
          " \"rgb sigma_a\" [0 0 0] \"rgb sigma_s\" [1.5 1 0.5] \"float g\" 0.6",
      8));
  ASSERT_TRUE(ls.scene.media.at(0).grid);
  const Film film = render_path(ls, 256);
  const Image img = film.image();
  const std::vector<float> rms = film.rms();
  for (int c = 0; c < 3; ++c) {
    double mean = 0, var = 0;
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        mean += img.at(x, y)[c] / 64;
        var += double(rms[size_t(y) * 8 + x]) * rms[size_t(y) * 8 + x] / (64.0 * 64.0);
      }
    EXPECT_NEAR(mean, 1, 5 * std::sqrt(var) + 2e-3) << "channel " << c;
  }
}

// A sphere of glowing absorbing gas (sigma_a 0.7, Le 2, Lescale 1.5) in front of a black
// backdrop: a pixel sees Le (1 - exp(-sigma_a c)) along a chord c. The photon methods refuse
// emitting media.
TEST(Media, EmittingMediumGlowsAlongItsChords) {
  std::string scene = slab_scene(
      "\"rgb sigma_a\" [0.7 0.7 0.7] \"rgb sigma_s\" [0 0 0] \"rgb Le\" [2 2 2] "
      "\"float Lescale\" 1.5",
      3);
  scene.replace(scene.find("\"rgb L\" [1 1 1]"), 15, "\"rgb L\" [0 0 0]");
  const LoadedScene ls = load(scene);
  ASSERT_TRUE(ls.scene.has_emissive_media());
  // Grey coefficients: the only noise is the glow's spectrum (D65) at the wavelengths drawn.
  expect_pixels_follow_chords(ls, render_path(ls, 16),
                              [](float chord) { return 3 * (1 - std::exp(-0.7f * chord)); });
  Film film(12, 12);
  EXPECT_THROW(render(ls, quiet_options(ls, "bpm", 1, 1), &film), Error);
}

// An absorbing glowing medium in the slab scene's sphere, with the backdrop's light off, rendered
// by path at 256 spp: each pixel sees the integral of exp(-tau(t)) glow(t) dt along its chord,
// where sigma_t(q) and glow(q) (luminance emitted per unit length) are given at a point (a
// midpoint rule of 4000 steps), within five standard errors of its estimate (path draws one point
// per piece of the chord). Returns the number of pixels that glow.
int expect_glow_along_chords(const LoadedScene& ls, const std::function<double(Vec3)>& sigma_t,
                             const std::function<double(Vec3)>& glow_at) {
  const Film f = render_path(ls, 256);
  const Image img = f.image();
  const std::vector<float> rms = f.rms();
  const Camera cam(ls.camera, 12, 12);
  int glowing = 0;
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 12; ++x) {
      const PixelChord p = pixel_chord(cam, x, y);
      if (!p.hits) continue;
      const int n = 4000;
      const double h = double(p.length()) / n;
      double tau = 0, glow = 0;
      for (int i = 0; i < n; ++i) {
        const Vec3 q = p.ray.o + p.ray.d * (p.t0 + float((i + 0.5) * h));
        const double s = sigma_t(q);
        glow += std::exp(-(tau + 0.5 * s * h)) * glow_at(q) * h;
        tau += s * h;
      }
      EXPECT_NEAR(img.at(x, y).luminance(), glow, 5 * rms[size_t(y) * 12 + x] + 2e-3 * glow)
          << x << "," << y;
      glowing += glow > 0.05;
    }
  return glowing;
}

// The slab scene with a glowing medium of type `type` and parameters `medium`, in world space,
// its backdrop's light off.
LoadedScene glowing_slab(const std::string& medium) {
  std::string scene = slab_scene(medium, 3);
  const std::string homogeneous = "\"string type\" \"homogeneous\" ";
  scene.replace(scene.find(homogeneous), homogeneous.size(), "");
  scene.replace(scene.find("\"rgb L\" [1 1 1]"), 15, "\"rgb L\" [0 0 0]");
  return load(medium_in_world(scene));
}

// A glowing, absorbing uniformgrid (sigma_a 0.6 per unit density, Le 2) whose glow a 3 x 3 x 3
// grid of Lescale values scales: glow(t) = 0.6 d(t) s(t) 2.
TEST(Media, GlowingGridScaledByItsLescaleGrid) {
  const LoadedScene ls = glowing_slab(
      std::string(kGridMedium) +
      " \"rgb sigma_a\" [0.6 0.6 0.6] \"rgb sigma_s\" [0 0 0] \"rgb Le\" [2 2 2] "
      "\"float Lescale\" [1 0 2 0.5 3 1 0 1 2  2 1 0 1 1 1 0.5 2 0  0 3 1 2 0.2 1 1 0 2]");
  const Medium& m = ls.scene.media.at(0);
  ASSERT_TRUE(m.grid && m.le_scale);
  const int glowing = expect_glow_along_chords(
      ls, [&](Vec3 q) { return 0.6 * m.density(q); },
      [&](Vec3 q) { return 0.6 * m.density(q) * m.le_scale->density(q) * 2; });
  EXPECT_GT(glowing, 20);  // the grid's box holds the sphere: the pixels glow
}

// The same grid glowing by a 3 x 3 x 3 grid of temperatures, offset by 200 K and scaled by 1.5
// (pbrt-v4's GridMedium), with its default Lescale (one voxel of 1): a point emits the blackbody
// at that temperature, 1 at its peak and not normalised, so glow(t) = 0.6 d(t) s(t) Y(T(t)) with
// Y(T) the integral of ybar times that blackbody in nm (tabulated per kelvin here).
TEST(Media, GridGlowingByTemperature) {
  const LoadedScene ls = glowing_slab(
      std::string(kGridMedium) +
      " \"rgb sigma_a\" [0.6 0.6 0.6] \"rgb sigma_s\" [0 0 0] \"float temperature\" "
      "[1500 900 1700 1200 2000 1000 300 1100 1600  1800 1400 600 1300 1900 1500 1000 1700 "
      "800  1200 1600 1400 2000 900 1500 1300 100 1700] \"float temperatureoffset\" 200 "
      "\"float temperaturescale\" 1.5");
  const Medium& m = ls.scene.media.at(0);
  ASSERT_TRUE(m.grid && m.le_scale && m.temperature);
  std::vector<double> luminance_at_kelvin(4000);
  for (size_t T = 101; T < luminance_at_kelvin.size(); ++T)
    luminance_at_kelvin[T] = SpectrumCurve::blackbody(float(T)).luminance() * ybar_integral();
  auto luminance = [&](double T) {
    if (!(T > 100)) return 0.0;
    const size_t i = std::min(size_t(T), luminance_at_kelvin.size() - 2);
    const double f = T - double(i);
    return luminance_at_kelvin[i] * (1 - f) + luminance_at_kelvin[i + 1] * f;
  };
  const int glowing = expect_glow_along_chords(
      ls, [&](Vec3 q) { return 0.6 * m.density(q); },
      [&](Vec3 q) {
        const double T = (m.temperature->density(q) - 200) * 1.5;
        return 0.6 * m.density(q) * m.le_scale->density(q) * luminance(T);
      });
  EXPECT_GT(glowing, 20);
}

// An rgbgrid glowing by grey colours of Le per voxel times Lescale 0.01 (pbrt-v4 does not
// normalise them: a grey c emits c D65 ybar_integral() Lescale, of luminance c 1.0686) where grey
// colours of sigma_a absorb: glow(t) = sigma_a(t) Le(t) 1.0686, interpolated per voxel.
TEST(Media, RgbGridGlowingByItsColoursOfLe) {
  const char* grey_a =
      "0 0.6 1.2 1.8 0.3 0.6 1.2 0 0.6  0.6 0.6 0.1 0 1.2 1.8 0.6 0.3 0  "
      "1.2 0 0.6 0.6 1.8 0.06 0.2 0.6 1.2";
  const char* grey_le = "1 0 2 0.5 3 1 0 1 2  2 1 0 1 1 1 0.5 2 0  0 3 1 2 0.2 1 1 0 2";
  auto triples = [](const char* values) {
    std::istringstream in(values);
    std::ostringstream out;
    for (float v; in >> v;) out << ' ' << 2 * v << ' ' << 2 * v << ' ' << 2 * v;
    return out.str();
  };
  const LoadedScene ls = glowing_slab(
      "\"string type\" \"rgbgrid\" \"integer nx\" 3 \"integer ny\" 3 \"integer nz\" 3 "
      "\"point3 p0\" [-1.2 -1.1 -1] \"point3 p1\" [1 1.2 1.1] \"rgb sigma_a\" [" +
      triples(grey_a) + "] \"rgb sigma_s\" [" +
      triples("0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0") +
      "] \"float scale\" 0.5 \"rgb Le\" [" + triples(grey_le) + "] \"float Lescale\" 0.005");
  const Medium& m = ls.scene.media.at(0);
  ASSERT_TRUE(m.rgb_grid && m.emits());
  const Wavelengths wl = sample_wavelengths(0.3f);
  auto sigma_a = [&](Vec3 q) {
    Spectrum a, s;
    m.rgb_grid->coefficients(q, wl, &a, &s);
    return double(a[0]);
  };
  const int glowing = expect_glow_along_chords(ls, sigma_a, [&](Vec3 q) {
    return sigma_a(q) * m.rgb_grid->glow(q, wl)[0] / d65_unit(wl.lambda[0]);
  });
  EXPECT_GT(glowing, 20);
}

TEST(Media, PhotonMethodsRefuseSensorsInScatteringMedia) {
  LoadedScene ls = load(slab_scene("\"rgb sigma_s\" [0.5 0.5 0.5]", 3));
  for (const char* integrator : {"bpm", "fpm"}) {
    RenderOptions opt = quiet_options(ls, integrator, 1, 1);
    opt.sensors = parse_sensors("0 0 0 0 0 1\n", "s.txt");
    Film with_sensors(ls.film.width, ls.film.height, 0, 1);
    EXPECT_THROW(render(ls, opt, &with_sensors), Error) << integrator;
  }
  // A file's integrator that maps to bpm renders with it.
  std::string bdpt = slab_scene("\"rgb sigma_s\" [0.5 0.5 0.5]", 3);
  bdpt.replace(bdpt.find("Integrator \"path\""), 17, "Integrator \"bdpt\"");
  EXPECT_EQ(load(bdpt).render.integrator, "bpm");
}

}  // namespace
}  // namespace bpm

namespace bpm {
namespace {

// A point light in a vacuum bubble (an interface sphere of radius 0.5) inside an absorbing medium
// (sigma_a 0.3), 2 units above a diffuse floor (albedo 0.5); the camera in the bubble looks
// straight down. Shadow rays cross the bubble's surface, as pbrt-v4's do: the floor below the
// light shows rho / pi I / h^2 exp(-sigma (h - 0.5)), dimmed by the camera ray's own
// exp(-sigma (h - 0.5)), in every integrator.
TEST(Media, ShadowRaysCrossInterfaces) {
  const LoadedScene ls = test::load(R"(LookAt 0 2 0  0 0 0  0 0 1
Camera "perspective" "float fov" 1
Film "rgb" "integer xresolution" 2 "integer yresolution" 2
PixelFilter "box"
Integrator "path" "integer maxdepth" 1
MakeNamedMedium "ink" "string type" "homogeneous" "rgb sigma_a" [0.3 0.3 0.3] "rgb sigma_s" [0 0 0]
WorldBegin
LightSource "point" "point3 from" [0 2 0] "rgb I" [1 1 1]
AttributeBegin
  MediumInterface "" "ink"
  Material "interface"
  Translate 0 2 0
  Shape "sphere" "float radius" 0.5
AttributeEnd
MediumInterface "ink"
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point3 P" [-9 0 -9  9 0 -9  9 0 9  -9 0 9]
)");
  const double t = std::exp(-0.3 * 1.5);
  const double expected = 0.5 / kPi * 1 / 4.0 * t * t;
  for (const char* integrator : {"path", "bpm", "fpm"}) {
    Film film(2, 2);
    render(ls, quiet_options(ls, integrator, 64, 1), &film);
    const Image img = film.image();
    double mean = 0;
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x) mean += img.at(x, y).luminance() / 4;
    EXPECT_NEAR(mean, expected, 0.01 * expected) << integrator;
  }
}

}  // namespace
}  // namespace bpm
