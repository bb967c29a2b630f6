// The kd-trees over backward photons return exactly the spheres a brute-force scan finds.
#include "photons/sphere_kdtree.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>

#include "base/rng.h"

namespace bpm {
namespace {

// Spheres clustered on a plane (like backward photons on a wall) with two radius classes (like
// r0 and r1), plus a few isolated large ones.
std::vector<SphereRef> random_spheres(Rng& rng, int n) {
  std::vector<SphereRef> s;
  for (int i = 0; i < n; ++i) {
    Vec3 c(rng.uniform() * 10, rng.uniform() * 10, rng.uniform() * 0.05f);
    float r = (i % 3 == 0) ? 0.4f * rng.uniform() : 0.05f * rng.uniform();
    if (i % 97 == 0) r = 3;
    s.push_back({c, r});
  }
  return s;
}

template <class Tree>
void check_against_brute_force(const char* name, int n) {
  Rng rng(stream_key(5, n));
  std::vector<SphereRef> spheres = random_spheres(rng, n);
  Tree tree;
  tree.build(spheres);
  size_t total = 0;
  for (int q = 0; q < 3000; ++q) {
    Vec3 p(rng.uniform() * 11 - 0.5f, rng.uniform() * 11 - 0.5f, rng.uniform() * 0.3f - 0.1f);
    // Some queries exactly at centres, where boundaries are tightest.
    if (q % 10 == 0 && n > 0) p = spheres[q % n].c;
    std::vector<uint32_t> expected, got;
    for (uint32_t i = 0; i < spheres.size(); ++i)
      if (length_squared(p - spheres[i].c) < spheres[i].r * spheres[i].r) expected.push_back(i);
    tree.query(p, [&](uint32_t i) { got.push_back(i); });
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, expected) << name << " n=" << n << " query " << q;
    total += got.size();
  }
  if (n >= 1000) {
    EXPECT_GT(total, 3000u) << name;  // the queries do find spheres
  }
}

TEST(SphereKdTree, MatchesBruteForce) {
  for (int n : {0, 1, 3, 50, 1000, 20000})
    check_against_brute_force<SphereKdTree>("sphere tree", n);
}

// A tree built again over fewer spheres finds only the new ones (its leaf arrays, padded for the
// four-wide test, start over), and a leaf's last spheres are found whatever the leaf's size.
TEST(SphereKdTree, RebuiltOverFewerSpheresFindsOnlyThose) {
  Rng rng(stream_key(9, 1));
  SphereKdTree tree;
  tree.build(random_spheres(rng, 5000));
  for (int n : {7, 1, 3, 5, 0}) {
    std::vector<SphereRef> spheres;
    for (int i = 0; i < n; ++i) spheres.push_back({Vec3(float(i), 0, 0), 0.75f});
    tree.build(spheres);
    for (int i = 0; i < n; ++i) {
      std::vector<uint32_t> got;
      tree.query(Vec3(float(i) + 0.5f, 0, 0), [&](uint32_t k) { got.push_back(k); });
      std::sort(got.begin(), got.end());
      std::vector<uint32_t> expected = {uint32_t(i)};
      if (i + 1 < n) expected.push_back(uint32_t(i + 1));
      EXPECT_EQ(got, expected) << "n=" << n << " at " << i;
    }
  }
  int found = 0;
  tree.query(Vec3(0, 0, 0), [&](uint32_t) { ++found; });
  EXPECT_EQ(found, 0);
}

TEST(CentreKdTree, MatchesBruteForce) {
  for (int n : {0, 1, 3, 50, 1000, 20000})
    check_against_brute_force<CentreKdTree>("centre tree", n);
}

TEST(CentreKdTree, PointQueriesWithinARadiusMatchBruteForce) {
  Rng rng(stream_key(6, 0));
  std::vector<SphereRef> points = random_spheres(rng, 5000);
  for (auto& p : points) p.r = 0;
  CentreKdTree tree;
  tree.build(points);
  for (int q = 0; q < 2000; ++q) {
    Vec3 p(rng.uniform() * 10, rng.uniform() * 10, rng.uniform() * 0.05f);
    float R = 0.02f + 0.5f * rng.uniform();
    std::vector<uint32_t> expected, got;
    for (uint32_t i = 0; i < points.size(); ++i)
      if (length_squared(p - points[i].c) < R * R) expected.push_back(i);
    tree.query_within(p, R, [&](uint32_t i) { got.push_back(i); });
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, expected) << "query " << q;
  }
}

// Backward photons on two walls of one object that meet at a corner, most of them on the wall
// perpendicular to the cell's longest axis: the median centre on that axis lies on that wall, and
// a plane there separates nothing. The tree must still split, or every query scans them all.
TEST(SphereKdTree, PhotonsOnAWallAcrossTheLongestAxisStillSplit) {
  Rng rng(stream_key(7, 0));
  std::vector<SphereRef> s;
  const float r = 0.01f;
  for (int i = 0; i < 20000; ++i) {
    float a = rng.uniform(), b = rng.uniform() * 0.5f;
    // The floor-like wall is longer in x, so that x is the longest axis.
    s.push_back(i % 5 < 3 ? SphereRef{Vec3(1, a, b), r}
                          : SphereRef{Vec3(1.5f * a - 0.5f, 1, b), r});
  }
  SphereKdTree t;
  t.build(s);
  size_t worst = 0;
  for (int q = 0; q < 1000; ++q) {
    float a = rng.uniform(), b = rng.uniform() * 0.5f;
    Vec3 p = q % 2 ? Vec3(1, a, b) : Vec3(1.5f * a - 0.5f, 1, b);
    worst = std::max(worst, t.tests_at(p));
  }
  // About 7 spheres contain a point; a leaf of a few hundred is the tree's cost trade-off.
  EXPECT_LT(worst, 1000u);
}

// Large cells build their halves as parallel tasks: the tree, and so the order in which a query
// reports spheres, must be the one a single thread builds.
TEST(SphereKdTree, ThreadsDoNotChangeTheTree) {
  Rng rng(stream_key(8, 0));
  std::vector<SphereRef> spheres = random_spheres(rng, 100000);
  SphereKdTree one, many;
  tbb::task_arena(1).execute([&] { one.build(spheres); });
  tbb::task_arena(4).execute([&] { many.build(spheres); });
  EXPECT_EQ(one.bytes(), many.bytes());
  EXPECT_EQ(one.reference_count(), many.reference_count());
  size_t found = 0;
  for (int q = 0; q < 2000; ++q) {
    Vec3 p(rng.uniform() * 10, rng.uniform() * 10, rng.uniform() * 0.05f);
    std::vector<uint32_t> a, b;
    one.query(p, [&](uint32_t i) { a.push_back(i); });
    many.query(p, [&](uint32_t i) { b.push_back(i); });
    ASSERT_EQ(a, b) << "query " << q;  // same spheres in the same order
    found += a.size();
  }
  EXPECT_GT(found, 2000u);
}

TEST(SphereKdTree, IdenticalSpheresDoNotRecurseForever) {
  std::vector<SphereRef> s(5000, SphereRef{Vec3(1, 2, 3), 0.5f});
  SphereKdTree t;
  t.build(s);
  int hits = 0;
  t.query(Vec3(1.1f, 2, 3), [&](uint32_t) { ++hits; });
  EXPECT_EQ(hits, 5000);
  EXPECT_LT(t.duplication(), 1.01);
}

}  // namespace
}  // namespace bpm

namespace bpm {
namespace {

// Both trees report the ids they were given for their spheres (the backward maps build one tree
// per class of photon from a subset of an object's photons and want the photons' own indices).
TEST(SphereKdTree, QueriesReportTheGivenIds) {
  std::vector<SphereRef> spheres;
  std::vector<uint32_t> ids;
  for (int i = 0; i < 200; ++i) {
    spheres.push_back({Vec3(0.01f * float(i), 0, 0), 0.015f});
    ids.push_back(uint32_t(1000 + 3 * i));
  }
  SphereKdTree st;
  st.build(spheres, &ids);
  CentreKdTree ct;
  ct.build(spheres, &ids);
  for (int i = 0; i < 200; i += 17) {
    std::vector<uint32_t> a, b;
    st.query(Vec3(0.01f * float(i), 0, 0), [&](uint32_t k) { a.push_back(k); });
    ct.query(Vec3(0.01f * float(i), 0, 0), [&](uint32_t k) { b.push_back(k); });
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b);
    EXPECT_NE(std::find(a.begin(), a.end(), uint32_t(1000 + 3 * i)), a.end()) << "sphere " << i;
    for (uint32_t k : a) EXPECT_EQ((k - 1000) % 3, 0u);
  }
}

}  // namespace
}  // namespace bpm
