// Analytic checks of the path integrator and of the render loop.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>

#include "camera/camera.h"
#include "film/image_io.h"
#include "integrator/progressive.h"
#include "test_util.h"

namespace bpm {
namespace {

using test::load;
using test::render_film;
using test::write_environment_exr;

// A convex diffuse object under a uniform environment L sees L over its whole hemisphere, so it
// reflects exactly rho * L; the background shows L.
TEST(PathIntegrator, ConvexDiffuseSphereUnderUniformSky) {
  const float rho = 0.8f;
  LoadedScene ls = load(R"(
    LookAt 0 0 -4  0 0 0  0 1 0
    Camera "perspective" "float fov" 30
    Film "rgb" "integer xresolution" 16 "integer yresolution" 16
    PixelFilter "box" "float xradius" 0.001 "float yradius" 0.001
    Integrator "path" "integer maxdepth" 10
    WorldBegin
    LightSource "infinite" "rgb L" [1 1 1]
    Material "diffuse" "rgb reflectance" [0.8 0.8 0.8]
    Shape "sphere" "float radius" 1
  )");
  Film film = render_film(ls, 64);
  Image img = film.image();
  std::vector<float> rms = film.rms();
  // Centre pixels see the sphere, corner pixels the sky. Grey under white light: the luminance
  // is the value; its only noise is the sampling of wavelengths (and of paths on the sphere).
  for (int y = 6; y < 10; ++y)
    for (int x = 6; x < 10; ++x) {
      float v = img.at(x, y).luminance();
      float sigma = rms[y * 16 + x];
      EXPECT_NEAR(v, rho, 4.5f * sigma + 1e-4f) << x << "," << y;
    }
  EXPECT_NEAR(img.at(0, 0).luminance(), 1.0f, 4.5f * rms[0] + 1e-4f);
  EXPECT_GT(rms[0], 0.0f);  // the wavelengths are sampled
}

// White furnace: inside a closed emitting sphere of albedo rho, radiance is Le / (1 - rho)
// everywhere (the Neumann series of the rendering equation). Exercises NEE, MIS between light
// and BSDF sampling, and Russian roulette over many bounces.
TEST(PathIntegrator, WhiteFurnaceEnclosure) {
  const float Le = 0.5f, rho = 0.5f;
  LoadedScene ls = load(R"(
    LookAt 0 0 0  0 0 1  0 1 0
    Camera "perspective" "float fov" 60
    Film "rgb" "integer xresolution" 8 "integer yresolution" 8
    PixelFilter "box"
    Integrator "path" "integer maxdepth" 200
    WorldBegin
    AreaLightSource "diffuse" "rgb L" [0.5 0.5 0.5] "bool twosided" true
    Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
    Shape "sphere" "float radius" 3
  )");
  Film film = render_film(ls, 256);
  Image img = film.image();
  std::vector<float> rms = film.rms();
  double sum = 0, var = 0;
  for (int i = 0; i < 64; ++i) {
    sum += img.at(i % 8, i / 8).average();
    var += double(rms[i]) * rms[i];
  }
  double mean = sum / 64, sigma = std::sqrt(var) / 64;
  EXPECT_NEAR(mean, Le / (1 - rho), 4 * sigma);
  EXPECT_LT(sigma, 0.02);  // the test has power: the tolerance is tight relative to the answer
}

// A diffuse plane under a point light: L = rho/pi * I cos(theta) / d^2 at every pixel. Direct
// light from a delta light has no spatial variance; what noise there is comes from the sampled
// wavelengths, and the per-pixel error estimate bounds it.
TEST(PathIntegrator, PlaneUnderPointLight) {
  const float rho = 0.6f, I = 3.0f, h = 2.0f;
  LoadedScene ls = load(R"(
    LookAt 0 5 -3  0 0 0  0 1 0
    Camera "perspective" "float fov" 50
    Film "rgb" "integer xresolution" 24 "integer yresolution" 16
    PixelFilter "box" "float xradius" 0.0001 "float yradius" 0.0001
    Integrator "path" "integer maxdepth" 1
    WorldBegin
    LightSource "point" "rgb I" [3 3 3] "point3 from" [0.5 2 0.3]
    Material "diffuse" "rgb reflectance" [0.6 0.6 0.6]
    Shape "trianglemesh" "point3 P" [-50 0 -50  50 0 -50  50 0 50  -50 0 50]
      "integer indices" [0 1 2 0 2 3]
  )");
  Film film = render_film(ls, 64);
  Image img = film.image();
  std::vector<float> rms = film.rms();
  Camera cam(ls.camera, 24, 16);
  double sum_ratio = 0, sum_var = 0;
  Vec3 light(0.5f, h, 0.3f);
  int checked = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 24; ++x) {
      Ray r = cam.generate_ray({x + 0.5f, y + 0.5f}, {0.5f, 0.5f}).ray;
      if (r.d.y >= 0) continue;
      Vec3 p = r.o + r.d * (-r.o.y / r.d.y);
      Vec3 to_light = light - p;
      float d2 = length_squared(to_light);
      float expected = rho / kPi * I * (to_light.y / std::sqrt(d2)) / d2;
      float sigma = rms[y * 24 + x];
      EXPECT_NEAR(img.at(x, y).luminance(), expected, 5 * sigma + 1e-4f * expected)
          << x << "," << y;
      EXPECT_LT(sigma, 0.02f * expected);
      sum_ratio += img.at(x, y).luminance() / expected;
      sum_var += double(sigma) * sigma / (double(expected) * expected);
      ++checked;
    }
  EXPECT_GT(checked, 200);
  // All pixels together: the mean ratio is 1 within 4 sigma (about 0.1%).
  EXPECT_NEAR(sum_ratio / checked, 1.0, 4 * std::sqrt(sum_var) / checked);
}

// The plane under the point light again, its reflectance now an image texture (a 2 x 2 PNG read
// with linear encoding and the point filter, repeated 25 times over the plane's uv): each pixel
// shows its texel's reflectance, which checks the image's orientation (t runs up the image).
TEST(PathIntegrator, ImageTexturedPlaneUnderPointLight) {
  const float I = 3.0f, h = 2.0f;
  std::filesystem::path png = std::filesystem::temp_directory_path() /
                              ("bpm_plane_texture_" + std::to_string(::getpid()) + ".png");
  Image tex;
  tex.width = tex.height = 2;
  tex.rgb = {0.2f, 0.2f, 0.2f, 0.9f, 0.9f, 0.9f,   // top row
             0.5f, 0.5f, 0.5f, 0.7f, 0.7f, 0.7f};  // bottom row
  write_png_display(png.string(), tex);
  LoadedScene ls = load(R"(
    LookAt 0 5 -3  0 0 0  0 1 0
    Camera "perspective" "float fov" 50
    Film "rgb" "integer xresolution" 24 "integer yresolution" 16
    PixelFilter "box" "float xradius" 0.0001 "float yradius" 0.0001
    Integrator "path" "integer maxdepth" 1
    WorldBegin
    LightSource "point" "rgb I" [3 3 3] "point3 from" [0.5 2 0.3]
    Texture "t" "spectrum" "imagemap" "string filename" ")" +
                        png.string() + R"("
      "string encoding" "linear" "string filter" "point" "float uscale" 25 "float vscale" 25
    Material "diffuse" "texture reflectance" "t"
    Shape "trianglemesh" "point3 P" [-50 0 -50  50 0 -50  50 0 50  -50 0 50]
      "point2 uv" [0 0 1 0 1 1 0 1] "integer indices" [0 1 2 0 2 3]
  )");
  std::filesystem::remove(png);
  Film film = render_film(ls, 64);
  Image img = film.image();
  std::vector<float> rms = film.rms();
  Camera cam(ls.camera, 24, 16);
  Vec3 light(0.5f, h, 0.3f);
  auto byte = [](float v) { return std::round(v * 255) / 255; };
  int checked = 0, seen[4] = {0, 0, 0, 0};
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 24; ++x) {
      Ray r = cam.generate_ray({x + 0.5f, y + 0.5f}, {0.5f, 0.5f}).ray;
      if (r.d.y >= 0) continue;
      Vec3 p = r.o + r.d * (-r.o.y / r.d.y);
      float fx = 2 * 25 * (p.x + 50) / 100, fy = 2 * (1 - 25 * (p.z + 50) / 100);
      auto near_edge = [](float f) { return std::fabs(f - std::round(f)) < 0.1f; };
      if (near_edge(fx) || near_edge(fy)) continue;
      int ix = int(std::floor(fx)) & 1, iy = int(std::floor(fy)) & 1;
      float rho = byte(tex.rgb[size_t(iy * 2 + ix) * 3]);
      ++seen[iy * 2 + ix];
      Vec3 to_light = light - p;
      float d2 = length_squared(to_light);
      float expected = rho / kPi * I * (to_light.y / std::sqrt(d2)) / d2;
      float sigma = rms[y * 24 + x];
      // The grey texels become near-constant spectra through the coefficient table (within 0.002).
      EXPECT_NEAR(img.at(x, y).luminance(), expected, 5 * sigma + 4e-3f * expected)
          << x << "," << y;
      ++checked;
    }
  EXPECT_GT(checked, 100);
  for (int k = 0; k < 4; ++k) EXPECT_GT(seen[k], 5) << "texel " << k;
}

// An absorbing medium (sigma_a = 0.7, grey) fills a sphere of radius 1 whose surface does not
// scatter; behind it an emitter of radiance 1 fills the view. Each pixel sees exp(-sigma_a c),
// c the chord its ray cuts through the sphere (Beer-Lambert), with every integrator.
TEST(Integrators, AbsorbingMediumAttenuatesByBeerLambert) {
  const float sigma = 0.7f, R = 1;
  LoadedScene ls = load(R"(
    LookAt 0 0 -4  0 0 0  0 1 0
    Camera "perspective" "float fov" 30
    Film "rgb" "integer xresolution" 16 "integer yresolution" 16
    PixelFilter "box" "float xradius" 0.0001 "float yradius" 0.0001
    Integrator "path" "integer maxdepth" 5
    MakeNamedMedium "ink" "string type" "homogeneous" "rgb sigma_a" [0.7 0.7 0.7] "rgb sigma_s" [0 0 0]
    WorldBegin
    AttributeBegin
      MediumInterface "ink" ""
      Material "interface"
      Shape "sphere" "float radius" 1
    AttributeEnd
    AttributeBegin
      AreaLightSource "diffuse" "rgb L" [1 1 1]
      Material "diffuse" "rgb reflectance" [0 0 0]
      Shape "trianglemesh" "point3 P" [-9 -9 3  9 -9 3  9 9 3  -9 9 3] "integer indices" [0 2 1 0 3 2]
    AttributeEnd
  )");
  Camera cam(ls.camera, 16, 16);
  for (const char* integrator : {"path", "bpm", "fpm"}) {
    Film film(16, 16);
    render(ls, quiet_options(ls, integrator, 64, 1), &film);
    Image img = film.image();
    std::vector<float> rms = film.rms();
    int inside = 0;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        Ray r = cam.generate_ray({x + 0.5f, y + 0.5f}, {0.5f, 0.5f}).ray;
        Vec3 d = normalize(r.d);
        float b = dot(r.o, d), c = length_squared(r.o) - R * R, disc = b * b - c;
        float chord = disc > 0 ? 2 * std::sqrt(disc) : 0;
        if (disc > 0 && disc < 0.05f) continue;  // grazing: the chord changes fast across the pixel
        inside += chord > 0;
        // The only noise is that of the sampled wavelengths.
        EXPECT_NEAR(img.at(x, y).luminance(), std::exp(-sigma * chord),
                    5 * rms[size_t(y) * 16 + x] + 1e-3f)
            << integrator << " " << x << "," << y;
        EXPECT_LT(rms[size_t(y) * 16 + x], 0.01f);
      }
    EXPECT_GT(inside, 40) << integrator;
    EXPECT_LT(img.at(8, 8).luminance(), 0.3f) << integrator;  // exp(-1.4) through the middle
  }
}

// The expectation of a pixel under the box filter of radius 1/2: f averaged over the pixel.
template <class F>
double pixel_mean(const Camera& cam, int x, int y, F&& f) {
  const int n = 12;
  double sum = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      sum += f(cam.generate_ray({x + (i + 0.5f) / n, y + (j + 0.5f) / n}, {0.5f, 0.5f}).ray);
  return sum / (n * n);
}

// Alpha masks with every integrator. (1) An emitter of radiance 1 seen through a black square
// whose alpha is a checkerboard of 0 and 0.25 cells: a pixel shows 1 - alpha averaged over it.
// (2) A plane under a point light, lit through a black disk of alpha 0.5 (an analytic shape)
// that covers the sky: half the unobstructed radiance, on camera rays, shadow rays and photons.
TEST(Integrators, AlphaMasksLetLightThrough) {
  LoadedScene sheet = load(R"(
    LookAt 0 0 -4  0 0 0  0 1 0
    Camera "perspective" "float fov" 30
    Film "rgb" "integer xresolution" 16 "integer yresolution" 16
    PixelFilter "box" "float xradius" 0.5 "float yradius" 0.5
    Integrator "path" "integer maxdepth" 5
    WorldBegin
    Texture "mask" "float" "checkerboard" "float uscale" 4 "float vscale" 4 "float tex1" 0 "float tex2" 0.25
    Material "diffuse" "rgb reflectance" [0 0 0]
    Shape "trianglemesh" "point3 P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0] "integer indices" [0 1 2 0 2 3]
      "point2 uv" [0 0  1 0  1 1  0 1] "texture alpha" "mask"
    AttributeBegin
      AreaLightSource "diffuse" "rgb L" [1 1 1]
      Shape "trianglemesh" "point3 P" [-9 -9 3  9 -9 3  9 9 3  -9 9 3] "integer indices" [0 2 1 0 3 2]
    AttributeEnd
  )");
  auto sheet_value = [](const Ray& r) {
    Vec3 p = r.o + r.d * (-r.o.z / r.d.z);
    if (std::fabs(p.x) > 1 || std::fabs(p.y) > 1) return 1.0;
    int cell = int(std::floor(2 * (p.x + 1))) + int(std::floor(2 * (p.y + 1)));
    return cell % 2 == 0 ? 1.0 : 0.75;
  };
  LoadedScene lit = load(R"(
    LookAt 0 1 -1  0 0 0.5  0 1 0
    Camera "perspective" "float fov" 50
    Film "rgb" "integer xresolution" 16 "integer yresolution" 16
    PixelFilter "box" "float xradius" 0.5 "float yradius" 0.5
    Integrator "path" "integer maxdepth" 5
    WorldBegin
    LightSource "point" "rgb I" [3 3 3] "point3 from" [0.5 3 0.3]
    AttributeBegin
      Material "diffuse" "rgb reflectance" [0 0 0]
      Translate 0 2 0
      Rotate 90 1 0 0
      Shape "disk" "float radius" 100 "float alpha" 0.5
    AttributeEnd
    Material "diffuse" "rgb reflectance" [0.6 0.6 0.6]
    Shape "trianglemesh" "point3 P" [-50 0 -50  50 0 -50  50 0 50  -50 0 50] "integer indices" [0 1 2 0 2 3]
  )");
  auto lit_value = [](const Ray& r) {
    if (r.d.y >= 0) return 0.0;
    Vec3 p = r.o + r.d * (-r.o.y / r.d.y);
    Vec3 to_light = Vec3(0.5f, 3, 0.3f) - p;
    double d2 = length_squared(to_light);
    return 0.5 * 0.6 / M_PI * 3 * (to_light.y / std::sqrt(d2)) / d2;
  };
  // Neither scene has caustic or indirect light for bpm's backward photons to gather, so its
  // light pass would trace its largest number of batches in every iteration; one is enough.
  struct Case {
    const LoadedScene* ls;
    std::function<double(const Ray&)> value;
    const char* name;
  };
  for (const Case& c : {Case{&sheet, sheet_value, "sheet"}, Case{&lit, lit_value, "lit"}}) {
    Camera cam(c.ls->camera, 16, 16);
    for (const char* integrator : {"path", "bpm", "fpm"}) {
      Film film(16, 16);
      RenderOptions opt = quiet_options(*c.ls, integrator, 64, 1);
      opt.bpm.photons_per_iteration = 20000;
      opt.fpm.photons_per_iteration = 20000;
      render(*c.ls, opt, &film);
      Image img = film.image();
      std::vector<float> rms = film.rms();
      double sum_diff = 0, sum_var = 0;
      for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
          double expected = pixel_mean(cam, x, y, c.value);
          // A pixel where few samples meet the mask may see none blocked, and then estimates a
          // variance of zero: the Bernoulli variance of one camera ray's outcome, over the
          // number of passes, bounds the noise from below.
          double blocked = c.name == std::string("sheet") ? 1 - expected : 0.5;
          double value = c.name == std::string("sheet") ? 1 : 2 * expected;
          double sigma = std::max(double(rms[size_t(y) * 16 + x]),
                                  value * std::sqrt(blocked * (1 - blocked) / 64));
          EXPECT_NEAR(img.at(x, y).luminance(), expected, 5 * sigma + 2e-3 * expected)
              << c.name << " " << integrator << " " << x << "," << y;
          sum_diff += img.at(x, y).luminance() - expected;
          sum_var += sigma * sigma;
        }
      EXPECT_NEAR(sum_diff, 0, 4 * std::sqrt(sum_var) + 1e-3) << c.name << " " << integrator;
    }
  }
}

// A diffuse plane (rho = 0.5) facing the light's +z under an environment image normalised by
// "illuminance" 2: the plane's luminance is rho / pi * 2 wherever the image's light comes from,
// since light from below the horizon cannot reach it. Both layouts, path and bpm (direct light by
// sampling the image and by the BSDF, weighed by MIS). The same camera then looks at the sky: a
// pixel shows the texel its ray points at.
TEST(Integrators, DiffusePlaneUnderEnvironmentImage) {
  for (bool equal_area : {true, false}) {
    std::string exr = write_environment_exr("bpm_env", equal_area ? 16 : 32, 16);
    LoadedScene ls = load(R"(
      LookAt 0 0 3  0 0 0  0 1 0
      Camera "perspective" "float fov" 40
      Film "rgb" "integer xresolution" 12 "integer yresolution" 12
      PixelFilter "box" "float xradius" 0.5 "float yradius" 0.5
      Integrator "path" "integer maxdepth" 1
      WorldBegin
      LightSource "infinite" "string filename" ")" +
                          exr + R"(" "float illuminance" 2
      Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
      Shape "trianglemesh" "point3 P" [-50 -50 0  50 -50 0  50 50 0  -50 50 0] "integer indices" [0 1 2 0 2 3]
    )");
    const double expected = 0.5 / M_PI * 2;
    for (const char* integrator : {"path", "bpm"}) {
      Film film(12, 12);
      RenderOptions opt = quiet_options(ls, integrator, 64, 1);
      opt.bpm.photons_per_iteration = 20000;
      render(ls, opt, &film);
      Image img = film.image();
      std::vector<float> rms = film.rms();
      double sum = 0, var = 0;
      for (int i = 0; i < 144; ++i) {
        double lum = img.at(i % 12, i / 12).luminance();
        EXPECT_NEAR(lum, expected, 5 * rms[size_t(i)] + 1e-3)
            << integrator << " " << equal_area << " pixel " << i;
        sum += lum;
        var += double(rms[size_t(i)]) * rms[size_t(i)];
      }
      EXPECT_NEAR(sum / 144, expected, 4 * std::sqrt(var) / 144 + 1e-3)
          << integrator << " " << equal_area;
    }
    // Looking up from below the plane's edge: the sky, texel by texel.
    LoadedScene sky = load(R"(
      LookAt 0 0 0  0.3 0.2 1  0 1 0
      Camera "perspective" "float fov" 60
      Film "rgb" "integer xresolution" 12 "integer yresolution" 12
      PixelFilter "box" "float xradius" 0.0001 "float yradius" 0.0001
      WorldBegin
      LightSource "infinite" "string filename" ")" +
                           exr + R"(" "float scale" 1.5
    )");
    const auto& light = std::get<ImageInfiniteLight>(sky.scene.lights[0]);
    Film film(12, 12);
    render(sky, quiet_options(sky, "path", 16, 1), &film);
    Image img = film.image();
    std::vector<float> sky_rms = film.rms();
    Camera cam(sky.camera, 12, 12);
    for (int y = 0; y < 12; ++y)
      for (int x = 0; x < 12; ++x) {
        Vec3 d = normalize(cam.generate_ray({x + 0.5f, y + 0.5f}, {0.5f, 0.5f}).ray.d);
        Vec2 uv = image_light_uv(light, d);
        // pbrt-v4's image coordinates: (u, v) with v down the image's rows.
        Rgb texel = light.image->texel(
            std::min(int(uv.x * light.image->width), light.image->width - 1),
            std::min(int(uv.y * light.image->height), light.image->height - 1), TexWrap::kClamp);
        // The only noise is that of the sampled wavelengths (the sigmoid fit errs by < 0.2%).
        EXPECT_NEAR(img.at(x, y).luminance(), 1.5f * texel.luminance(),
                    5 * sky_rms[size_t(y) * 12 + x] + 0.005f * texel.luminance())
            << equal_area << " " << x << "," << y;
      }
    std::filesystem::remove(exr);
  }
}

// A diffuse plane (rho = 0.6) under image point lights, with path and bpm: a goniometric light of
// I = 3 with a constant image of 0.5 is a point light of intensity 1.5; a projection light of a
// constant white image pointing down lights the square its 90-degree frame cuts out of the plane
// with intensity "scale", and nothing outside.
TEST(Integrators, PlaneUnderGoniometricAndProjectionLights) {
  std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("bpm_gonio_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  Image flat;
  flat.width = flat.height = 8;
  flat.rgb.assign(8 * 8 * 3, 0.5f);
  write_exr((dir / "half.exr").string(), flat);
  flat.rgb.assign(8 * 8 * 3, 1.0f);
  write_exr((dir / "white.exr").string(), flat);
  const std::string head = R"(
    LookAt 0 5 -3  0 0 0  0 1 0
    Camera "perspective" "float fov" 50
    Film "rgb" "integer xresolution" 24 "integer yresolution" 16
    PixelFilter "box" "float xradius" 0.0001 "float yradius" 0.0001
    Integrator "path" "integer maxdepth" 1
    WorldBegin
    Material "diffuse" "rgb reflectance" [0.6 0.6 0.6]
    Shape "trianglemesh" "point3 P" [-50 0 -50  50 0 -50  50 0 50  -50 0 50] "integer indices" [0 1 2 0 2 3]
  )";
  LoadedScene gonio = load(head + R"(
    Translate 0.5 2 0.3
    LightSource "goniometric" "string filename" ")" +
                           (dir / "half.exr").string() + R"(" "rgb I" [3 3 3]
  )");
  LoadedScene proj = load(head + R"(
    Translate 0 2 0
    Rotate 90 1 0 0
    LightSource "projection" "string filename" ")" +
                          (dir / "white.exr").string() + R"(" "float scale" 2
  )");
  for (bool is_gonio : {true, false}) {
    const LoadedScene& ls = is_gonio ? gonio : proj;
    Vec3 light = is_gonio ? Vec3(0.5f, 2, 0.3f) : Vec3(0, 2, 0);
    float I = is_gonio ? 1.5f : 2.0f;
    Camera cam(ls.camera, 24, 16);
    for (const char* integrator : {"path", "bpm"}) {
      RenderOptions opt = quiet_options(ls, integrator, 16, 1);
      opt.bpm.photons_per_iteration = 20000;
      Film film(24, 16);
      render(ls, opt, &film);
      Image img = film.image();
      std::vector<float> rms = film.rms();
      int lit = 0, dark = 0;
      for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 24; ++x) {
          Ray r = cam.generate_ray({x + 0.5f, y + 0.5f}, {0.5f, 0.5f}).ray;
          if (r.d.y >= 0) continue;
          Vec3 p = r.o + r.d * (-r.o.y / r.d.y);
          float expected = 0;
          if (!is_gonio) {
            // The frame covers |x|, |z| < 2 on the plane; skip a band around its edge.
            float edge = std::fmax(std::fabs(p.x), std::fabs(p.z));
            if (std::fabs(edge - 2) < 0.1f) continue;
            if (edge > 2) {
              EXPECT_EQ(img.at(x, y).luminance(), 0.0f) << integrator << " " << x << "," << y;
              ++dark;
              continue;
            }
          }
          Vec3 to_light = light - p;
          float d2 = length_squared(to_light);
          expected = 0.6f / kPi * I * (to_light.y / std::sqrt(d2)) / d2;
          EXPECT_NEAR(img.at(x, y).luminance(), expected,
                      5 * rms[size_t(y) * 24 + x] + 2e-3f * expected)
              << (is_gonio ? "goniometric " : "projection ") << integrator << " " << x << "," << y;
          ++lit;
        }
      EXPECT_GT(lit, 40);
      if (!is_gonio) {
        EXPECT_GT(dark, 40);
      }
    }
  }
  std::filesystem::remove_all(dir);
}

// An image area light (pbrt-v4's "filename" on a diffuse area light) seen face on: each pixel
// shows the image bilinearly filtered at (u, 1 - v), times scale, so the image appears upright on
// a quad whose v runs up.
TEST(PathIntegrator, ImageAreaLightShowsItsImage) {
  std::filesystem::path exr = std::filesystem::temp_directory_path() /
                              ("bpm_area_image_" + std::to_string(::getpid()) + ".exr");
  Image img_in;
  img_in.width = 4;
  img_in.height = 3;
  for (int i = 0; i < 12; ++i)
    for (int c = 0; c < 3; ++c) img_in.rgb.push_back(0.1f + 0.15f * i + 0.02f * c);
  write_exr(exr.string(), img_in);
  LoadedScene ls = load(R"(
    LookAt 0 0 -4  0 0 0  0 1 0
    Camera "perspective" "float fov" 30
    Film "rgb" "integer xresolution" 16 "integer yresolution" 16
    PixelFilter "box" "float xradius" 0.0001 "float yradius" 0.0001
    Integrator "path" "integer maxdepth" 1
    WorldBegin
    AreaLightSource "diffuse" "string filename" ")" +
                        exr.string() + R"(" "float scale" 2 "bool twosided" true
    Shape "trianglemesh" "point3 P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0] "integer indices" [0 1 2 0 2 3]
      "point2 uv" [0 0  1 0  1 1  0 1]
  )");
  std::filesystem::remove(exr);
  const auto& light = std::get<AreaLight>(ls.scene.lights[0]);
  Film film(16, 16);
  render(ls, quiet_options(ls, "path", 16, 1), &film);
  Image img = film.image();
  std::vector<float> rms = film.rms();
  Camera cam(ls.camera, 16, 16);
  int inside = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      Ray r = cam.generate_ray({x + 0.5f, y + 0.5f}, {0.5f, 0.5f}).ray;
      Vec3 p = r.o + r.d * (-r.o.z / r.d.z);
      if (std::fabs(p.x) > 1 || std::fabs(p.y) > 1) continue;
      Vec2 uv((p.x + 1) / 2, (p.y + 1) / 2);
      // The image's top row at the quad's top (v = 1).
      float expected =
          2 *
          light.image->lookup({uv.x, 1 - uv.y}, TexFilter::kBilinear, TexWrap::kClamp).luminance();
      EXPECT_NEAR(img.at(x, y).luminance(), expected,
                  5 * rms[size_t(y) * 16 + x] + 0.005f * expected)
          << x << "," << y;
      ++inside;
    }
  EXPECT_GT(inside, 150);
  // Brighter rows lower in the file: the bottom of the quad is brighter than its top.
  EXPECT_GT(img.at(8, 13).luminance(), img.at(8, 2).luminance() * 1.5f);
}

// The film's clamp (maxcomponentvalue) holds for debiased estimates too, which may be negative:
// on the largest magnitude, keeping the sign and the colour's proportions.
TEST(Film, RecordPassClampsDebiasedEstimates) {
  const Wavelengths wl = sample_wavelengths(0.3f);
  for (float v : {-1e6f, 1e6f, -2.0f}) {
    Film film(1, 1);
    record_pass(&film, 0, Spectrum(v), wl, 1, 10, true);
    const Rgb c = film.image().at(0, 0);
    const float m = std::fmax(c.max_component(), -c.min_component());
    if (std::fabs(v) > 100) {
      EXPECT_NEAR(m, 10, 1e-3) << v;
    } else {
      EXPECT_LT(m, 10) << v;
    }
    EXPECT_EQ(c[1] < 0, v < 0) << v;
  }
}

// A pixel's stream_uniform over the passes of one stream (pass j in stream j mod
// Film::kStreams) puts the stream's first 2^k passes one in each interval of width 2^-k; pixels
// and streams have scrambles of their own.
TEST(CameraSampler, StreamUniformStratifiesTheStreamsPasses) {
  const CameraSampler camera(CameraSettings{}, FilterSettings{}, 8, 8, 3);
  for (uint32_t pixel : {0u, 9u, 63u}) {
    std::vector<float> first(Film::kStreams);
    for (int stream = 0; stream < Film::kStreams; ++stream) {
      constexpr int k = 6, n = 1 << k;
      std::vector<int> hits(n, 0);
      for (int t = 0; t < n; ++t) {
        const float u = camera.stream_uniform(t * Film::kStreams + stream, pixel);
        ASSERT_GE(u, 0.0f);
        ASSERT_LT(u, 1.0f);
        ++hits[size_t(u * n)];
      }
      for (int j = 0; j < n; ++j) EXPECT_EQ(hits[size_t(j)], 1) << pixel << " " << stream;
      first[size_t(stream)] = camera.stream_uniform(stream, pixel);
    }
    std::sort(first.begin(), first.end());
    EXPECT_EQ(std::unique(first.begin(), first.end()), first.end()) << pixel;
    EXPECT_NE(camera.stream_uniform(0, pixel), camera.stream_uniform(0, pixel + 1)) << pixel;
  }
}

// Same seed and budget give the same image whatever the number of threads.
TEST(Renderer, SameImageWithOneAndTwoThreads) {
  LoadedScene ls = load(R"(
    LookAt 0.5 0.5 -1.2  0.5 0.5 0  0 1 0
    Camera "perspective" "float fov" 45
    Film "rgb" "integer xresolution" 40 "integer yresolution" 30
    Integrator "path" "integer maxdepth" 6
    WorldBegin
    Material "diffuse" "rgb reflectance" [0.7 0.6 0.5]
    Shape "bilinearmesh" "point3 P" [0 0 0  1 0 0  0 0 1  1 0 1]
    Shape "bilinearmesh" "point3 P" [0 0 1  1 0 1  0 1 1  1 1 1]
    Material "dielectric"
    AttributeBegin
      Translate 0.5 0.2 0.5
      Shape "sphere" "float radius" 0.2
    AttributeEnd
    AttributeBegin
      AreaLightSource "diffuse" "rgb L" [4 4 4]
      Shape "bilinearmesh" "point3 P" [0.3 0.9 0.3  0.7 0.9 0.3  0.3 0.9 0.7  0.7 0.9 0.7]
    AttributeEnd
  )");
  Image a = render_film(ls, 8, 1, 7).image();
  Image b = render_film(ls, 8, 2, 7).image();
  Image c = render_film(ls, 8, 2, 8).image();
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  EXPECT_EQ(a.rgb, b.rgb);
  EXPECT_NE(a.rgb, c.rgb);  // and the seed matters
}

// Light emitted by a one-sided area light leaves only the side its normal faces.
TEST(PathIntegrator, OneSidedAreaLightEmitsOnItsNormalSide) {
  const char* tmpl = R"(
    LookAt 0 0 -3  0 0 0  0 1 0
    Camera "perspective" "float fov" 20
    Film "rgb" "integer xresolution" 4 "integer yresolution" 4
    PixelFilter "box"
    WorldBegin
    AreaLightSource "diffuse" "rgb L" [2 2 2]
    %s
    Shape "disk" "float radius" 5
  )";
  char a[1024], b[1024];
  std::snprintf(a, sizeof a, tmpl,
                "Rotate 180 0 1 0");  // disk normal +z rotated to face the camera
  std::snprintf(b, sizeof b, tmpl, "");
  Film front = render_film(load(a), 64);
  EXPECT_NEAR(front.image().at(1, 1).luminance(), 2.0f, 4.5f * front.rms()[5] + 1e-5f);
  EXPECT_EQ(render_film(load(b), 16).image().at(1, 1).max_component(), 0.0f);
}

}  // namespace
}  // namespace bpm
