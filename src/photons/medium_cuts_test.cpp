// A surface near a point in a medium cuts the discs across the beams it gathers: the share of a
// disc on the point's side of the plane against a count of points spread over it, and the cut
// found along the point's ray over a floor, under a tilted roof, and nowhere in open space.
#include "photons/medium_cuts.h"

#include <gtest/gtest.h>

#include <cmath>

#include "base/rng.h"
#include "scene/flatten.h"
#include "scene/parsed_scene.h"

namespace bpm {
namespace {

// The share of the disc of `radius` about the origin across unit d on the side of the plane
// n . x = -h (n unit) that holds the origin, from a grid of points over the disc.
double counted_share(Vec3 n, float h, Vec3 d, float radius) {
  const Frame f = Frame::from_z(d);
  int in = 0, all = 0;
  constexpr int k = 400;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      const float x = (2 * (float(i) + 0.5f) / k - 1) * radius,
                  y = (2 * (float(j) + 0.5f) / k - 1) * radius;
      if (x * x + y * y >= radius * radius) continue;
      ++all;
      in += dot(f.to_world(Vec3(x, y, 0)), n) > -h;
    }
  return double(in) / all;
}

TEST(MediumCuts, DiscShareIsThePartOnThePointsSide) {
  Rng rng(stream_key(11, 0));
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 n =
        normalize(Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f));
    const Vec3 d =
        normalize(Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f));
    const float h = 0.02f + 0.98f * rng.uniform(), radius = 0.5f + rng.uniform();
    EXPECT_NEAR(beam_disc_share(n * h, d, radius), counted_share(n, h, d, radius), 2e-3)
        << "n " << n.x << " " << n.y << " " << n.z << ", d " << d.x << " " << d.y << " " << d.z
        << ", h " << h << ", radius " << radius;
  }
  // No cut; a beam along the normal (its disc lies parallel to the plane); the plane beyond the
  // disc; a beam parallel to a plane next to the point.
  EXPECT_EQ(beam_disc_share(Vec3(), Vec3(1, 0, 0), 1), 1.0f);
  EXPECT_EQ(beam_disc_share(Vec3(0, 0, 0.1f), Vec3(0, 0, 1), 1), 1.0f);
  EXPECT_EQ(beam_disc_share(Vec3(0, 0, 0.5f), Vec3(1, 0, 0), 0.4f), 1.0f);
  EXPECT_NEAR(beam_disc_share(Vec3(0, 0, 1e-4f), Vec3(1, 0, 0), 1), 0.5, 1e-3);
}

const char* kScene =
    "LookAt 0 3 -5  0 0 0  0 1 0\nCamera \"perspective\"\nFilm \"rgb\" \"integer xresolution\" 8 "
    "\"integer yresolution\" 8\nWorldBegin\n"
    // A floor at y = 0, facing up.
    "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [-10 0 -10  -10 0 10  "
    "10 0 10  10 0 -10]\n"
    // A roof over x > 5 at y = 4 + (x - 5): 45 degrees.
    "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [5 4 -10  5 4 10  10 9 "
    "10  10 9 -10]\n";

TEST(MediumCuts, FoundAlongThePointsRay) {
  LoadedScene ls = flatten_scene(parse_scene_string(kScene));
  PathCounters rays;
  // Going down toward the floor, 0.3 above it: the floor's plane, whatever the ray's slant.
  for (Vec3 d : {Vec3(0, -1, 0), normalize(Vec3(1, -1, 0)), normalize(Vec3(3, -1, 1))}) {
    const float to_end = 0.3f / -d.y;
    const Vec3 c = medium_cut(ls.scene, Vec3(0, 0.3f, 0), d, to_end, kInf, 1.0f, rays);
    EXPECT_NEAR(c.x, 0, 1e-5);
    EXPECT_NEAR(c.y, 0.3, 1e-5);
    EXPECT_NEAR(c.z, 0, 1e-5);
  }
  // Leaving the floor upward: found behind the point.
  Vec3 c = medium_cut(ls.scene, Vec3(2, 0.5f, 1), Vec3(0, 1, 0), kInf, 0.5f, 1.0f, rays);
  EXPECT_NEAR(c.y, 0.5, 1e-5);
  // Too far along the ray (kCutReach radii), or too far from the plane: no cut.
  c = medium_cut(ls.scene, Vec3(0, 0.3f, 0), normalize(Vec3(20, -1, 0)), 0.3f * std::sqrt(401.f),
                 kInf, 1.0f, rays);
  EXPECT_EQ(length_squared(c), 0);
  c = medium_cut(ls.scene, Vec3(0, 1.5f, 0), normalize(Vec3(1, -1, 0)), 1.5f * std::sqrt(2.f), kInf,
                 1.0f, rays);
  EXPECT_EQ(length_squared(c), 0);
  // Under the roof, going up along y: the roof's plane is 0.5 / sqrt 2 away along its normal.
  c = medium_cut(ls.scene, Vec3(6, 4.5f, 0), Vec3(0, 1, 0), 0.5f, kInf, 1.0f, rays);
  EXPECT_NEAR(length(c), 0.5 / std::sqrt(2.0), 1e-5);
  EXPECT_NEAR(c.x, 0.25, 1e-5);
  EXPECT_NEAR(c.y, -0.25, 1e-5);
  // Open space: neither way meets anything.
  const uint64_t before = rays.probe_rays;
  c = medium_cut(ls.scene, Vec3(-3, 2, 0), Vec3(0, 0, 1), 0.5f, 0.5f, 1.0f, rays);
  EXPECT_EQ(length_squared(c), 0);
  EXPECT_EQ(rays.probe_rays - before, 2u);
}

// Beams go on past glass into the same medium: no cut there. Past glass into another medium, or
// a bare interface to vacuum, they end.
TEST(MediumCuts, OnlySurfacesWhereBeamsEnd) {
  const std::string head =
      "LookAt 0 3 -5  0 0 0  0 1 0\nCamera \"perspective\"\nFilm \"rgb\" \"integer xresolution\" 8 "
      "\"integer yresolution\" 8\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n"
      "WorldBegin\n";
  const std::string floor =
      "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [-10 0 -10  -10 0 10  "
      "10 0 10  10 0 -10]\n";
  struct Case {
    const char* what;
    std::string scene;
    bool cut;
  };
  const Case cases[] = {
      {"glass in fog", "MediumInterface \"fog\" \"fog\"\nMaterial \"dielectric\"\n" + floor, false},
      {"glass without media", "Material \"dielectric\"\n" + floor, false},
      {"a cut-out",
       "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [-10 0 "
       "-10  -10 0 10  10 0 10  10 0 -10] \"float alpha\" 0.5\n",
       false},
      {"glass over vacuum", "MediumInterface \"\" \"fog\"\nMaterial \"dielectric\"\n" + floor,
       true},
      {"an interface", "MediumInterface \"\" \"fog\"\nMaterial \"interface\"\n" + floor, true},
      {"a mix of diffuse and glass",
       "MakeNamedMaterial \"a\" \"string type\" \"diffuse\"\nMakeNamedMaterial \"b\" \"string "
       "type\" \"dielectric\"\nMaterial \"mix\" \"string materials\" [\"a\" \"b\"]\n" +
           floor,
       false},
      {"diffuse", floor, true},
  };
  for (const Case& c : cases) {
    LoadedScene ls = flatten_scene(parse_scene_string(head + c.scene));
    PathCounters rays;
    const Vec3 cut = medium_cut(ls.scene, Vec3(0, 0.3f, 0), Vec3(0, -1, 0), 0.3f, kInf, 1, rays);
    EXPECT_EQ(length_squared(cut) > 0, c.cut) << c.what;
  }
}

}  // namespace
}  // namespace bpm
