// Tests of texture images (filtering, wrapping), mappings and texture nodes; reading image files
// is tested in image_file_oiio_test.cpp.
#include "textures/texture.h"

#include <gtest/gtest.h>

#include <cmath>

#include "base/error.h"

namespace bpm {
namespace {

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
  // A float texture reads the mean of the channels (as pbrt-v4 does), scaled, then inverted.
  EXPECT_FLOAT_EQ(ts.value(plain, ctx), (0.7f + 0.3f + 0.1f) / 3);
  EXPECT_FLOAT_EQ(ts.value(scaled, ctx), 0.5f * (0.7f + 0.3f + 0.1f) / 3);
  EXPECT_FLOAT_EQ(ts.value(inverted, ctx), 1 - (0.7f + 0.3f + 0.1f) / 3);
}

}  // namespace
}  // namespace bpm
