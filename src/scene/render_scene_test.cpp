// The scene at one set of wavelengths (WavelengthMaterials): the emission spectra it evaluates once
// per iteration are those the lights give themselves, shared only between equal curves, and
// sampling with them changes no sample.
#include "scene/render_scene.h"

#include <gtest/gtest.h>

#include "base/rng.h"
#include "scene/flatten.h"
#include "scene/parsed_scene.h"

namespace bpm {
namespace {

// Two white quads (four triangle lights), a red one-sided quad (two), a point light, and a quad
// whose emission is an image (two).
LoadedScene lights_of_every_kind() {
  auto quad = [](float y) {
    const std::string s = std::to_string(y);
    return "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [-1 " + s +
           " -1  1 " + s + " -1  1 " + s + " 1  -1 " + s + " 1]\n";
  };
  return flatten_scene(parse_scene_string(
      "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\"\nFilm \"rgb\" \"integer xresolution\" 8 "
      "\"integer yresolution\" 8\nWorldBegin\n"
      "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [3 3 3] \"bool twosided\" true\n" +
      quad(3) + quad(4) +
      "AttributeEnd\n"
      "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [4 1 0.5]\n" +
      quad(5) +
      "AttributeEnd\n"
      "LightSource \"point\" \"rgb I\" [5 5 5] \"point3 from\" [0 2 0]\n"
      "AttributeBegin\nAreaLightSource \"diffuse\" \"string filename\" \"" +
      std::string(BPM_SOURCE_DIR) + "/scenes/textures/wood.png\"\n" + quad(6) + "AttributeEnd\n"));
}

TEST(WavelengthMaterials, LightSpectraAreTheLightsOwnAndSharedOnlyByEqualCurves) {
  const LoadedScene ls = lights_of_every_kind();
  const RenderScene& scene = ls.scene;
  ASSERT_EQ(scene.lights.size(), 9u);
  const WavelengthMaterials wm(scene, sample_wavelengths(0.41f));
  for (int i = 0; i < 9; ++i) {
    const auto* area = std::get_if<AreaLight>(&scene.lights[size_t(i)]);
    const Spectrum* s = wm.light_spectrum(i);
    if (!area || area->image) {
      EXPECT_EQ(s, nullptr) << "light " << i;
      continue;
    }
    ASSERT_NE(s, nullptr) << "light " << i;
    EXPECT_TRUE(s->c == area->radiance.sample(wm.wl).c) << "light " << i;
  }
  // The white quads' four triangles share one entry; the red quad has its own.
  EXPECT_EQ(wm.light_spectrum(0), wm.light_spectrum(3));
  EXPECT_NE(wm.light_spectrum(3), wm.light_spectrum(4));
  EXPECT_EQ(wm.light_spectrum(4), wm.light_spectrum(5));
  // A path's own materials evaluate nothing ahead.
  const WavelengthMaterials single = WavelengthMaterials::resolved_per_point(scene, wm.wl);
  EXPECT_EQ(single.light_spectrum(0), nullptr);
}

TEST(WavelengthMaterials, SamplingWithTheLightSpectraChangesNoSample) {
  const LoadedScene ls = lights_of_every_kind();
  const RenderScene& scene = ls.scene;
  const WavelengthMaterials wm(scene, sample_wavelengths(0.77f));
  Rng rng(stream_key(5, 0));
  int emitted = 0, back_facing = 0;
  for (int k = 0; k < 4000; ++k) {
    const int i = k % int(scene.lights.size());
    const Light& light = scene.lights[size_t(i)];
    const Vec2 u1{rng.uniform(), rng.uniform()}, u2{rng.uniform(), rng.uniform()};
    // Photons: the same sample with and without the light's spectrum given.
    auto a = light_sample_le(light, scene.light_shape(light), u1, u2, scene.bounds_info, wm.wl);
    auto b = light_sample_le(light, scene.light_shape(light), u1, u2, scene.bounds_info, wm.wl,
                             wm.light_spectrum(i));
    ASSERT_EQ(a.has_value(), b.has_value());
    if (a) {
      ASSERT_TRUE(a->flux.c == b->flux.c);
      emitted += !a->flux.is_black();
    }
    // Shadow rays, from points on both sides of the one-sided red quad among others.
    const Vec3 p(rng.uniform() * 4 - 2, rng.uniform() * 8, rng.uniform() * 4 - 2);
    auto c = light_sample_li(light, scene.light_shape(light), p, u1, scene.bounds_info, wm.wl);
    auto d = light_sample_li(light, scene.light_shape(light), p, u1, scene.bounds_info, wm.wl,
                             wm.light_spectrum(i));
    ASSERT_EQ(c.has_value(), d.has_value());
    if (c) {
      ASSERT_TRUE(c->radiance.c == d->radiance.c);
      ASSERT_EQ(c->pdf_solid_angle, d->pdf_solid_angle);
    } else if (i == 4 || i == 5) {
      ++back_facing;
    }
  }
  EXPECT_GT(emitted, 3000);
  EXPECT_GT(back_facing, 50);  // the one-sided light was seen from behind
}

// may_reach_emitter asks the emitters' own Embree scene: it must say false only where no emitting
// surface lies anywhere along the ray (a light-finding BSDF sample is then skipped), whatever
// stands in front or behind. Random rays through a sphere light (user geometry), a quad light, a
// wall and an interface sphere; each one walked surface by surface through the whole scene.
TEST(RenderScene, MayReachEmitterIsFalseOnlyWhereNoEmitterLiesAlongTheRay) {
  const LoadedScene ls = flatten_scene(parse_scene_string(
      "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\"\nFilm \"rgb\" \"integer "
      "xresolution\" 8 \"integer yresolution\" 8\nWorldBegin\n"
      "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\nTranslate 0.5 0 0\n"
      "Shape \"sphere\" \"float radius\" 0.3\nAttributeEnd\n"
      "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
      "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [-1 1 -0.5  -0.2 1 "
      "-0.5  -0.2 1 0.5  -1 1 0.5]\nAttributeEnd\n"
      "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [-1 -1 0  1 -1 0  1 "
      "1 0  -1 1 0]\n"
      "AttributeBegin\nMaterial \"interface\"\nTranslate -0.5 0 0\nShape \"sphere\" \"float "
      "radius\" 0.4\nAttributeEnd\n"));
  const RenderScene& scene = ls.scene;
  Rng rng(7);
  int said_no = 0, said_yes = 0, found = 0;
  for (int i = 0; i < 20000; ++i) {
    auto u = [&] { return 4 * rng.uniform() - 2; };
    const Vec3 o{u(), u(), u()}, d = normalize(Vec3{u(), u(), u()});
    const bool may = scene.may_reach_emitter(Ray{o, d});
    (may ? said_yes : said_no)++;
    // Every surface along the line, in order, whatever it is.
    bool emitter = false;
    Ray r{o, d};
    Hit h;
    for (int k = 0; k < 16 && scene.intersect(r, &h); ++k) {
      emitter |= scene.objects[size_t(h.object)].first_light >= 0;
      r.o = r.o + r.d * (h.t + 1e-4f);
    }
    found += emitter;
    if (emitter) {
      EXPECT_TRUE(may) << "ray " << i;
    }
  }
  EXPECT_GT(said_no, 1000);
  EXPECT_GT(found, 300);
}

}  // namespace
}  // namespace bpm
