#include "photons/sphere_kdtree.h"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <optional>
#include <tuple>
#include <utility>

namespace bpm {
namespace {

// Cost of descending one level in units of testing one sphere (a node visit is a likely cache
// miss; leaf spheres are tested four at a time from contiguous memory). A split is made only when
// the expected number of sphere tests per query (query points spread uniformly over the cell)
// falls by more than this. Measured (render time at 2 threads against 24, the value before the
// four-wide test): 64 builds the trees in 0.76-0.79 of the time and leaves the light pass as it
// was (1.00-1.01) on caustic-sphere, spot-facets, water-box and lamp-room; 96 and more slow the
// light pass on lamp-room (1.05 at 96, 1.07 at 160).
constexpr float kTraversalCost = 64;
constexpr size_t kMinLeaf = 8;
constexpr int kMaxDepth = 48;
// Cells with more spheres than this take their median from an even sample of this many.
constexpr size_t kSampledMedianMin = 512;
constexpr size_t kMedianSample = 64;
// Cells with at least this many spheres build their two halves as separate tasks (a scene whose
// photons lie mostly on one object would otherwise build its tree on one thread).
constexpr size_t kParallelMin = 16384;

int longest_axis(const Bounds3& b) {
  Vec3 d = b.hi - b.lo;
  return d.x >= d.y && d.x >= d.z ? 0 : (d.y >= d.z ? 1 : 2);
}

Bounds3 sphere_bounds(const SphereRef& s) {
  const Vec3 r(s.r, s.r, s.r);
  return {s.c - r, s.c + r};
}

// The spheres on either side of a plane (one that crosses it on both), and their bounds.
struct Sides {
  std::vector<uint32_t> left, right;
  Bounds3 lbounds, rbounds;
};

void split_at(const std::vector<uint32_t>& ids, const std::vector<SphereRef>& spheres, int axis,
              float at, Sides& sides) {
  sides.left.clear();
  sides.right.clear();
  sides.lbounds = sides.rbounds = Bounds3();
  for (uint32_t i : ids) {
    const SphereRef& s = spheres[i];
    const Bounds3 e = sphere_bounds(s);
    if (s.c[axis] - s.r < at) {
      sides.left.push_back(i);
      sides.lbounds.expand(e);
    }
    if (s.c[axis] + s.r >= at) {
      sides.right.push_back(i);
      sides.rbounds.expand(e);
    }
  }
}

// How many spheres split_at would put on each side.
std::pair<size_t, size_t> count_sides(const std::vector<uint32_t>& ids,
                                      const std::vector<SphereRef>& spheres, int axis, float at) {
  size_t nl = 0, nr = 0;
  for (uint32_t i : ids) {
    const SphereRef& s = spheres[i];
    nl += s.c[axis] - s.r < at;
    nr += s.c[axis] + s.r >= at;
  }
  return std::pair{nl, nr};
}

struct Split {
  int axis;
  float at;
  float cost;
};

// The plane: the median centre on the longest axis (balanced trees for clustered photons), over
// every sphere in a small cell and over an even sample of them in a large one. Where many
// centres share that coordinate (photons on a wall perpendicular to the axis) a plane through
// them puts every such sphere on both sides and splits nothing; then the middle of the axis,
// then the other axes. The first plane that separates some spheres is returned with its cost.
// A small cell counts each candidate's sides before splitting; a large one (`large`) splits at
// once into `sides` (it nearly always pays) and counts the sides it made.
std::optional<Split> choose_split(const std::vector<uint32_t>& ids, const Bounds3& cell,
                                  const std::vector<SphereRef>& spheres, bool large, Sides& sides) {
  const size_t n = ids.size();
  const int first_axis = longest_axis(cell);
  std::optional<Split> best;
  std::vector<float> cs;
  for (int k = 0; k < 3 && !best; ++k) {
    const int axis = (first_axis + k) % 3;
    const float lo = cell.lo[axis], hi = cell.hi[axis];
    if (!(hi > lo)) continue;
    cs.clear();
    const size_t step = large ? n / kMedianSample : 1;
    for (size_t j = 0; j < n; j += step) cs.push_back(spheres[ids[j]].c[axis]);
    std::nth_element(cs.begin(), cs.begin() + cs.size() / 2, cs.end());
    for (float at : {cs[cs.size() / 2], 0.5f * (lo + hi)}) {
      if (!(at > lo && at < hi)) continue;
      size_t nl, nr;
      if (large) {
        split_at(ids, spheres, axis, at, sides);
        nl = sides.left.size();
        nr = sides.right.size();
      } else {
        std::tie(nl, nr) = count_sides(ids, spheres, axis, at);
      }
      if (nl < n && nr < n) {
        const float pl = (at - lo) / (hi - lo);
        best = Split{axis, at, kTraversalCost + pl * float(nl) + (1 - pl) * float(nr)};
        break;
      }
    }
  }
  return best;
}

Bounds3 clip(Bounds3 c, const Bounds3& b) {
  c.lo = vmax(c.lo, b.lo);
  c.hi = vmin(c.hi, b.hi);
  return c;
}

}  // namespace

void SphereKdTree::build(const std::vector<SphereRef>& spheres, const std::vector<uint32_t>* ids) {
  nodes_.clear();
  items_.clear();
  for (auto* v : {&x_, &y_, &z_, &r2_}) v->clear();
  input_count_ = spheres.size();
  if (spheres.empty()) return;
  std::vector<uint32_t> order(spheres.size());
  Bounds3 cell;
  for (uint32_t i = 0; i < order.size(); ++i) {
    order[i] = i;
    cell.expand(extent(spheres[i]));
  }
  nodes_.reserve(2 * spheres.size() / kMinLeaf + 1);
  build_node(order, cell, 0, spheres);
  for (auto* v : {&x_, &y_, &z_}) v->resize(v->size() + kPad, 0.0f);
  r2_.resize(r2_.size() + kPad, -1.0f);  // no squared distance is below it
  nodes_.shrink_to_fit();
  if (ids)
    for (uint32_t& item : items_) item = (*ids)[item];
}

Bounds3 SphereKdTree::extent(const SphereRef& s) { return sphere_bounds(s); }

// `cell` is the node's region of space clipped to the bounds of its spheres (no query outside
// their union finds anything).
void SphereKdTree::build_node(std::vector<uint32_t>& ids, Bounds3 cell, int depth,
                              const std::vector<SphereRef>& spheres) {
  uint32_t self = uint32_t(nodes_.size());
  nodes_.push_back({});
  auto make_leaf = [&] {
    nodes_[self] = {0, kLeaf, uint32_t(items_.size()), uint32_t(ids.size())};
    for (uint32_t i : ids) add_slot(i, spheres[i]);
  };
  const size_t n = ids.size();
  if (n <= kMinLeaf || depth >= kMaxDepth) return make_leaf();
  // The first plane that separates some spheres is kept if it pays.
  const bool large = n > kSampledMedianMin;
  Sides sides;
  const std::optional<Split> best = choose_split(ids, cell, spheres, large, sides);
  if (!best || best->cost >= float(n)) return make_leaf();
  const int axis = best->axis;
  const float at = best->at;
  if (!large) split_at(ids, spheres, axis, at, sides);
  std::vector<uint32_t>().swap(ids);
  Bounds3 lcell = cell, rcell = cell;
  lcell.hi[axis] = at;
  rcell.lo[axis] = at;
  lcell = clip(lcell, sides.lbounds);
  rcell = clip(rcell, sides.rbounds);
  uint32_t right_index;
  if (n >= kParallelMin) {
    // Both halves as subtrees of their own, appended in the order the serial build lays them out:
    // the tree is the same whatever the threads did.
    SphereKdTree l, r;
    tbb::parallel_invoke([&] { l.build_node(sides.left, lcell, depth + 1, spheres); },
                         [&] { r.build_node(sides.right, rcell, depth + 1, spheres); });
    append(l);
    right_index = uint32_t(nodes_.size());
    append(r);
  } else {
    build_node(sides.left, lcell, depth + 1, spheres);
    std::vector<uint32_t>().swap(sides.left);
    right_index = uint32_t(nodes_.size());
    build_node(sides.right, rcell, depth + 1, spheres);
  }
  nodes_[self] = {at, uint32_t(axis), right_index, 0};
}

void SphereKdTree::append(const SphereKdTree& sub) {
  const uint32_t node_base = uint32_t(nodes_.size()), item_base = uint32_t(items_.size());
  for (Node node : sub.nodes_) {
    node.a += node.axis == kLeaf ? item_base : node_base;
    nodes_.push_back(node);
  }
  items_.insert(items_.end(), sub.items_.begin(), sub.items_.end());
  x_.insert(x_.end(), sub.x_.begin(), sub.x_.end());
  y_.insert(y_.end(), sub.y_.begin(), sub.y_.end());
  z_.insert(z_.end(), sub.z_.begin(), sub.z_.end());
  r2_.insert(r2_.end(), sub.r2_.begin(), sub.r2_.end());
}

void SphereKdTree::add_slot(uint32_t item, const SphereRef& s) {
  items_.push_back(item);
  x_.push_back(s.c.x);
  y_.push_back(s.c.y);
  z_.push_back(s.c.z);
  r2_.push_back(s.r * s.r);
}

size_t SphereKdTree::bytes() const {
  return nodes_.size() * sizeof(Node) + items_.size() * sizeof(uint32_t) +
         (x_.size() + y_.size() + z_.size() + r2_.size()) * sizeof(float);
}

double SphereKdTree::duplication() const {
  return input_count_ ? double(items_.size()) / double(input_count_) : 0.0;
}

void CentreKdTree::build(const std::vector<SphereRef>& spheres, const std::vector<uint32_t>* ids) {
  nodes_.clear();
  max_radius_ = 0;
  spheres_ = spheres;
  items_.resize(spheres.size());
  for (uint32_t i = 0; i < items_.size(); ++i) {
    items_[i] = ids ? (*ids)[i] : i;
    max_radius_ = std::max(max_radius_, spheres[i].r);
  }
  if (spheres.empty()) return;
  nodes_.reserve(2 * spheres.size() / 8 + 1);
  build_node(0, uint32_t(spheres.size()), 0);
}

void CentreKdTree::build_node(uint32_t begin, uint32_t end, int depth) {
  uint32_t self = uint32_t(nodes_.size());
  nodes_.push_back({0, kLeaf, begin, end - begin});
  if (end - begin <= 8 || depth >= 60) return;
  Bounds3 b;
  for (uint32_t k = begin; k < end; ++k) b.expand(spheres_[k].c);
  int axis = longest_axis(b);
  if (!(b.hi[axis] > b.lo[axis])) return;
  uint32_t mid = begin + (end - begin) / 2;
  // Keep items_ and spheres_ in step: sort an index permutation, then apply it.
  std::vector<uint32_t> perm(end - begin);
  for (uint32_t k = 0; k < perm.size(); ++k) perm[k] = begin + k;
  std::nth_element(
      perm.begin(), perm.begin() + (mid - begin), perm.end(),
      [&](uint32_t x, uint32_t y) { return spheres_[x].c[axis] < spheres_[y].c[axis]; });
  std::vector<SphereRef> s(perm.size());
  std::vector<uint32_t> it(perm.size());
  for (uint32_t k = 0; k < perm.size(); ++k) {
    s[k] = spheres_[perm[k]];
    it[k] = items_[perm[k]];
  }
  std::copy(s.begin(), s.end(), spheres_.begin() + begin);
  std::copy(it.begin(), it.end(), items_.begin() + begin);
  float split = spheres_[mid].c[axis];
  build_node(begin, mid, depth + 1);
  uint32_t right_index = uint32_t(nodes_.size());
  build_node(mid, end, depth + 1);
  nodes_[self] = {split, uint32_t(axis), right_index, 0};
}

size_t CentreKdTree::bytes() const {
  return nodes_.size() * sizeof(Node) + items_.size() * (sizeof(uint32_t) + sizeof(SphereRef));
}

}  // namespace bpm
