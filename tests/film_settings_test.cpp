// The Film's crop ("cropwindow", "pixelbounds": the image is a crop of the camera's raster,
// rendered as the whole image renders those pixels), white balance ("whitebalance") and the
// spectral film.
#include <ImfChannelList.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfStringAttribute.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "base/error.h"
#include "film/image_io.h"
#include "test_util.h"

namespace bpm {
namespace {

std::string scene(const std::string& integrator, const std::string& film_extra) {
  return R"(LookAt 0 1 -3  0 0.3 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 24 "integer yresolution" 16 )" +
         film_extra + R"(
Integrator ")" +
         integrator +
         R"(" "integer maxdepth" 4
WorldBegin
LightSource "point" "point3 from" [1 2 -1] "rgb I" [5 5 5]
Material "diffuse" "rgb reflectance" [0.7 0.5 0.3]
Shape "sphere" "float radius" 0.5
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [-5 -0.5 -5  5 -0.5 -5  5 -0.5 5  -5 -0.5 5]
)";
}

Image render_image(const LoadedScene& ls, const std::string& integrator) {
  Film film(ls.film.width, ls.film.height);
  RenderOptions opt = quiet_options(ls, integrator, 8, 5);
  opt.adaptive = false;
  render(ls, opt, &film);
  return film.image();
}

// The crop's pixels are the whole image's, bit for bit (path: each pixel's random stream is keyed
// by its place in the full raster); pixelbounds naming the same pixels gives the same image.
TEST(Crop, CropRendersTheWholeImagesPixels) {
  const LoadedScene full = test::load(scene("path", ""));
  const LoadedScene crop = test::load(scene("path", "\"float cropwindow\" [0.25 0.75 0.5 0.25]"));
  ASSERT_EQ(crop.film.width, 12);
  ASSERT_EQ(crop.film.height, 4);
  EXPECT_EQ(crop.film.x0, 6);
  EXPECT_EQ(crop.film.y0, 4);
  const Image a = render_image(full, "path"), b = render_image(crop, "path");
  for (int y = 0; y < b.height; ++y)
    for (int x = 0; x < b.width; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(b.at(x, y)[c], a.at(x + 6, y + 4)[c]) << x << "," << y;
  const LoadedScene bounds = test::load(scene("path", "\"integer pixelbounds\" [6 18 4 8]"));
  EXPECT_EQ(render_image(bounds, "path").rgb, b.rgb);
}

// bpm renders a crop as it renders the whole image: the crop's mean agrees with the same pixels
// of a full render within their stated errors.
TEST(Crop, BpmCropAgreesWithTheWholeImage) {
  const LoadedScene full = test::load(scene("bpm", ""));
  const LoadedScene crop = test::load(scene("bpm", "\"integer pixelbounds\" [4 20 6 14]"));
  Film fa(full.film.width, full.film.height, Film::kStreams);
  Film fb(crop.film.width, crop.film.height, Film::kStreams);
  render(full, quiet_options(full, "bpm", 32, 5), &fa);
  render(crop, quiet_options(crop, "bpm", 32, 6), &fb);
  const Image a = fa.image(), b = fb.image();
  const std::vector<float> ea = fa.total_rms_rgb(), eb = fb.total_rms_rgb();
  double mean_a = 0, mean_b = 0, err = 0;
  for (int y = 0; y < b.height; ++y)
    for (int x = 0; x < b.width; ++x) {
      mean_a += a.at(x + 4, y + 6).luminance();
      mean_b += b.at(x, y).luminance();
      err += ea[3 * ((y + 6) * a.width + x + 4) + 1] + eb[3 * (y * b.width + x) + 1];
    }
  EXPECT_NEAR(mean_b, mean_a, 3 * err / std::sqrt(double(b.width * b.height)) + 1e-3 * mean_a);
}

// Bad crops are located errors; bounds past the raster are clamped to it.
TEST(Crop, BadCropsAreLocatedErrors) {
  auto error_of = [](const std::string& extra) {
    try {
      test::load(scene("path", extra));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of("\"float cropwindow\" [0 1 0]").find("4 values"), std::string::npos);
  EXPECT_NE(error_of("\"integer pixelbounds\" [5 5 0 4]").find("empty"), std::string::npos);
  EXPECT_NE(error_of("\"float cropwindow\" [0.5 0.5 0 1]").find("leaves no pixel"),
            std::string::npos);
  EXPECT_NE(
      error_of("\"float cropwindow\" [0 1 0 1] \"integer pixelbounds\" [0 4 0 4]").find("only one"),
      std::string::npos);
  EXPECT_NE(error_of("\"float cropwindow\" [0 1 0 1]").find(""), std::string::npos);
  const LoadedScene clamped = test::load(scene("path", "\"integer pixelbounds\" [-4 100 2 6]"));
  EXPECT_EQ(clamped.film.width, 24);
  EXPECT_EQ(clamped.film.x0, 0);
  EXPECT_EQ(clamped.film.height, 4);
}

}  // namespace
}  // namespace bpm

namespace bpm {
namespace {

// pbrt-v4's film "whitebalance": a white plane under a 3000 K blackbody renders neutral when the
// film is balanced for 3000 K (pbrt-v4 takes a blackbody's white below 4000 K), and orange when it
// is not; a balance for D65's temperature changes nothing.
TEST(WhiteBalance, BalancedFilmRendersTheLightsWhiteNeutral) {
  auto mean_colour = [](const std::string& film_extra, const char* integrator = "path") {
    const LoadedScene ls = test::load(R"(LookAt 0 0 3  0 0 0  0 1 0
Camera "perspective" "float fov" 20
Film "rgb" "integer xresolution" 8 "integer yresolution" 8 )" +
                                      film_extra + R"(
Integrator "path" "integer maxdepth" 1
WorldBegin
LightSource "distant" "point3 from" [0 0 1] "point3 to" [0 0 0] "blackbody L" 3000
Material "diffuse" "rgb reflectance" [1 1 1]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point3 P" [-5 -5 0  5 -5 0  5 5 0  -5 5 0]
)");
    Film film(ls.film.width, ls.film.height);
    render(ls, quiet_options(ls, integrator, 16, 1), &film);
    const Image img = film.image();
    Rgb sum(0, 0, 0);
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) sum += img.at(x, y);
    return sum;
  };
  const Rgb balanced = mean_colour("\"float whitebalance\" 3000");
  EXPECT_NEAR(balanced[0] / balanced[1], 1, 0.01);
  EXPECT_NEAR(balanced[2] / balanced[1], 1, 0.01);
  const Rgb raw = mean_colour("");
  EXPECT_GT(raw[0] / raw[2], 2);
  const std::array<float, 9> m = white_balance_srgb(6504);
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(m[size_t(i)], i % 4 == 0 ? 1 : 0, 5e-3) << i;
  // A named camera sensor balanced for the light renders it neutral too, through every
  // integrator; unbalanced (6500 K, a named sensor's default) it renders it orange.
  for (const char* integrator : {"path", "bpm", "fpm"}) {
    const Rgb camera =
        mean_colour("\"string sensor\" \"nikon_d850\" \"float whitebalance\" 3000", integrator);
    EXPECT_NEAR(camera[0] / camera[1], 1, 0.03) << integrator;
    EXPECT_NEAR(camera[2] / camera[1], 1, 0.03) << integrator;
    EXPECT_NEAR(camera[1] / balanced[1], 1, 0.03) << integrator;  // the same exposure
  }
  const Rgb camera_raw = mean_colour("\"string sensor\" \"nikon_d850\"");
  EXPECT_GT(camera_raw[0] / camera_raw[2], 2);
  EXPECT_THROW(mean_colour("\"string sensor\" \"leica_m\""), Error);
}

// A spectral film seeing an infinite light of a constant spectrum (normalised, as pbrt-v4 does, to
// unit luminance: 1 at every wavelength): every bucket of every pixel reads 1, in every
// integrator, the colour is that spectrum's (the equal-energy white in sRGB); wavelengths fall
// in the buckets of their range, the ends clamped.
TEST(SpectralFilm, ConstantSpectrumFillsEveryBucket) {
  const SpectralBuckets b{5, 400, 700};
  EXPECT_EQ(b.bucket(399), 0);
  EXPECT_EQ(b.bucket(459.9f), 0);
  EXPECT_EQ(b.bucket(460.1f), 1);
  EXPECT_EQ(b.bucket(701), 4);
  for (const char* integrator : {"path", "bpm", "fpm"}) {
    LoadedScene ls = test::load(R"(LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" 30
Film "spectral" "integer xresolution" 4 "integer yresolution" 4 "integer nbuckets" 5
  "float lambdamin" 400 "float lambdamax" 700
WorldBegin
LightSource "infinite" "spectrum L" [300 2  900 2]
)");
    ASSERT_EQ(ls.film.spectral, b);
    Film film(ls.film.width, ls.film.height);
    render(ls, quiet_options(ls, integrator, 8, 3), &film);
    for (int k = 0; k < b.count; ++k)
      for (float v : film.bucket_image(k)) EXPECT_NEAR(v, 1, 1e-5) << integrator << " " << k;
    const Image img = film.image();
    // Equal energy in linear sRGB: (1.2, 0.95, 0.91) at unit luminance, within the colour noise
    // of 8 passes of 4 wavelengths.
    EXPECT_NEAR(img.at(1, 1)[0], 1.2, 0.06) << integrator;
    EXPECT_NEAR(img.at(1, 1)[2], 0.91, 0.06) << integrator;
  }
}

// The EXR holds pbrt-v4's spectral layout: S0.<centre>nm channels (decimal comma) after R, G, B,
// and the layout's attributes; bad spectral film parameters get located errors.
TEST(SpectralFilm, ExrChannelsAndErrors) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("bpm_spectral_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string scene_path = (dir / "s.pbrt").string(), out = (dir / "s.exr").string();
  {
    std::FILE* f = std::fopen(scene_path.c_str(), "w");
    std::fputs(
        R"(Film "spectral" "integer xresolution" 4 "integer yresolution" 2 "integer nbuckets" 2
WorldBegin
LightSource "infinite" "rgb L" [0.5 0.5 0.5]
)",
        f);
    std::fclose(f);
  }
  const std::string cmd = std::string(BPM_BINARY) + " render " + scene_path + " -q --spp 2 -o " +
                          out + " > /dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  Imf::InputFile exr(out.c_str());
  std::vector<std::string> names;
  for (auto c = exr.header().channels().begin(); c != exr.header().channels().end(); ++c)
    names.push_back(c.name());
  EXPECT_NE(std::find(names.begin(), names.end(), "S0.477,500nm"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "S0.712,500nm"), names.end());
  const auto* version =
      exr.header().findTypedAttribute<Imf::StringAttribute>("spectralLayoutVersion");
  ASSERT_TRUE(version);
  EXPECT_EQ(version->value(), "1.0");
  std::filesystem::remove_all(dir);
  auto error = [](const std::string& film) {
    try {
      test::load(film + "\nWorldBegin\n");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error(R"(Film "spectral" "integer nbuckets" 0)").find("nbuckets must be in [1, 1000]"),
            std::string::npos);
  EXPECT_NE(error(R"(Film "spectral" "float lambdamin" 700 "float lambdamax" 400)")
                .find("lambdamin and lambdamax must lie in [360, 830] nm"),
            std::string::npos);
  EXPECT_NE(error(R"(Film "spectral" "string filename" "a.png")").find("writes EXR only"),
            std::string::npos);
  EXPECT_NE(error(R"(Film "gbuffer")").find("film \"gbuffer\" is not supported (rgb, spectral)"),
            std::string::npos);
}

}  // namespace
}  // namespace bpm
