// Splitting and displacing PLY meshes as pbrt-v4's "plymesh" with "displacement".
#include "scene/displace.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>

namespace bpm {
namespace {

// A 2 x 2 square in the xy plane, counter-clockwise seen from +z, uv 0..1.
PlyMesh square() {
  PlyMesh m;
  m.positions = {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(2, 2, 0), Vec3(0, 2, 0)};
  m.uvs = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

float area(const PlyMesh& m) {
  float a = 0;
  for (size_t i = 0; i < m.indices.size(); i += 3) {
    const Vec3 p0 = m.positions[size_t(m.indices[i])], p1 = m.positions[size_t(m.indices[i + 1])],
               p2 = m.positions[size_t(m.indices[i + 2])];
    a += 0.5f * cross(p1 - p0, p2 - p0).z;  // signed: a flipped piece would subtract
  }
  return a;
}

// Every edge shorter than the limit (in world space: a scale of 2 doubles them), the square's
// area kept with every piece's winding, and no crack: each directed edge inside the square is
// matched by its reverse, and the boundary's pieces add up to the boundary.
TEST(Displace, SplittingLeavesShortEdgesAndNoCracks) {
  PlyMesh m = square();
  const Transform scale2 = Transform::scale(Vec3(2, 2, 2));
  const size_t bound = displaced_triangle_count(m, scale2, 0.3f);
  displace_mesh(&m, scale2, 0.3f, [](Vec3, Vec2) { return 0.0f; });
  EXPECT_LE(m.indices.size() / 3, bound);
  EXPECT_GT(m.indices.size() / 3, 100u);
  EXPECT_NEAR(area(m), 4, 1e-4f);
  std::map<std::pair<int, int>, int> edges;
  float boundary = 0;
  for (size_t i = 0; i < m.indices.size(); i += 3)
    for (int k = 0; k < 3; ++k) {
      const int a = m.indices[i + size_t(k)], b = m.indices[i + size_t(k + 1) % 3];
      const Vec3 pa = m.positions[size_t(a)], pb = m.positions[size_t(b)];
      EXPECT_LT(2 * length(pa - pb), 0.3f);
      ++edges[{a, b}];
    }
  for (const auto& [e, n] : edges) {
    EXPECT_EQ(n, 1);
    if (!edges.count({e.second, e.first}))
      boundary += length(m.positions[size_t(e.first)] - m.positions[size_t(e.second)]);
  }
  EXPECT_NEAR(boundary, 8, 1e-4f);
  for (const Vec3& n : m.normals) EXPECT_NEAR(n.z, 1, 1e-6f);
}

// A constant displacement lifts the square along its normal (computed: the file has none); a
// ramp d = a u over a 2-wide square tilts it to the slope a / 2 along x.
TEST(Displace, VerticesMoveAlongTheirNormalsByTheDisplacement) {
  PlyMesh m = square();
  displace_mesh(&m, Transform(), 0.5f, [](Vec3, Vec2) { return 0.25f; });
  for (const Vec3& p : m.positions) EXPECT_NEAR(p.z, 0.25f, 1e-6f);
  constexpr float kA = 0.6f;
  PlyMesh r = square();
  displace_mesh(&r, Transform(), 0.5f, [](Vec3, Vec2 uv) { return kA * uv.x; });
  for (size_t v = 0; v < r.positions.size(); ++v) {
    EXPECT_NEAR(r.positions[v].z, kA / 2 * r.positions[v].x, 1e-5f);
    const Vec3 want = normalize(Vec3(-kA / 2, 0, 1));
    EXPECT_NEAR(dot(r.normals[v], want), 1, 1e-5f);
  }
  // The point handed to the displacement is the object-space vertex.
  PlyMesh q = square();
  displace_mesh(&q, Transform::translate(Vec3(5, 0, 0)), 0.5f, [](Vec3 p, Vec2) {
    EXPECT_LE(p.x, 2.0f);
    return 0.0f;
  });
}

}  // namespace
}  // namespace bpm
