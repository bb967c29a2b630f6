// The disc probes measure the share of a gathering disc where photons can land: all of it on an
// open floor, the part left of a wall or of a table top's edge (the disc less a circular segment),
// all of it under an overhang or behind glass; and the screen test marks the pixels near where
// the camera sees an edge.
#include "bpm/disc_probes.h"

#include <gtest/gtest.h>

#include <cmath>

#include "scene/flatten.h"
#include "scene/parsed_scene.h"

namespace bpm {
namespace {

const char* kHeader =
    "LookAt 0 3 -5  0 0 0  0 1 0\nCamera \"perspective\"\nFilm \"rgb\" \"integer xresolution\" 8 "
    "\"integer yresolution\" 8\nWorldBegin\n";

// A 20 x 20 floor at height y facing up, as object `first` of the scene.
std::string floor_at(float y) {
  const std::string h = std::to_string(y);
  return "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [-10 " + h +
         " -10  -10 " + h + " 10  10 " + h + " 10  10 " + h + " -10]\n";
}

// A wall in the plane x = 0, from the floor up to y = 2.
const char* kWall =
    "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [0 0 -10  0 0 10  0 2 "
    "10 "
    " 0 2 -10]\n";

// The share of a disc of radius 1 about p on an upward surface of `object`, over n draws of the
// probes: the mean of the share, and of its inverse (what the estimate is divided by).
struct Shares {
  double mean = 0, mean_inverse = 0;
};
Shares shares(const LoadedScene& ls, int object, Vec3 p, int n = 2000) {
  SurfacePoint sp;
  sp.p = p;
  sp.ng = sp.ns = Vec3(0, 1, 0);
  sp.error = 1e-6f;
  Rng rng(stream_key(5, 0));
  PathCounters rays;
  Shares s;
  for (int i = 0; i < n; ++i) {
    DiscProbes d = probe_disc(ls.scene, sp, Vec3(0, 1, 0), object, 1.0f, 0.5f, rng, rays);
    const float share = disc_share(d.found, d.cut, 0);
    s.mean += share / n;
    s.mean_inverse += 1 / (share * n);
  }
  EXPECT_GE(rays.probe_rays, uint64_t(n) * (kDiscProbes + 1));
  return s;
}

// The part of a unit disc on the near side of a line at distance d from its centre.
double disc_less_segment(double d) {
  return (M_PI - (std::acos(d) - d * std::sqrt(1 - d * d))) / M_PI;
}

TEST(DiscProbes, OpenFloorIsWhole) {
  LoadedScene ls = flatten_scene(parse_scene_string(kHeader + floor_at(0)));
  SurfacePoint sp;
  sp.p = Vec3(0.3f, 0, -0.2f);
  sp.ng = sp.ns = Vec3(0, 1, 0);
  Rng rng(stream_key(1, 0));
  PathCounters rays;
  for (int i = 0; i < 200; ++i) {
    DiscProbes d = probe_disc(ls.scene, sp, Vec3(0, 1, 0), 0, 0.5f, 0.5f, rng, rays);
    ASSERT_EQ(d.found, 0xff);
    ASSERT_EQ(d.cut, 0);
  }
}

// The probes are uniform over the disc (stratified), so the mean share is the disc's share; the
// mean of its inverse exceeds the inverse of the share by a few percent at most (Jensen).
TEST(DiscProbes, WallCutsOffACircularSegment) {
  LoadedScene ls = flatten_scene(parse_scene_string(kHeader + floor_at(0) + kWall));
  for (double d : {0.1, 0.4, 0.7}) {
    SCOPED_TRACE("wall at " + std::to_string(d));
    const Shares s = shares(ls, 0, Vec3(-float(d), 0, 0));
    const double c = disc_less_segment(d);
    EXPECT_NEAR(s.mean, c, 0.01);
    EXPECT_NEAR(s.mean_inverse * c, 1.0, 0.03);
  }
}

// A table top 1 above the floor, ending at x = 0: past its edge the probes find the floor.
TEST(DiscProbes, EdgeOfASurfaceCutsOffACircularSegment) {
  LoadedScene ls = flatten_scene(parse_scene_string(
      kHeader + floor_at(0) +
      "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [-3 1 -3  -3 1 3  0 "
      "1 3  0 1 -3]\n"));
  for (double d : {0.2, 0.6}) {
    SCOPED_TRACE("edge at " + std::to_string(d));
    const Shares s = shares(ls, 1, Vec3(-float(d), 1, 0));
    EXPECT_NEAR(s.mean, disc_less_segment(d), 0.01);
  }
}

// Photons reach the floor under a resting sphere, and through glass: neither cuts the disc.
TEST(DiscProbes, OverhangsAndGlassDoNotCut) {
  LoadedScene sphere = flatten_scene(parse_scene_string(
      kHeader + floor_at(0) +
      "AttributeBegin\nTranslate 0 1 0\nShape \"sphere\" \"float radius\" 1\nAttributeEnd\n"));
  EXPECT_GT(shares(sphere, 0, Vec3(0.5f, 0, 0)).mean, 0.99);
  LoadedScene glass = flatten_scene(parse_scene_string(
      kHeader + floor_at(0) + "Material \"dielectric\" \"float eta\" 1.5\n" + kWall));
  EXPECT_NEAR(shares(glass, 0, Vec3(-0.3f, 0, 0), 200).mean, 1.0, 1e-6);
}

TEST(DiscProbes, SpheresAndCylindersAreNotProbed) {
  EXPECT_FALSE(may_cut_discs(Sphere{}));
  EXPECT_FALSE(may_cut_discs(Cylinder{}));
  EXPECT_TRUE(may_cut_discs(Disk{}));
  EXPECT_TRUE(may_cut_discs(TriangleMesh{}));
}

// First vertices of a 16 x 12 image on a plane: two objects meeting between columns 7 and 8, and
// a step between rows 5 and 6 of the right one. The marks spread over the radii and the border.
TEST(DiscProbes, MarksPixelsNearEdgesAndTheBorder) {
  const int w = 16, h = 12;
  std::vector<FirstVertex> first(size_t(w * h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      FirstVertex& f = first[size_t(y * w + x)];
      f.p = Vec3(0.1f * float(x), x >= 8 && y >= 6 ? 0.5f : 0.0f, 0.1f * float(y));
      f.ng = Vec3(0, 1, 0);
      f.object = x < 8 ? 0 : 1;
    }
  std::vector<uint8_t> near;
  mark_near_edges(first, w, h, 1, 2, &near);
  auto at = [&](int x, int y) { return near[size_t(y * w + x)]; };
  EXPECT_EQ(at(3, 3), 0);      // two from the border, four from the seam
  EXPECT_EQ(at(5, 3), 1);      // the seam's columns are 7 and 8: two away, within r1 only
  EXPECT_EQ(at(6, 3), 3);      // one away: within both
  EXPECT_EQ(at(12, 2), 0);     // far from the seam, the step (rows 5 and 6) and the border
  EXPECT_EQ(at(12, 3), 1);     // two rows above the step
  EXPECT_EQ(at(12, 8), 1);     // two rows below it
  EXPECT_EQ(at(12, 9), 0);     // three below it, two from the border
  EXPECT_EQ(at(0, 3) & 2, 2);  // the border
  EXPECT_EQ(at(1, 3), 1);
  // A pixel without a first vertex is an edge, and so are its neighbours (a break marks both
  // sides): (3, 2) is one row from (3, 1).
  first[size_t(3 * w + 3)].object = -1;
  mark_near_edges(first, w, h, 1, 2, &near);
  EXPECT_EQ(at(3, 3), 3);
  EXPECT_EQ(at(3, 1), 3);
  EXPECT_EQ(at(0 + 3, 7), 0);  // four rows below it, three from the border
}

}  // namespace
}  // namespace bpm
