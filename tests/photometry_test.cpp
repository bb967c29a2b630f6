// Photometry in absolute units: the luminance channel Y (cd/m^2) of every integrator against
// closed forms, with lights stated in pbrt-v4's photometric terms (a light's "power" in lumens,
// "illuminance" in lux, emission spectra normalised to unit luminance). Each case compares the
// mean of Y over the image with its expected value within three of the film's own standard errors
// (taken as fully correlated between pixels, since the photon methods share an iteration's
// wavelengths and photons), plus 1e-3 for the spectral fit of a white reflectance.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include "base/sampling.h"
#include "film/image_io.h"
#include "lights/photometric_file.h"
#include "test_util.h"

namespace bpm {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The mean of Y over some pixels, its expected value, and the standard error of the mean: for
// path, whose pixels are independent, sqrt(sum of the pixels' variances) / n; for the photon
// methods, whose pixels share an iteration's wavelengths and photons, the mean of the pixels'
// standard errors (the bound for fully correlated errors).
struct Measured {
  double mean = 0, expected = 0, variance_sum = 0, error_sum = 0;
  int n = 0;
  void add(double y, double rms, double e) {
    mean += y;
    expected += e;
    variance_sum += rms * rms;
    error_sum += rms;
    ++n;
  }
  double error(const std::string& integrator) const {
    return integrator == "path" ? std::sqrt(variance_sum) / n : error_sum / n;
  }
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
      m.add(y[p], rms[p], expected(-1 + (2 * i + 1.0) / w, -1 + (2 * j + 1.0) / h));
    }
  return m;
}

void expect_agrees(const Measured& m, const std::string& integrator, double allowance = 1e-3) {
  const double mean = m.mean / m.n, expected = m.expected / m.n, error = m.error(integrator);
  EXPECT_NEAR(mean, expected, 3 * error + allowance * expected)
      << integrator << ": Y " << mean << " cd/m^2 against " << expected << " (standard error "
      << error << ")";
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

// The error the photon methods state is the error they make, though their iterations' wavelengths
// are stratified (which makes eq. 5 over iterations overstate it about 40 times here): a
// uniformly lit plane, whose pixels' only error is the spectral sampling's, over 16 seeds. The RMS
// of the stated errors (8 streams: 7 degrees of freedom each) and of the actual ones (16 degrees of
// freedom: within a factor 0.57 to 1.5 of the truth at 99%) agree within a factor 2.
TEST(Photometry, PhotonMethodsStateTheErrorTheyMake) {
  const std::string scene = plane_scene(
      "bpm",
      R"(LightSource "distant" "point3 from" [0 0 1] "point3 to" [0 0 0] "blackbody L" 3000 "float illuminance" 1000)",
      "0.5 0.5 0.5");
  LoadedScene ls = test::load(scene);
  const double expected = 0.5 * 1000 / kPi;
  double stated2 = 0, error2 = 0;
  constexpr int kSeeds = 16;
  for (int seed = 0; seed < kSeeds; ++seed) {
    Film film(ls.film.width, ls.film.height, Film::kStreams);
    render(ls, quiet_options(ls, "bpm", 32, uint64_t(seed + 1)), &film);
    const size_t centre = size_t(ls.film.height / 2) * ls.film.width + ls.film.width / 2;
    stated2 += std::pow(film.total_rms_luminance()[centre], 2);
    error2 += std::pow(film.luminance_image()[centre] - expected, 2);
  }
  const double ratio = std::sqrt(stated2 / error2);
  EXPECT_GT(ratio, 0.5) << "stated " << std::sqrt(stated2 / kSeeds) << ", made "
                        << std::sqrt(error2 / kSeeds);
  EXPECT_LT(ratio, 2.0) << "stated " << std::sqrt(stated2 / kSeeds) << ", made "
                        << std::sqrt(error2 / kSeeds);
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
                "path");
  const double rgb_luminance = 0.2126 * 1 + 0.7152 * 0.5 + 0.0722 * 0.25;
  expect_agrees(measure(emitter(R"("rgb L" [1 0.5 0.25])"), "path", 16,
                        [&](double, double) { return rgb_luminance; }),
                "path");
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

// ---- Luminaires from photometric files ----

namespace fs = std::filesystem;

// A scratch folder of the test's own.
fs::path scratch() {
  const fs::path dir =
      fs::temp_directory_path() / ("bpm_photometry_" + std::to_string(::getpid()) + "_" +
                                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Runs a command; its exit status, and what it printed on stdout and stderr.
std::pair<int, std::string> run(const std::string& cmd, const fs::path& dir) {
  const std::string out = (dir / "out.txt").string();
  const int status = std::system((cmd + " > " + out + " 2>&1").c_str());
  std::ifstream in(out);
  std::stringstream s;
  s << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, s.str()};
}

// An asymmetric type C luminaire (planes every 15 degrees, gamma every 5): a downlight whose
// light leans toward C 60, dark above 100 degrees.
double asymmetric_intensity(double c, double g) {
  if (g > 100) return 0;
  const double base = 800 * std::cos(g * 0.9 * kPi / 180);
  return std::max(0.0, base * (1 + 0.6 * std::cos((c - 60) * kPi / 180) * std::sin(g * kPi / 180)));
}

std::string asymmetric_ies() {
  std::ostringstream s;
  s << "IESNA:LM-63-2002\n[TEST] asymmetric\n[MANUFAC] bpm\n[LUMINAIRE] lean\nTILT=NONE\n"
    << "1 -1 1 37 25 1 2 0.2 0.2 0.05\n1 1 30\n";
  for (int j = 0; j <= 36; ++j) s << 5 * j << " ";
  s << "\n";
  for (int i = 0; i <= 24; ++i) s << 15 * i << " ";
  s << "\n";
  for (int i = 0; i <= 24; ++i) {
    for (int j = 0; j <= 36; ++j) s << asymmetric_intensity(15 * i, 5 * j) << " ";
    s << "\n";
  }
  return s.str();
}

// A camera 4 above a plane of reflectance 0.8, the luminaire 1.5 above it (nadir down, C 90
// toward +y), the given integrator.
std::string luminaire_scene(const std::string& file, const std::string& integrator, int size) {
  return R"(LookAt 0 0 4  0 0 0  0 1 0
Camera "perspective" "float fov" 70
Film "rgb" "integer xresolution" )" +
         std::to_string(size) + " \"integer yresolution\" " + std::to_string(size) + R"(
PixelFilter "box"
Integrator ")" +
         integrator +
         R"(" "integer maxdepth" 1
WorldBegin
AttributeBegin
  Translate 0 0 1.5
  Rotate 90 1 0 0
  LightSource "goniometric" "string filename" ")" +
         file + R"("
AttributeEnd
Material "diffuse" "rgb reflectance" [0.8 0.8 0.8]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point3 P" [-4 -4 0  4 -4 0  4 4 0  -4 4 0]
)";
}

// `bpm luminaire` writes the image pbrt-v4 reads and says how to place it; a goniometric light
// naming the IES file itself renders the very same image in bpm.
TEST(Photometry, LuminaireImageAndFileRenderAlike) {
  const fs::path dir = scratch();
  std::ofstream(dir / "lean.ies") << asymmetric_ies();
  auto [status, text] =
      run("cd " + dir.string() + " && " + BPM_BINARY + " luminaire lean.ies -o lean.exr", dir);
  ASSERT_EQ(status, 0) << text;
  EXPECT_NE(text.find("LightSource \"goniometric\" \"string filename\" \"lean.exr\""),
            std::string::npos)
      << text;
  const double flux = parse_ies(asymmetric_ies(), "lean.ies").luminous_flux();
  char printed[64];
  std::snprintf(printed, sizeof printed, "%.6g lm", flux);
  EXPECT_NE(text.find(printed), std::string::npos) << text;
  for (const char* file : {"lean.exr", "lean.ies"})
    std::ofstream(dir / (std::string(file) + ".pbrt")) << luminaire_scene(file, "bpm", 24);
  for (const char* file : {"lean.exr", "lean.ies"}) {
    auto [s, t] = run(std::string(BPM_BINARY) + " render " + (dir / file).string() +
                          ".pbrt --spp 4 -q -o " + (dir / file).string() + ".out.exr",
                      dir);
    ASSERT_EQ(s, 0) << t;
  }
  const Image a = read_exr((dir / "lean.exr.out.exr").string());
  const Image b = read_exr((dir / "lean.ies.out.exr").string());
  EXPECT_EQ(a.rgb, b.rgb);
  fs::remove_all(dir);
}

// The illuminance a luminaire gives follows its table: L = rho I(C, gamma) cos(gamma) / (pi r^2)
// on the plane below, for every integrator, with I read as the goniometric light reads it: the
// texel of the image (lights/photometric_file.h) toward the point. The luminaire hangs with
// "Rotate 90 1 0 0": nadir along -z, C 90 along world -y.
TEST(Photometry, LuminaireIlluminanceFollowsItsTable) {
  const fs::path dir = scratch();
  std::ofstream(dir / "lean.ies") << asymmetric_ies();
  const PhotometricData d = parse_ies(asymmetric_ies(), "lean.ies");
  const std::vector<float> image = goniometric_image(d, kLuminaireImageSize);
  const double half = 4 * std::tan(35 * kPi / 180);  // half the side of the plane seen
  auto expected = [&](double x, double y) {
    // The camera looks down -z with +y up; pbrt-v4's raster x runs toward -x of the world here.
    const double wx = -x * half, wy = -y * half, h = 1.5;
    const double r2 = wx * wx + wy * wy + h * h, r = std::sqrt(r2);
    // The direction in the light's frame (world = Rotate 90 about x of it), then pbrt-v4's
    // swap of y and z into the image's sphere.
    const Vec3 light(float(wx / r), float(-h / r), float(-wy / r));
    const Vec2 uv = equal_area_sphere_to_square(Vec3(light.x, light.z, light.y));
    const int n = kLuminaireImageSize;
    const int u = std::clamp(int(uv.x * n), 0, n - 1), v = std::clamp(int(uv.y * n), 0, n - 1);
    return 0.8 * image[size_t(v) * n + u] * (h / r) / r2 / kPi;
  };
  for (const char* integrator : {"path", "bpm", "fpm"}) {
    std::ofstream(dir / "s.pbrt") << luminaire_scene("lean.ies", integrator, 16);
    ParsedScene parsed = parse_scene_file((dir / "s.pbrt").string());
    LoadedScene ls = flatten_scene(parsed);
    Film film(ls.film.width, ls.film.height);
    render(ls, quiet_options(ls, integrator, 16, 3), &film);
    const std::vector<float> y = film.luminance_image(), rms = film.rms();
    // Per quadrant of the image: its mean against the table's (each pixel's over 8 x 8 points).
    for (int q = 0; q < 4; ++q) {
      Measured m;
      for (int j = 0; j < 16; ++j)
        for (int i = 0; i < 16; ++i) {
          if ((i >= 8) != bool(q & 1) || (j >= 8) != bool(q & 2)) continue;
          double e = 0;
          for (int a = 0; a < 8; ++a)
            for (int b = 0; b < 8; ++b)
              e += expected(-1 + (i + (a + 0.5) / 8) / 8, -1 + (j + (b + 0.5) / 8) / 8);
          m.add(y[size_t(j) * 16 + i], rms[size_t(j) * 16 + i], e / 64);
        }
      expect_agrees(m, integrator, 2e-3);
    }
  }
  fs::remove_all(dir);
}

// A malformed photometric file stops the render before anything is written, with its line.
TEST(Photometry, MalformedLuminaireIsALocatedError) {
  const fs::path dir = scratch();
  std::string ies = asymmetric_ies();
  ies.replace(ies.find("1 -1 1 37"), 9, "1 -1 0 37");  // a candela multiplier of 0
  std::ofstream(dir / "bad.ies") << ies;
  std::ofstream(dir / "s.pbrt") << luminaire_scene("bad.ies", "path", 8);
  auto [status, text] = run(std::string(BPM_BINARY) + " render " + (dir / "s.pbrt").string() +
                                " -q -o " + (dir / "s.exr").string(),
                            dir);
  EXPECT_EQ(status, 1);
  EXPECT_NE(text.find("bad.ies:6:6: the candela multiplier must be positive"), std::string::npos)
      << text;
  EXPECT_FALSE(fs::exists(dir / "s.exr"));
  fs::remove_all(dir);
}

// The same file in pbrt-v4 (with the image `bpm luminaire` wrote) and in bpm: the luminance of
// each quadrant of the image within 1% (the luminaire is asymmetric, so a turned or mirrored
// image would differ), when ../shared's pbrt-v4 is there and starts.
TEST(Photometry, LuminaireMatchesPbrtV4) {
  const std::string shared = test::shared_dir();
  const fs::path pbrt = fs::path(shared) / "tools" / "pbrt-v4" / "pbrt";
  if (shared.empty() || !fs::exists(pbrt)) GTEST_SKIP() << "no ../shared/tools/pbrt-v4/pbrt";
  const fs::path dir = scratch();
  if (run(pbrt.string() + " --help", dir).first != 0)
    GTEST_SKIP() << "pbrt-v4 does not start here (its libraries: see its README)";
  std::ofstream(dir / "lean.ies") << asymmetric_ies();
  ASSERT_EQ(run("cd " + dir.string() + " && " + BPM_BINARY + " luminaire lean.ies", dir).first, 0);
  std::ofstream(dir / "s.pbrt") << luminaire_scene("lean.exr", "path", 32);
  auto [status, text] = run(pbrt.string() + " --quiet --nthreads 2 --spp 64 --seed 3 --outfile " +
                                (dir / "pbrt.exr").string() + " " + (dir / "s.pbrt").string(),
                            dir);
  ASSERT_EQ(status, 0) << text;
  ASSERT_EQ(run(std::string(BPM_BINARY) + " render " + (dir / "s.pbrt").string() +
                    " --spp 64 -q -o " + (dir / "bpm.exr").string(),
                dir)
                .first,
            0);
  const Image a = read_exr((dir / "bpm.exr").string()), b = read_exr((dir / "pbrt.exr").string());
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  double ya[4] = {}, yb[4] = {};
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const int q = (x >= a.width / 2) + 2 * (y >= a.height / 2);
      const Rgb ca = a.at(x, y), cb = b.at(x, y);
      ya[q] += 0.2126 * ca[0] + 0.7152 * ca[1] + 0.0722 * ca[2];
      yb[q] += 0.2126 * cb[0] + 0.7152 * cb[1] + 0.0722 * cb[2];
    }
  for (int q = 0; q < 4; ++q) EXPECT_NEAR(ya[q] / yb[q], 1, 0.01) << "quadrant " << q;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace bpm
