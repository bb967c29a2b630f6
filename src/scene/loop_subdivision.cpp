#include "scene/loop_subdivision.h"

#include <cmath>
#include <stdexcept>
#include <unordered_map>

namespace bpm {
namespace {

uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return uint64_t(uint32_t(a)) << 32 | uint32_t(b);
}

// Edges with the vertices opposite them, and each vertex's neighbours.
struct Topology {
  struct Edge {
    int a, b;
    int opposite[2] = {-1, -1};
    int faces = 0;
  };
  std::vector<Edge> edges;
  std::unordered_map<uint64_t, int> edge_of;
  std::vector<std::vector<int>> neighbours;  // distinct vertices sharing an edge
  std::vector<std::vector<int>> boundary;    // neighbours along boundary edges

  Topology(size_t n_vertices, const std::vector<int>& idx)
      : neighbours(n_vertices), boundary(n_vertices) {
    for (size_t f = 0; f + 2 < idx.size(); f += 3)
      for (int k = 0; k < 3; ++k) {
        int a = idx[f + k], b = idx[f + (k + 1) % 3], c = idx[f + (k + 2) % 3];
        auto [it, fresh] = edge_of.emplace(edge_key(a, b), int(edges.size()));
        if (fresh) edges.push_back(Edge{a, b});
        Edge& e = edges[it->second];
        if (e.faces == 2)
          throw std::invalid_argument("an edge is shared by more than two triangles");
        e.opposite[e.faces++] = c;
      }
    for (const Edge& e : edges) {
      neighbours[e.a].push_back(e.b);
      neighbours[e.b].push_back(e.a);
      if (e.faces == 1) {
        boundary[e.a].push_back(e.b);
        boundary[e.b].push_back(e.a);
      }
    }
  }
  bool on_boundary(int v) const { return !boundary[v].empty(); }
};

// Loop's weight of each neighbour of an interior vertex of valence n.
float beta(size_t n) { return n == 3 ? 3.0f / 16 : 3.0f / (8.0f * float(n)); }

Vec3 sum_of(const std::vector<Vec3>& p, const std::vector<int>& ids) {
  Vec3 s(0, 0, 0);
  for (int i : ids) s = s + p[i];
  return s;
}

void subdivide_once(std::vector<Vec3>& p, std::vector<int>& idx) {
  Topology t(p.size(), idx);
  std::vector<Vec3> q(p.size() + t.edges.size());
  // Vertex (even) rule.
  for (size_t v = 0; v < p.size(); ++v) {
    const auto& nb = t.neighbours[v];
    if (nb.empty()) {
      q[v] = p[v];
    } else if (t.on_boundary(int(v))) {
      q[v] = t.boundary[v].size() == 2
                 ? p[v] * 0.75f + (p[t.boundary[v][0]] + p[t.boundary[v][1]]) * 0.125f
                 : p[v];
    } else {
      float b = beta(nb.size());
      q[v] = p[v] * (1 - float(nb.size()) * b) + sum_of(p, nb) * b;
    }
  }
  // Edge (odd) rule.
  for (size_t e = 0; e < t.edges.size(); ++e) {
    const auto& ed = t.edges[e];
    Vec3& out = q[p.size() + e];
    if (ed.faces == 2)
      out = (p[ed.a] + p[ed.b]) * 0.375f + (p[ed.opposite[0]] + p[ed.opposite[1]]) * 0.125f;
    else
      out = (p[ed.a] + p[ed.b]) * 0.5f;
  }
  // Each triangle into four, keeping the winding.
  std::vector<int> next;
  next.reserve(idx.size() * 4);
  const int base = int(p.size());
  for (size_t f = 0; f + 2 < idx.size(); f += 3) {
    int a = idx[f], b = idx[f + 1], c = idx[f + 2];
    int ab = base + t.edge_of.at(edge_key(a, b)), bc = base + t.edge_of.at(edge_key(b, c)),
        ca = base + t.edge_of.at(edge_key(c, a));
    for (int v : {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca}) next.push_back(v);
  }
  p.swap(q);
  idx.swap(next);
}

}  // namespace

SubdividedMesh loop_subdivide(const std::vector<Vec3>& positions, const std::vector<int>& indices,
                              int levels) {
  SubdividedMesh m;
  m.positions = positions;
  m.indices = indices;
  for (int l = 0; l < levels; ++l) subdivide_once(m.positions, m.indices);
  // Limit positions.
  Topology t(m.positions.size(), m.indices);
  std::vector<Vec3> limit(m.positions.size());
  for (size_t v = 0; v < m.positions.size(); ++v) {
    const auto& nb = t.neighbours[v];
    const Vec3& p = m.positions[v];
    if (nb.empty()) {
      limit[v] = p;
    } else if (t.on_boundary(int(v))) {
      limit[v] =
          t.boundary[v].size() == 2
              ? p * 0.6f + (m.positions[t.boundary[v][0]] + m.positions[t.boundary[v][1]]) * 0.2f
              : p;
    } else {
      float g = 1 / (float(nb.size()) + 3 / (8 * beta(nb.size())));
      limit[v] = p * (1 - float(nb.size()) * g) + sum_of(m.positions, nb) * g;
    }
  }
  m.positions.swap(limit);
  // Area-weighted vertex normals of the limit mesh.
  m.normals.assign(m.positions.size(), Vec3(0, 0, 0));
  for (size_t f = 0; f + 2 < m.indices.size(); f += 3) {
    int a = m.indices[f], b = m.indices[f + 1], c = m.indices[f + 2];
    Vec3 n = cross(m.positions[b] - m.positions[a], m.positions[c] - m.positions[a]);
    for (int v : {a, b, c}) m.normals[v] = m.normals[v] + n;
  }
  for (Vec3& n : m.normals) {
    float l = length(n);
    n = l > 0 ? n / l : Vec3(0, 0, 1);
  }
  return m;
}

}  // namespace bpm
