// Tests of reading texture images from files of each kind (decoding, channels, errors). They write
// their images with OpenImageIO, so they are their own test program (bpm_image_tests): the other
// tests do not link it (see image_file.h).
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "base/error.h"
#include "textures/texture.h"

namespace bpm {
namespace {

namespace fs = std::filesystem;

class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("bpm_texture_test_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

// Writes float values (width * height * channels, rows from the top) in the file's format,
// converted to 8 bits for 8-bit formats.
void write_image(const std::string& path, int w, int h, int channels, OIIO::TypeDesc format,
                 const std::vector<float>& v) {
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out) << OIIO::geterror();
  OIIO::ImageSpec spec(w, h, channels, format);
  ASSERT_TRUE(out->open(path, spec)) << out->geterror();
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, v.data())) << out->geterror();
  out->close();
}

float srgb_decode(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}
float byte(float v) { return std::round(v * 255) / 255; }

const std::vector<float> kPixels = {0.2f, 0.5f, 1.0f, 0.0f, 0.25f, 0.75f};  // 2 x 1, RGB

TEST(TextureImage, EightBitFormatsAreDecodedWithTheirEncoding) {
  TempDir dir;
  for (const char* ext : {"png", "tga"}) {
    std::string path = dir.file(std::string("a.") + ext);
    write_image(path, 2, 1, 3, OIIO::TypeDesc::UINT8, kPixels);
    auto srgb = load_texture_image(path, TexEncoding{TexEncoding::Kind::kSrgb, 0});
    auto linear = load_texture_image(path, TexEncoding{TexEncoding::Kind::kLinear, 0});
    auto gamma = load_texture_image(path, TexEncoding{TexEncoding::Kind::kGamma, 2.0f});
    ASSERT_EQ(srgb->width, 2);
    ASSERT_EQ(srgb->height, 1);
    ASSERT_EQ(srgb->channels, 3);
    for (size_t i = 0; i < kPixels.size(); ++i) {
      EXPECT_NEAR(srgb->texels[i], srgb_decode(byte(kPixels[i])), 1e-6f) << ext << " " << i;
      EXPECT_NEAR(linear->texels[i], byte(kPixels[i]), 1e-6f) << ext << " " << i;
      EXPECT_NEAR(gamma->texels[i], byte(kPixels[i]) * byte(kPixels[i]), 1e-6f) << ext << " " << i;
    }
  }
  // JPEG is lossy: near the values.
  std::string jpg = dir.file("a.jpg");
  write_image(jpg, 2, 1, 3, OIIO::TypeDesc::UINT8, kPixels);
  auto j = load_texture_image(jpg, TexEncoding{TexEncoding::Kind::kLinear, 0});
  EXPECT_EQ(j->width, 2);
  EXPECT_NEAR(j->texels[1], 0.5f, 0.15f);
}

TEST(TextureImage, FloatFormatsAreLinearAndUnbounded) {
  TempDir dir;
  const std::vector<float> v = {3.5f, 0.1f, 0.02f, 7.0f, 0.0f, 1.25f};
  std::string exr = dir.file("f.exr");
  write_image(exr, 2, 1, 3, OIIO::TypeDesc::FLOAT, v);
  // PFM by hand (OpenImageIO reads it but does not write it): little-endian (negative scale),
  // rows from the bottom; two rows here, the top one v and the bottom one v / 2.
  std::string pfm = dir.file("f.pfm");
  {
    std::ofstream f(pfm, std::ios::binary);
    f << "PF\n2 2\n-1.0\n";
    for (float x : v) {
      float h = x / 2;
      f.write(reinterpret_cast<const char*>(&h), 4);
    }
    f.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * 4));
  }
  for (const std::string& path : {exr, pfm}) {
    auto img = load_texture_image(path, TexEncoding{TexEncoding::Kind::kSrgb, 0});  // ignored
    ASSERT_EQ(img->width, 2);
    for (size_t i = 0; i < v.size(); ++i) EXPECT_FLOAT_EQ(img->texels[i], v[i]) << path << " " << i;
  }
  auto p = load_texture_image(pfm, TexEncoding{});
  ASSERT_EQ(p->height, 2);
  EXPECT_FLOAT_EQ(p->texel(1, 1, TexWrap::kClamp)[2], 1.25f / 2);
  // One channel stays one channel and reads as grey.
  std::string grey = dir.file("g.exr");
  write_image(grey, 1, 1, 1, OIIO::TypeDesc::FLOAT, {0.3f});
  auto g = load_texture_image(grey, TexEncoding{});
  EXPECT_EQ(g->channels, 1);
  EXPECT_FLOAT_EQ(g->texel(0, 0, TexWrap::kRepeat)[2], 0.3f);
}

TEST(TextureImage, MissingAndCorruptFilesAreErrorsNamingThem) {
  TempDir dir;
  std::string missing = dir.file("none.png");
  try {
    load_texture_image(missing, TexEncoding{});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  std::string bad = dir.file("bad.png");
  std::ofstream(bad) << "not an image";
  EXPECT_THROW(load_texture_image(bad, TexEncoding{}), Error);
}

}  // namespace
}  // namespace bpm
