// Dispersion: a dielectric whose index is a spectrum sends each wavelength its own way, and from
// there on a path follows its hero wavelength alone (hero_wavelength_only).
#include <gtest/gtest.h>

#include <cmath>
#include <variant>

#include "base/rng.h"
#include "photons/light_path.h"
#include "test_util.h"

namespace bpm {
namespace {

using test::load;

// A collimated beam along +x enters a slab of glass-F11 at normal incidence through the face
// x = 1 and leaves through a face tilted by 30 degrees through (2, 0, 0) (outward normal
// (cos 30, sin 30, 0)), then lands on a screen at x = 5.
const char* kPrism = R"(
  LookAt 0 0 -10  0 0 0  0 1 0
  Camera "perspective"
  Film "rgb" "integer xresolution" [8] "integer yresolution" [8]
  WorldBegin
  LightSource "spot" "point3 from" [0 0 0] "point3 to" [1 0 0] "float coneangle" [0.3]
      "float conedeltaangle" [0] "rgb I" [1 1 1]
  AttributeBegin
    Material "dielectric" "spectrum eta" "glass-F11"
    Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
        "point3 P" [1 -1 -1  1 -1 1  1 1 1  1 1 -1]
    Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
        "point3 P" [2.57735 -1 -1  1.42265 1 -1  1.42265 1 1  2.57735 -1 1]
  AttributeEnd
  Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
      "point3 P" [5 -5 -5  5 5 -5  5 5 5  5 -5 5]
)";

// Snell's law, in vector form, for the beam leaving the glass through the tilted face.
double expected_screen_y(double n) {
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  double cos_t = std::sqrt(1 - n * n * (1 - c * c));
  // t = n d + (cos_t - n cos_i) normal, with d = (1, 0, 0) and normal = (c, s, 0).
  double tx = n + (cos_t - n * c) * c, ty = (cos_t - n * c) * s;
  return (5 - 2) / tx * ty;
}

TEST(Dispersion, PrismBendsEachWavelengthBySnellsLaw) {
  LoadedScene ls = load(kPrism);
  const int screen = 2;  // objects: the two glass faces, then the screen
  const auto& glass =
      std::get<DielectricMaterial>(ls.scene.materials[ls.scene.objects[0].material]);
  ASSERT_TRUE(glass.eta_spectrum);
  double previous_y = -1e9;  // longer wavelengths bend less: y grows with lambda
  for (float lambda : {420.0f, 480.0f, 550.0f, 620.0f, 700.0f}) {
    Wavelengths wl;
    for (int i = 0; i < Spectrum::kChannels; ++i) {
      wl.lambda[i] = lambda + 10.0f * float(i);
      wl.pdf[i] = 1;
    }
    const WavelengthMaterials wm(ls.scene, wl);
    double sum_y = 0, sum_w = 0;
    int hits = 0;
    LightCounters counters;
    for (uint64_t k = 0; k < 4000; ++k) {
      Rng rng(stream_key(7, k));
      const EmissionDraw e = unguided_emission(ls.scene, rng);
      trace_light_path(ls.scene, wm, 5, 1, e, rng, counters, [&](const PhotonHit& h) {
        if (h.object != screen) return;
        ++hits;
        EXPECT_TRUE(h.hero_only);
        for (int i = 1; i < Spectrum::kChannels; ++i) EXPECT_EQ(h.flux[i], 0.0f);
        sum_y += h.flux[0] * h.sp.p.y;
        sum_w += h.flux[0];
      });
    }
    ASSERT_GT(hits, 1000) << lambda;
    double n = glass.eta_spectrum->value(lambda);
    double y = sum_y / sum_w;
    // The cone's half angle of 0.3 degrees spreads the spot by about 0.05 either way.
    EXPECT_NEAR(y, expected_screen_y(n), 0.01) << "lambda " << lambda << " n " << n;
    EXPECT_GT(y, previous_y + 0.02) << lambda;
    previous_y = y;
  }
}

}  // namespace
}  // namespace bpm
