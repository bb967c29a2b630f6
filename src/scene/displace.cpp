#include "scene/displace.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>

namespace bpm {
namespace {

// Sum of each triangle's unit normal (counter-clockwise) at its corners, normalised.
std::vector<Vec3> vertex_normals(const std::vector<Vec3>& p, const std::vector<int>& indices) {
  std::vector<Vec3> n(p.size(), Vec3(0, 0, 0));
  for (size_t i = 0; i + 2 < indices.size(); i += 3) {
    const int a = indices[i], b = indices[i + 1], c = indices[i + 2];
    const Vec3 f = cross(p[size_t(b)] - p[size_t(a)], p[size_t(c)] - p[size_t(b)]);
    const float len = length(f);
    if (!(len > 0)) continue;
    for (int v : {a, b, c}) n[size_t(v)] = n[size_t(v)] + f / len;
  }
  for (Vec3& v : n)
    if (length(v) > 0) v = normalize(v);
  return n;
}

class Refiner {
 public:
  Refiner(PlyMesh* mesh, const Transform& world_from_object, float edge_length)
      : m_(*mesh), xf_(world_from_object), max_(edge_length) {}

  // Splits triangle (v0, v1, v2) at the midpoint of its longest edge until every edge is shorter
  // than the limit; appends the pieces to out, in the triangle's winding.
  void refine(int v0, int v1, int v2, std::vector<int>* out) {
    const float d01 = distance(v0, v1), d12 = distance(v1, v2), d20 = distance(v2, v0);
    if (d01 < max_ && d12 < max_ && d20 < max_) {
      out->insert(out->end(), {v0, v1, v2});
      return;
    }
    std::array<int, 3> v;  // the longest edge first, the winding kept
    if (d01 > d12)
      v = d01 > d20 ? std::array<int, 3>{v0, v1, v2} : std::array<int, 3>{v2, v0, v1};
    else
      v = d12 > d20 ? std::array<int, 3>{v1, v2, v0} : std::array<int, 3>{v2, v0, v1};
    const int mid = midpoint(v[0], v[1]);
    refine(v[0], mid, v[2], out);
    refine(mid, v[1], v[2], out);
  }

 private:
  float distance(int a, int b) const {
    return length(xf_.point(m_.positions[size_t(a)]) - xf_.point(m_.positions[size_t(b)]));
  }
  int midpoint(int a, int b) {
    const uint64_t key = (uint64_t(uint32_t(std::min(a, b))) << 32) | uint32_t(std::max(a, b));
    const auto [it, added] = split_.try_emplace(key, int(m_.positions.size()));
    if (!added) return it->second;
    const size_t i = size_t(a), j = size_t(b);
    m_.positions.push_back((m_.positions[i] + m_.positions[j]) * 0.5f);
    const Vec3 n = m_.normals[i] + m_.normals[j];
    m_.normals.push_back(length(n) > 0 ? normalize(n) : m_.normals[i]);
    m_.uvs.push_back((m_.uvs[i] + m_.uvs[j]) * 0.5f);
    return it->second;
  }
  PlyMesh& m_;
  const Transform& xf_;
  float max_;
  std::unordered_map<uint64_t, int> split_;
};

}  // namespace

size_t displaced_triangle_count(const PlyMesh& mesh, const Transform& world_from_object,
                                float edge_length) {
  // Each split halves the longest edge: a triangle whose longest edge is L becomes about
  // (2 L / edge_length)^2 pieces at most.
  double total = 0;
  for (size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
    float longest = 0;
    for (int k = 0; k < 3; ++k) {
      const Vec3 a = world_from_object.point(mesh.positions[size_t(mesh.indices[i + size_t(k)])]);
      const Vec3 b =
          world_from_object.point(mesh.positions[size_t(mesh.indices[i + size_t(k + 1) % 3])]);
      longest = std::max(longest, length(a - b));
    }
    const double r = std::floor(double(longest) / edge_length) + 1;
    total += longest < edge_length ? 1 : 2 * r * r;
  }
  return total > 1e18 ? size_t(1e18) : size_t(total);
}

void displace_mesh(PlyMesh* mesh, const Transform& world_from_object, float edge_length,
                   const std::function<float(Vec3 p, Vec2 uv)>& displacement) {
  if (mesh->normals.size() != mesh->positions.size())
    mesh->normals = vertex_normals(mesh->positions, mesh->indices);
  std::vector<int> refined;
  refined.reserve(mesh->indices.size());
  Refiner refiner(mesh, world_from_object, edge_length);
  for (size_t i = 0; i + 2 < mesh->indices.size(); i += 3)
    refiner.refine(mesh->indices[i], mesh->indices[i + 1], mesh->indices[i + 2], &refined);
  mesh->indices = std::move(refined);
  for (size_t v = 0; v < mesh->positions.size(); ++v)
    mesh->positions[v] =
        mesh->positions[v] + mesh->normals[v] * displacement(mesh->positions[v], mesh->uvs[v]);
  mesh->normals = vertex_normals(mesh->positions, mesh->indices);
}

}  // namespace bpm
