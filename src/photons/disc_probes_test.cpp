// The disc probes measure the share of a gathering disc where photons can land: all of it on an
// open floor, the part left of a wall or of a table top's edge (the disc less a circular segment),
// all of it under an overhang or behind glass; where one map holds every object's photons (fpm),
// other objects count too; a disc with only its own flat mesh near it is whole without probes;
// and the screen test marks the pixels near where the camera sees an edge.
#include "photons/disc_probes.h"

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
Shares shares(const LoadedScene& ls, int object, Vec3 p, int n = 2000,
              PhotonSurfaces where = PhotonSurfaces::kOwnObject) {
  // The surface as the scene gives it (its normal's sign included, which kAnyObject compares).
  const Ray down{p + Vec3(0, 1e-3f, 0), Vec3(0, -1, 0), 1e-2f};
  Hit hit;
  EXPECT_TRUE(ls.scene.intersect(down, &hit));
  EXPECT_EQ(hit.object, object);
  const SurfacePoint sp = ls.scene.surface(down, hit);
  Rng rng(stream_key(5, 0));
  PathCounters rays;
  Shares s;
  for (int i = 0; i < n; ++i) {
    DiscProbes d = probe_disc(ls.scene, sp, Vec3(0, 1, 0), object, where, 1.0f, 0.5f, rng, rays);
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
    DiscProbes d = probe_disc(ls.scene, sp, Vec3(0, 1, 0), 0, PhotonSurfaces::kOwnObject, 0.5f,
                              0.5f, rng, rays);
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

// fpm's maps hold every object's photons: a floor of two objects is whole across their seam, where
// bpm's per-object maps hold photons of one side only (the disc less a segment); walls, a table
// top's edge and the floor under a resting sphere count as they do for bpm.
TEST(DiscProbes, AnySurfaceThatStopsLightCountsWhereOneMapHoldsAll) {
  const PhotonSurfaces any = PhotonSurfaces::kAnyObject;
  LoadedScene seam = flatten_scene(parse_scene_string(
      std::string(kHeader) +
      "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [-10 0 -10  -10 0 "
      "10  0 0 10  0 0 -10]\n"
      "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [0 0 -10  0 0 10  "
      "10 0 10  10 0 -10]\n"));
  EXPECT_NEAR(shares(seam, 0, Vec3(-0.3f, 0, 0), 500, any).mean, 1.0, 1e-6);
  EXPECT_NEAR(shares(seam, 0, Vec3(-0.3f, 0, 0)).mean, disc_less_segment(0.3), 0.01);
  LoadedScene wall = flatten_scene(parse_scene_string(kHeader + floor_at(0) + kWall));
  EXPECT_NEAR(shares(wall, 0, Vec3(-0.4f, 0, 0), 2000, any).mean, disc_less_segment(0.4), 0.01);
  LoadedScene table = flatten_scene(parse_scene_string(
      kHeader + floor_at(0) +
      "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [-3 1 -3  -3 1 3  0 "
      "1 3  0 1 -3]\n"));
  EXPECT_NEAR(shares(table, 1, Vec3(-0.4f, 1, 0), 2000, any).mean, disc_less_segment(0.4), 0.01);
  LoadedScene sphere = flatten_scene(parse_scene_string(
      kHeader + floor_at(0) +
      "AttributeBegin\nTranslate 0 1 0\nShape \"sphere\" \"float radius\" 1\nAttributeEnd\n"));
  EXPECT_GT(shares(sphere, 0, Vec3(0.5f, 0, 0), 2000, any).mean, 0.97);
}

// A photon is cut off from a disc's point by a wall standing between them on the surface, and
// not by open floor, a resting sphere's overhang or glass; a disc's probes say they looked only
// where geometry is near (an open floor is whole on sight of the tree).
TEST(DiscProbes, PhotonsPastAWallAreCutOff) {
  const Vec3 up(0, 1, 0);
  PathCounters rays;
  LoadedScene wall = flatten_scene(parse_scene_string(kHeader + floor_at(0) + kWall));
  EXPECT_TRUE(
      photon_cut_off(wall.scene, Vec3(-0.3f, 0, 0), up, Vec3(0.2f, 0, 0.1f), 0, 1, 0.5f, rays));
  EXPECT_FALSE(
      photon_cut_off(wall.scene, Vec3(-0.3f, 0, 0), up, Vec3(-0.9f, 0, 0.4f), 0, 1, 0.5f, rays));
  EXPECT_GT(rays.probe_rays, 0u);
  LoadedScene sphere = flatten_scene(parse_scene_string(
      kHeader + floor_at(0) +
      "AttributeBegin\nTranslate 0 1 0\nShape \"sphere\" \"float radius\" 1\nAttributeEnd\n"));
  EXPECT_FALSE(
      photon_cut_off(sphere.scene, Vec3(0.9f, 0, 0), up, Vec3(0.3f, 0, 0.2f), 0, 1, 0.5f, rays));
  LoadedScene glass = flatten_scene(
      parse_scene_string(kHeader + floor_at(0) + "Material \"dielectric\"\n" + kWall));
  EXPECT_FALSE(
      photon_cut_off(glass.scene, Vec3(-0.3f, 0, 0), up, Vec3(0.2f, 0, 0.1f), 0, 1, 0.5f, rays));
  // The probes of a disc on the open floor do not look; those of one by the wall do.
  SurfacePoint sp;
  sp.p = Vec3(-0.3f, 0, 0);
  sp.ng = sp.ns = up;
  Rng rng(stream_key(2, 0));
  LoadedScene open = flatten_scene(parse_scene_string(kHeader + floor_at(0)));
  EXPECT_FALSE(
      probe_disc(open.scene, sp, up, 0, PhotonSurfaces::kOwnObject, 1, 0.5f, rng, rays).looked);
  EXPECT_TRUE(
      probe_disc(wall.scene, sp, up, 0, PhotonSurfaces::kOwnObject, 1, 0.5f, rng, rays).looked);
}

// Photons reach the floor under a resting sphere, and through glass: neither cuts the disc.
TEST(DiscProbes, OverhangsAndGlassDoNotCut) {
  LoadedScene sphere = flatten_scene(parse_scene_string(
      kHeader + floor_at(0) +
      "AttributeBegin\nTranslate 0 1 0\nShape \"sphere\" \"float radius\" 1\nAttributeEnd\n"));
  // Near where the sphere touches the floor the gap is thinner than the skimming ray's height
  // (kept above the floor by its error bound): a few probes in a hundred find a cut there.
  EXPECT_GT(shares(sphere, 0, Vec3(0.5f, 0, 0)).mean, 0.97);
  LoadedScene glass = flatten_scene(parse_scene_string(
      kHeader + floor_at(0) + "Material \"dielectric\" \"float eta\" 1.5\n" + kWall));
  EXPECT_NEAR(shares(glass, 0, Vec3(-0.3f, 0, 0), 200).mean, 1.0, 1e-6);
}

// A disc with nothing near it but its own flat mesh, no border within it, is whole without a
// probe (one query of the scene's tree); near a border, a wall, a crease or a sphere the probes
// run, and find the cut where there is one.
TEST(DiscProbes, PlainlyWholeDiscsCastNoProbes) {
  struct Case {
    std::string name, scene;
    Vec3 p;
    bool probed, cut;
    float error = 0;  // the point's error bound
  };
  // A floor folded up by 70 degrees at x = 0.4 (one mesh): past the fold photons meet a normal
  // the gather does not take (normal_cos 0.5).
  const std::string crease =
      "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3 3 2 4 3 4 5] \"point3 P\" [-10 0 "
      "-10  -10 0 10  0.4 0 10  0.4 0 -10  1.4 2.75 10  1.4 2.75 -10]\n";
  const std::string sphere =
      "AttributeBegin\nTranslate 0 1.6 0\nShape \"sphere\" \"float radius\" 1\nAttributeEnd\n";
  const std::vector<Case> cases = {
      {"open floor", floor_at(0), Vec3(0.3f, 0, -0.2f), false, false},
      {"the floor's border", floor_at(0), Vec3(9.7f, 0, 0), true, true},
      {"a wall inside the disc", floor_at(0) + kWall, Vec3(-0.3f, 0, 0), true, true},
      {"a wall within two radii", floor_at(0) + kWall, Vec3(-0.8f, 0, 0), true, false},
      {"a wall farther", floor_at(0) + kWall, Vec3(-1.2f, 0, 0), false, false},
      {"a crease inside the disc", crease, Vec3(0.1f, 0, 0), true, true},
      {"a sphere above", floor_at(0) + sphere, Vec3(0, 0, 0), true, false},
      {"a double-sided floor's border",
       "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3 0 2 1 0 3 2] \"point3 P\" [-10 0 "
       "-10  -10 0 10  10 0 10  10 0 -10]\n",
       Vec3(9.7f, 0, -5), true, true},
      // Probes lifted 0.2 off the point by its error bound: the reach grows by twice that.
      {"a wall farther, a large error bound", floor_at(0) + kWall, Vec3(-1.2f, 0, 0), true, false,
       0.05f},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    LoadedScene ls = flatten_scene(parse_scene_string(kHeader + c.scene));
    SurfacePoint sp;
    sp.p = c.p;
    sp.ng = sp.ns = Vec3(0, 1, 0);
    sp.error = c.error;
    Rng rng(stream_key(2, 0));
    PathCounters rays;
    uint8_t cut = 0;
    for (int i = 0; i < 50; ++i) {
      DiscProbes d = probe_disc(ls.scene, sp, Vec3(0, 1, 0), 0, PhotonSurfaces::kOwnObject, 0.5f,
                                0.5f, rng, rays);
      if (!c.probed) {
        ASSERT_EQ(d.found, 0xff);
      }
      cut |= d.cut;
    }
    EXPECT_EQ(rays.probe_rays > 0, c.probed);
    EXPECT_EQ(cut != 0, c.cut);
  }
}

TEST(DiscProbes, SpheresAndCylindersAreNotProbed) {
  EXPECT_FALSE(may_cut_discs(Sphere{}));
  EXPECT_FALSE(may_cut_discs(Cylinder{}));
  EXPECT_TRUE(may_cut_discs(Disk{}));
  EXPECT_TRUE(may_cut_discs(TriangleMesh{}));
}

// Looking straight down at two floors that meet at x = 0 (two objects), with a raised block on
// the right one: the seam and the block's outline are edges, the open floor is not; the marks
// spread over the radii and the image's border.
TEST(DiscProbes, FindsEdgesAndMarksPixelsNearThem) {
  const int w = 16, h = 12;
  LoadedScene ls = flatten_scene(parse_scene_string(
      "LookAt 0 10 0  0 0 0  0 0 1\nCamera \"perspective\" \"float fov\" 20\nFilm \"rgb\" "
      "\"integer xresolution\" 16 \"integer yresolution\" 12\nWorldBegin\n"
      "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [-5 0 -5  -5 0 5  0 0 "
      "5  0 0 -5]\n"
      "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [0 0 -5  0 0 5  5 0 5 "
      " 5 0 -5]\n"
      "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [-1.2 0.5 -0.3  -1.2 "
      "0.5 0.3  -0.8 0.5 0.3  -0.8 0.5 -0.3]\n"));
  const Camera camera(ls.camera, w, h);
  const std::vector<uint8_t> edges = find_edges(ls.scene, camera, w, h);
  ASSERT_EQ(edges.size(), size_t(w * h));
  auto edge = [&](int x, int y) { return edges[size_t(y * w + x)]; };
  // Which columns hold the seam (the camera may mirror x).
  int seam = -1;
  for (int x = 0; x + 1 < w; ++x)
    if (edge(x, 0) && edge(x + 1, 0) && edge(x, h - 1) && edge(x + 1, h - 1)) seam = x;
  ASSERT_TRUE(seam == 7) << "seam at column " << seam;
  int marked = 0;
  for (uint8_t e : edges) marked += e;
  // The seam's two columns and the block's outline (about 3 x 5 pixels, at x -1.2..-0.8).
  EXPECT_GE(marked, 2 * h + 8);
  EXPECT_LE(marked, 2 * h + 24);
  // An open stretch of floor on the block's far side: no edge.
  const int open_x = camera.generate_ray({0.5f, 6.5f}, {0.5f, 0.5f}).ray.d.x < 0 ? 13 : 2;
  EXPECT_EQ(edge(open_x, 6), 0);

  std::vector<uint8_t> near;
  mark_near_edges(edges, w, h, 1, 2, &near);
  auto at = [&](int x, int y) { return near[size_t(y * w + x)]; };
  EXPECT_EQ(at(open_x, 6), 0);        // far from the seam, the block and the border
  EXPECT_EQ(at(open_x, 2), 0);        // the large disc's window (two rows) reaches the border
  EXPECT_EQ(at(open_x, 1), 1);        // only from here
  EXPECT_EQ(at(open_x, 0), 3);        // the border row
  EXPECT_EQ(at(seam - 2, 6) & 1, 1);  // two columns from the seam (on either side of it)
  EXPECT_EQ(at(seam + 3, 6) & 1, 1);
  EXPECT_EQ(at(seam - 1, 6), 3);  // one from it
}

}  // namespace
}  // namespace bpm
