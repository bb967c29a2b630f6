// Per-object kd-trees over backward photons (section 2 of the paper).
//
// SphereKdTree stores whole integration spheres: a sphere goes into every leaf whose cell it
// overlaps, so a query point descends to exactly one leaf and tests only the spheres there.
// CentreKdTree is the classic tree over sphere centres, queried by a range search with the
// largest radius; it is kept behind a switch so that the paper's claim (the sphere tree builds
// 1.5-2x slower but answers much faster) can be measured.
#pragma once
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <cmath>
#include <cstdint>
#include <vector>

#include "base/vec.h"

namespace bpm {

struct SphereRef {
  Vec3 c;
  float r;
};

class SphereKdTree {
 public:
  // Queries report sphere i as ids[i] when ids are given (one per sphere), else as i.
  void build(const std::vector<SphereRef>& spheres, const std::vector<uint32_t>* ids = nullptr);
  // Calls f(i) for every sphere i with |p - c_i| < r_i.
  template <class F>
  void query(Vec3 p, F&& f) const {
    if (!nodes_.empty()) query_leaf(leaf_of(p), p, f);
  }
  // A query in two steps, so that queries can be grouped by leaf (their spheres are then read
  // from cache): the leaf p descends to (a node index, below node_count(); the tree must not be
  // empty), and the query's tests in that leaf. query_leaf(leaf_of(p), p, f) is query(p, f).
  uint32_t leaf_of(Vec3 p) const {
    uint32_t n = 0;
    while (nodes_[n].axis != kLeaf) n = p[nodes_[n].axis] < nodes_[n].split ? n + 1 : nodes_[n].a;
    return n;
  }
  uint32_t node_count() const { return uint32_t(nodes_.size()); }
  template <class F>
  void query_leaf(uint32_t leaf, Vec3 p, F&& f) const {
    const uint32_t begin = nodes_[leaf].a, end = begin + nodes_[leaf].b;
#if defined(__SSE2__)
    // Four spheres per step (the arrays are padded, so a step may read past the leaf); the same
    // float operations as the scalar test below, so the same spheres are found, in slot order
    // (where the compiler contracts neither into fused multiply-adds: the default build has none).
    const __m128 px = _mm_set1_ps(p.x), py = _mm_set1_ps(p.y), pz = _mm_set1_ps(p.z);
    for (uint32_t k = begin; k < end; k += 4) {
      const __m128 dx = _mm_sub_ps(px, _mm_loadu_ps(&x_[k]));
      const __m128 dy = _mm_sub_ps(py, _mm_loadu_ps(&y_[k]));
      const __m128 dz = _mm_sub_ps(pz, _mm_loadu_ps(&z_[k]));
      const __m128 d2 =
          _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
      uint32_t hits = uint32_t(_mm_movemask_ps(_mm_cmplt_ps(d2, _mm_loadu_ps(&r2_[k]))));
      if (end - k < 4) hits &= (1u << (end - k)) - 1;
      for (; hits; hits &= hits - 1) f(items_[k + uint32_t(__builtin_ctz(hits))]);
    }
#else
    for (uint32_t k = begin; k < end; ++k)
      if (length_squared(p - Vec3(x_[k], y_[k], z_[k])) < r2_[k]) f(items_[k]);
#endif
  }
  // How many spheres a query at p tests (the size of its leaf).
  size_t tests_at(Vec3 p) const {
    if (nodes_.empty()) return 0;
    uint32_t n = 0;
    while (nodes_[n].axis != kLeaf) n = p[nodes_[n].axis] < nodes_[n].split ? n + 1 : nodes_[n].a;
    return nodes_[n].b;
  }
  size_t bytes() const;
  // Sphere references stored in leaves, and that over the spheres given (1: no duplication).
  size_t reference_count() const { return items_.size(); }
  double duplication() const;

 private:
  static constexpr uint32_t kLeaf = 3;
  struct Node {
    float split;
    uint32_t axis;  // 0..2, or kLeaf
    uint32_t a;     // inner: right child (the left child follows the node); leaf: first item
    uint32_t b;     // leaf: item count
  };
  void build_node(std::vector<uint32_t>& ids, Bounds3 cell, int depth,
                  const std::vector<SphereRef>& spheres);
  static Bounds3 extent(const SphereRef& s);  // the sphere's bounding box
  // Appends a subtree built on its own (its node and item indices shifted).
  void append(const SphereKdTree& sub);
  std::vector<Node> nodes_;
  // Per leaf slot: the sphere's index, and its centre and squared radius (a copy, for locality;
  // in separate arrays, padded by kPad slots that match nothing, for testing four at a time).
  static constexpr uint32_t kPad = 3;
  void add_slot(uint32_t item, const SphereRef& s);
  std::vector<uint32_t> items_;
  std::vector<float> x_, y_, z_, r2_;
  size_t input_count_ = 0;
};

class CentreKdTree {
 public:
  // Queries report sphere i as ids[i] when ids are given (one per sphere), else as i.
  void build(const std::vector<SphereRef>& spheres, const std::vector<uint32_t>* ids = nullptr);
  bool empty() const { return nodes_.empty(); }
  // Calls f(i) for every sphere i with |p - c_i| < r_i (a range search with the largest radius).
  template <class F>
  void query(Vec3 p, F&& f) const {
    traverse(p, max_radius_, [&](uint32_t k) {
      const SphereRef& s = spheres_[k];
      if (length_squared(p - s.c) < s.r * s.r) f(items_[k]);
    });
  }
  // Calls f(i) for every centre within `radius` of p, whatever the spheres' radii (a point
  // kd-tree, as forward photon maps use).
  template <class F>
  void query_within(Vec3 p, float radius, F&& f) const {
    traverse(p, radius, [&](uint32_t k) {
      if (length_squared(p - spheres_[k].c) < radius * radius) f(items_[k]);
    });
  }
  size_t bytes() const;

 private:
  static constexpr uint32_t kLeaf = 3;
  struct Node {
    float split;
    uint32_t axis, a, b;
  };
  void build_node(uint32_t begin, uint32_t end, int depth);
  // Visits every leaf slot k whose centre may lie within R of p.
  template <class G>
  void traverse(Vec3 p, float R, G&& g) const {
    if (nodes_.empty()) return;
    uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      uint32_t self = stack[--top];
      const Node& nd = nodes_[self];
      if (nd.axis == kLeaf) {
        for (uint32_t k = nd.a, e = nd.a + nd.b; k < e; ++k) g(k);
        continue;
      }
      float d = p[nd.axis] - nd.split;
      uint32_t near = d < 0 ? self + 1 : nd.a, far = d < 0 ? nd.a : self + 1;
      if (std::fabs(d) < R) stack[top++] = far;
      stack[top++] = near;
    }
  }
  std::vector<Node> nodes_;
  std::vector<uint32_t> items_;
  std::vector<SphereRef> spheres_;
  float max_radius_ = 0;
};

}  // namespace bpm
