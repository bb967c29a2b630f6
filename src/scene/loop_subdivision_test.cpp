// Tests of Loop subdivision: counts and closedness, affine invariance (every rule is an affine
// combination), planar meshes staying planar with the plane's normal, a regular vertex of a flat
// grid staying put, a sphere-like mesh moving toward its limit, and non-manifold input rejected.
#include "scene/loop_subdivision.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <stdexcept>

namespace bpm {
namespace {

// Octahedron, outward winding.
void octahedron(std::vector<Vec3>* p, std::vector<int>* idx) {
  *p = {Vec3(1, 0, 0),  Vec3(-1, 0, 0), Vec3(0, 1, 0),
        Vec3(0, -1, 0), Vec3(0, 0, 1),  Vec3(0, 0, -1)};
  *idx = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
}

// A flat triangulated grid in z = 0, n x n cells over [0, n]^2.
void grid(int n, std::vector<Vec3>* p, std::vector<int>* idx) {
  p->clear();
  idx->clear();
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) p->push_back(Vec3(float(x), float(y), 0));
  auto id = [n](int x, int y) { return y * (n + 1) + x; };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      for (int v :
           {id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y), id(x + 1, y + 1), id(x, y + 1)})
        idx->push_back(v);
}

TEST(LoopSubdivision, CountsAndClosedness) {
  std::vector<Vec3> p;
  std::vector<int> idx;
  octahedron(&p, &idx);
  SubdividedMesh m = loop_subdivide(p, idx, 2);
  EXPECT_EQ(m.indices.size(), idx.size() * 16);
  // V' = V + E per level: 6 + 12 = 18, then 18 + 48 = 66.
  EXPECT_EQ(m.positions.size(), 66u);
  std::map<std::pair<int, int>, int> edge_faces;
  for (size_t f = 0; f < m.indices.size(); f += 3)
    for (int k = 0; k < 3; ++k) {
      int a = m.indices[f + k], b = m.indices[f + (k + 1) % 3];
      ++edge_faces[{std::min(a, b), std::max(a, b)}];
    }
  for (const auto& [e, n] : edge_faces) EXPECT_EQ(n, 2) << "closed meshes stay closed";
  // Outward normals, and every limit point inside the octahedron's bounding sphere but well away
  // from the centre.
  for (size_t v = 0; v < m.positions.size(); ++v) {
    EXPECT_GT(dot(m.normals[v], m.positions[v]), 0.0f);
    EXPECT_LT(length(m.positions[v]), 1.0f);
    EXPECT_GT(length(m.positions[v]), 0.4f);
  }
}

TEST(LoopSubdivision, AffineInvariant) {
  std::vector<Vec3> p;
  std::vector<int> idx;
  octahedron(&p, &idx);
  auto xf = [](Vec3 v) { return Vec3(2 * v.x + 0.5f * v.y + 1, -v.y + 3, 0.25f * v.z + v.x - 2); };
  std::vector<Vec3> q;
  for (Vec3 v : p) q.push_back(xf(v));
  SubdividedMesh a = loop_subdivide(p, idx, 2), b = loop_subdivide(q, idx, 2);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  for (size_t i = 0; i < a.positions.size(); ++i) {
    Vec3 e = xf(a.positions[i]);
    EXPECT_NEAR(b.positions[i].x, e.x, 1e-4f);
    EXPECT_NEAR(b.positions[i].y, e.y, 1e-4f);
    EXPECT_NEAR(b.positions[i].z, e.z, 1e-4f);
  }
}

TEST(LoopSubdivision, FlatGridStaysFlatAndRegularVerticesStay) {
  std::vector<Vec3> p;
  std::vector<int> idx;
  grid(4, &p, &idx);
  SubdividedMesh m = loop_subdivide(p, idx, 1);
  for (size_t v = 0; v < m.positions.size(); ++v) {
    EXPECT_NEAR(m.positions[v].z, 0.0f, 1e-6f);
    EXPECT_NEAR(m.normals[v].z, 1.0f, 1e-5f);
    // Boundary points stay on the square's boundary lines or inside.
    EXPECT_GE(m.positions[v].x, -1e-5f);
    EXPECT_LE(m.positions[v].x, 4 + 1e-5f);
  }
  // The centre vertex (2, 2) is regular (valence 6, symmetric neighbours): it does not move.
  EXPECT_NEAR(m.positions[2 * 5 + 2].x, 2.0f, 1e-5f);
  EXPECT_NEAR(m.positions[2 * 5 + 2].y, 2.0f, 1e-5f);
  // A boundary vertex between two boundary neighbours on a straight edge stays on that edge.
  EXPECT_NEAR(m.positions[2].y, 0.0f, 1e-6f);
  EXPECT_NEAR(m.positions[2].x, 2.0f, 1e-5f);
}

TEST(LoopSubdivision, RejectsNonManifoldEdges) {
  std::vector<Vec3> p = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0),
                         Vec3(0, 0, 1)};
  std::vector<int> idx = {0, 1, 2, 1, 0, 3, 0, 1, 4};
  EXPECT_THROW(loop_subdivide(p, idx, 1), std::invalid_argument);
}

}  // namespace
}  // namespace bpm
