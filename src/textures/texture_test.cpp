// Tests of texture images (reading, decoding, filtering, wrapping), mappings and texture nodes.
#include "textures/texture.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "base/error.h"

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

// A 2 x 2 image: (0, 1 / 2, 3) in row order, grey.
TexImage two_by_two() {
  TexImage img;
  img.width = img.height = 2;
  img.channels = 1;
  img.texels = {0, 1, 2, 3};
  return img;
}

TEST(TextureImage, PointAndBilinearLookups) {
  TexImage img = two_by_two();
  auto at = [&](float s, float t, TexFilter f, TexWrap w) { return img.lookup({s, t}, f, w)[0]; };
  // Texel centres give the texels; between them, the bilinear blend.
  EXPECT_FLOAT_EQ(at(0.25f, 0.25f, TexFilter::kBilinear, TexWrap::kClamp), 0);
  EXPECT_FLOAT_EQ(at(0.75f, 0.75f, TexFilter::kBilinear, TexWrap::kClamp), 3);
  EXPECT_FLOAT_EQ(at(0.5f, 0.5f, TexFilter::kBilinear, TexWrap::kClamp), 1.5f);
  EXPECT_FLOAT_EQ(at(0.5f, 0.25f, TexFilter::kBilinear, TexWrap::kClamp), 0.5f);
  EXPECT_FLOAT_EQ(at(0.3f, 0.7f, TexFilter::kPoint, TexWrap::kClamp), 2);
  // Wrapping: repeat blends across the edge, clamp holds the edge, black fades to zero.
  EXPECT_FLOAT_EQ(at(0.0f, 0.25f, TexFilter::kBilinear, TexWrap::kRepeat), 0.5f);
  EXPECT_FLOAT_EQ(at(0.0f, 0.25f, TexFilter::kBilinear, TexWrap::kClamp), 0.0f);
  EXPECT_FLOAT_EQ(at(1.0f, 0.25f, TexFilter::kBilinear, TexWrap::kBlack), 0.5f);
  EXPECT_FLOAT_EQ(at(1.25f, 0.25f, TexFilter::kPoint, TexWrap::kRepeat), 0);
  EXPECT_FLOAT_EQ(at(1.25f, 0.25f, TexFilter::kPoint, TexWrap::kBlack), 0);
  EXPECT_FLOAT_EQ(at(-0.25f, 0.75f, TexFilter::kPoint, TexWrap::kRepeat), 3);
  // The octahedral fold mirrors across the edge's middle.
  EXPECT_FLOAT_EQ(img.texel(-1, 0, TexWrap::kOctahedralSphere)[0],
                  img.texel(0, 1, TexWrap::kRepeat)[0]);
  EXPECT_FLOAT_EQ(img.texel(1, -1, TexWrap::kOctahedralSphere)[0],
                  img.texel(0, 0, TexWrap::kRepeat)[0]);
  EXPECT_FLOAT_EQ(img.texel(2, 1, TexWrap::kOctahedralSphere)[0],
                  img.texel(1, 0, TexWrap::kRepeat)[0]);
}

TEST(TextureMapping, UvSphericalCylindricalPlanar) {
  TextureContext ctx{{0, 3, 0}, {0.25f, 0.5f}};
  TexMapping uv;
  uv.su = 2, uv.sv = 3, uv.du = 0.5f, uv.dv = -1;
  Vec2 st = uv.map(ctx);
  EXPECT_FLOAT_EQ(st.x, 1.0f);
  EXPECT_FLOAT_EQ(st.y, 0.5f);

  TexMapping sph;
  sph.kind = TexMapping::Kind::kSpherical;
  st = sph.map(ctx);  // +y: theta = pi/2, phi = pi/2
  EXPECT_NEAR(st.x, 0.5f, 1e-6f);
  EXPECT_NEAR(st.y, 0.25f, 1e-6f);
  sph.texture_from_world = Transform::translate(Vec3(0, -3, 1));  // the point is now at +z
  EXPECT_NEAR(sph.map(ctx).x, 0.0f, 1e-6f);

  TexMapping cyl;
  cyl.kind = TexMapping::Kind::kCylindrical;
  st = cyl.map(TextureContext{{1, 0, 2}, {}});
  EXPECT_NEAR(st.x, 0.5f, 1e-6f);
  EXPECT_NEAR(st.y, 2.0f, 1e-6f);

  TexMapping pl;
  pl.kind = TexMapping::Kind::kPlanar;
  pl.vs = {0, 0, 1}, pl.vt = {1, 1, 0}, pl.ds = 0.5f, pl.dt = 1;
  st = pl.map(TextureContext{{2, 3, 4}, {}});
  EXPECT_FLOAT_EQ(st.x, 4.5f);
  EXPECT_FLOAT_EQ(st.y, 6.0f);
}

TEST(TextureSet, CheckerboardScaleAndMix) {
  TextureSet ts;
  Wavelengths wl = sample_wavelengths(0.4f);
  int a = ts.add(ConstantTexture{SpectrumCurve(0.2f), 0});
  int b = ts.add(ConstantTexture{SpectrumCurve(0.8f), 0});
  CheckerboardTexture c2;
  c2.tex1 = a, c2.tex2 = b;
  int checker = ts.add(c2);
  auto v = [&](int node, Vec3 p, Vec2 uv) {
    return ts.spectrum(node, TextureContext{p, uv}, wl)[0];
  };
  EXPECT_FLOAT_EQ(v(checker, {}, {0.5f, 0.5f}), 0.2f);
  EXPECT_FLOAT_EQ(v(checker, {}, {1.5f, 0.5f}), 0.8f);
  EXPECT_FLOAT_EQ(v(checker, {}, {-0.5f, 0.5f}), 0.8f);
  EXPECT_FLOAT_EQ(v(checker, {}, {-0.5f, -0.5f}), 0.2f);
  CheckerboardTexture c3 = c2;
  c3.dimension = 3;
  int checker3 = ts.add(c3);
  EXPECT_FLOAT_EQ(v(checker3, {0.5f, 0.5f, 0.5f}, {}), 0.2f);
  EXPECT_FLOAT_EQ(v(checker3, {0.5f, 1.5f, 0.5f}, {}), 0.8f);
  EXPECT_FLOAT_EQ(v(checker3, {0.5f, 1.5f, -0.5f}, {}), 0.2f);

  int half = ts.add(ConstantTexture{SpectrumCurve(), 0.5f});
  int quarter = ts.add(ConstantTexture{SpectrumCurve(), 0.25f});
  EXPECT_FLOAT_EQ(v(ts.add(ScaleTexture{b, half}), {}, {}), 0.4f);
  EXPECT_FLOAT_EQ(v(ts.add(MixTexture{a, b, quarter}), {}, {}), 0.75f * 0.2f + 0.25f * 0.8f);
  // Float nodes compose the same way; an amount that is itself a texture.
  CheckerboardTexture fc;
  fc.tex1 = half, fc.tex2 = quarter;
  int fchecker = ts.add(fc);
  EXPECT_FLOAT_EQ(ts.value(fchecker, TextureContext{{}, {1.5f, 0}}), 0.25f);
  int mix = ts.add(MixTexture{a, b, fchecker});
  EXPECT_FLOAT_EQ(v(mix, {}, {0.5f, 0}), 0.5f * 0.2f + 0.5f * 0.8f);
  EXPECT_FLOAT_EQ(v(mix, {}, {1.5f, 0}), 0.75f * 0.2f + 0.25f * 0.8f);
}

// An image texel becomes the spectrum of its colour: the same, wavelength by wavelength, as the
// scene-level fit of that colour; scale and invert apply before.
TEST(TextureSet, ImageTexelsBecomeTheirColoursSpectrum) {
  auto img = std::make_shared<TexImage>();
  img->width = img->height = 1;
  img->texels = {0.7f, 0.3f, 0.1f};
  TextureSet ts;
  ImageTexture it;
  it.image = img;
  int plain = ts.add(it);
  it.scale = 0.5f;
  int scaled = ts.add(it);
  it.scale = 1;
  it.invert = true;
  int inverted = ts.add(it);
  TextureContext ctx{{}, {0.3f, 0.6f}};
  for (float u : {0.05f, 0.4f, 0.8f}) {
    Wavelengths wl = sample_wavelengths(u);
    Spectrum want =
        SpectrumCurve::from_rgb(Rgb(0.7f, 0.3f, 0.1f), SpectrumKind::kAlbedo).sample(wl);
    Spectrum want_half =
        SpectrumCurve::from_rgb(Rgb(0.35f, 0.15f, 0.05f), SpectrumKind::kAlbedo).sample(wl);
    Spectrum want_inv =
        SpectrumCurve::from_rgb(Rgb(0.3f, 0.7f, 0.9f), SpectrumKind::kAlbedo).sample(wl);
    Spectrum got = ts.spectrum(plain, ctx, wl), half = ts.spectrum(scaled, ctx, wl),
             inv = ts.spectrum(inverted, ctx, wl);
    for (int i = 0; i < Spectrum::kChannels; ++i) {
      EXPECT_NEAR(got[i], want[i], 0.01f) << wl.lambda[i];
      EXPECT_NEAR(half[i], want_half[i], 0.01f) << wl.lambda[i];
      EXPECT_NEAR(inv[i], want_inv[i], 0.01f) << wl.lambda[i];
    }
  }
  // A float texture reads the first channel.
  EXPECT_FLOAT_EQ(ts.value(plain, ctx), 0.7f);
}

}  // namespace
}  // namespace bpm
