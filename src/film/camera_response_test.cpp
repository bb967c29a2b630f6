// Named camera sensors: pbrt-v4's names, white balance by the fit, colours near the CIE
// observer's.
#include "film/camera_response.h"

#include <gtest/gtest.h>

#include <cmath>

namespace bpm {
namespace {

// L at the wavelengths of a uniform stratified sample of [kLambdaMin, kLambdaMax], many times:
// the exact colour up to the quadrature.
template <class F, class Conv>
Rgb colour_of(F&& spectrum, Conv&& to_rgb) {
  Rgb sum;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const Wavelengths wl =
        sample_wavelengths_uniform((float(i) + 0.5f) / n, kLambdaMin, kLambdaMax);
    Spectrum L;
    for (int k = 0; k < Spectrum::kChannels; ++k) L[k] = spectrum(wl.lambda[size_t(k)]);
    sum += to_rgb(L, wl);
  }
  return sum / float(n);
}

TEST(CameraResponse, NamesArePbrtV4s) {
  const std::vector<std::string> names = CameraResponse::names();
  EXPECT_EQ(names.size(), 17u);
  EXPECT_EQ(names.front(), "canon_eos_100d");
  EXPECT_EQ(names.back(), "sony_ilce_9");
  EXPECT_FALSE(CameraResponse::named("cie1931", 6500));
  EXPECT_FALSE(CameraResponse::named("leica_m", 6500));
}

// The fit maps a white lit by the white-balance illuminant to the white of sRGB, at the light's
// luminance: every camera balances daylight and tungsten (a blackbody at 3000 K) to grey.
TEST(CameraResponse, WhiteUnderTheBalanceIlluminantIsNeutral) {
  for (const std::string& name : CameraResponse::names())
    for (float kelvin : {3000.0f, 6500.0f}) {
      const CameraResponse r = *CameraResponse::named(name, kelvin);
      auto light = [&](float l) { return daylight_spectrum(kelvin, l); };
      const Rgb camera = colour_of(
          light, [&](const Spectrum& L, const Wavelengths& wl) { return r.to_rgb(L, wl); });
      const float y = colour_of(light, [](const Spectrum& L, const Wavelengths& wl) {
        return Rgb(spectrum_to_luminance(L, wl), 0, 0);
      })[0];
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(camera[c] / y, 1, 0.03) << name << " " << kelvin << " K channel " << c;
    }
}

// Under D65, balanced for 6500 K, a camera sees a coloured reflectance about as the CIE observer
// does (the fit's residual: a few percent).
TEST(CameraResponse, ColoursUnderDaylightAreNearTheObservers) {
  const SpectrumCurve d65 = SpectrumCurve::from_rgb(Rgb(1, 1, 1), SpectrumKind::kIlluminant);
  for (Rgb colour : {Rgb(0.7f, 0.3f, 0.2f), Rgb(0.2f, 0.6f, 0.3f), Rgb(0.25f, 0.3f, 0.7f)}) {
    const SpectrumCurve refl = SpectrumCurve::from_rgb(colour, SpectrumKind::kAlbedo);
    auto lit = [&](float l) { return d65.value(l) * refl.value(l); };
    const Rgb cie = colour_of(
        lit, [](const Spectrum& L, const Wavelengths& wl) { return spectrum_to_rgb(L, wl); });
    for (const char* name : {"canon_eos_5d_mkiv", "nikon_d850", "sony_ilce_9"}) {
      const CameraResponse r = *CameraResponse::named(name, 6500);
      const Rgb camera =
          colour_of(lit, [&](const Spectrum& L, const Wavelengths& wl) { return r.to_rgb(L, wl); });
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(camera[c], cie[c], 0.05f) << name << " channel " << c;
    }
  }
}

}  // namespace
}  // namespace bpm
