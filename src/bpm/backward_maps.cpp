#include "bpm/backward_maps.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <numeric>

namespace bpm {
namespace {

// The low 10 bits of v spread to every third bit.
uint32_t spread_bits(uint32_t v) {
  v &= 0x3ffu;
  v = (v | (v << 16)) & 0x030000ffu;
  v = (v | (v << 8)) & 0x0300f00fu;
  v = (v | (v << 4)) & 0x030c30c3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

// Gathers one object's backward photons from the threads' lists into dst, sorted along a Morton
// curve through their bounds (ties, which photons in one of its 2^30 cells are, by key(): the
// order does not depend on the threads). A query's leaf then names photons that lie together in
// memory; in pixel order each one it accepts was a cache miss. Returns how many there were.
size_t gather_in_space(const std::vector<ObjectPhotonLists*>& per_thread, uint32_t o,
                       BackwardPhoton* dst) {
  Bounds3 b;
  size_t n = 0;
  for (const ObjectPhotonLists* l : per_thread)
    if (o < l->size())
      for (const BackwardPhoton& bp : (*l)[o]) {
        b.expand(bp.p);
        ++n;
      }
  const Vec3 extent = b.hi - b.lo;
  auto cell = [](float x, float lo, float size) {
    return size > 0 ? uint32_t(std::clamp((x - lo) / size * 1024.0f, 0.0f, 1023.0f)) : 0u;
  };
  struct Item {
    uint32_t code;
    uint64_t key;
    const BackwardPhoton* photon;
  };
  std::vector<Item> items;
  items.reserve(n);
  for (const ObjectPhotonLists* l : per_thread)
    if (o < l->size())
      for (const BackwardPhoton& bp : (*l)[o])
        items.push_back({spread_bits(cell(bp.p.x, b.lo.x, extent.x)) |
                             spread_bits(cell(bp.p.y, b.lo.y, extent.y)) << 1 |
                             spread_bits(cell(bp.p.z, b.lo.z, extent.z)) << 2,
                         bp.key(), &bp});
  std::sort(items.begin(), items.end(), [](const Item& a, const Item& c) {
    return a.code != c.code ? a.code < c.code : a.key < c.key;
  });
  for (size_t k = 0; k < n; ++k) dst[k] = *items[k].photon;
  return n;
}

}  // namespace

size_t BackwardMaps::tree_bytes() const {
  size_t b = 0;
  for (const auto& t : sphere_trees) b += t.bytes();
  for (const auto& t : centre_trees) b += t.bytes();
  return b;
}

void build_backward_maps(std::vector<ObjectPhotonLists*>& per_thread, size_t object_count,
                         bool centre_tree, BackwardMaps* maps) {
  maps->centre_tree = centre_tree;
  maps->object_begin.assign(object_count + 1, 0);
  for (size_t o = 0; o < object_count; ++o) {
    size_t n = 0;
    for (ObjectPhotonLists* l : per_thread)
      if (o < l->size()) n += (*l)[o].size();
    maps->object_begin[o + 1] = maps->object_begin[o] + uint32_t(n);
  }
  maps->photons.resize(maps->object_begin[object_count]);
  // The trees of the last iteration are rebuilt in place (keeping their memory); those of objects
  // without backward photons are emptied.
  if (centre_tree) {
    maps->sphere_trees.clear();
    maps->centre_trees.resize(2 * object_count);
  } else {
    maps->centre_trees.clear();
    maps->sphere_trees.resize(2 * object_count);
  }
  for (size_t o = 0; o < object_count; ++o)
    if (!maps->has_photons(int(o)))
      for (size_t t = 2 * o; t < 2 * o + 2; ++t) {
        if (centre_tree)
          maps->centre_trees[t].build({});
        else
          maps->sphere_trees[t].build({});
      }

  std::vector<uint32_t> order;
  for (uint32_t o = 0; o < object_count; ++o)
    if (maps->has_photons(int(o))) order.push_back(o);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return maps->object_begin[a + 1] - maps->object_begin[a] >
           maps->object_begin[b + 1] - maps->object_begin[b];
  });
  auto build_one = [&](uint32_t o) {
    BackwardPhoton* dst = maps->photons.data() + maps->object_begin[o];
    const size_t n = gather_in_space(per_thread, o, dst);
    // Emptied, keeping their memory for the next iteration's eye pass (the memory budget counts
    // two copies of every backward photon).
    for (ObjectPhotonLists* l : per_thread)
      if (o < l->size()) (*l)[o].clear();
    for (int c = 0; c < 2; ++c) {
      const uint8_t accepts = c == 0 ? kAcceptsCaustic : kAcceptsIndirect;
      std::vector<SphereRef> spheres;
      std::vector<uint32_t> ids;
      for (size_t k = 0; k < n; ++k)
        if (dst[k].accepts & accepts) {
          spheres.push_back({dst[k].p, dst[k].radius});
          ids.push_back(maps->object_begin[o] + uint32_t(k));
        }
      if (centre_tree)
        maps->centre_trees[2 * o + c].build(spheres, &ids);
      else
        maps->sphere_trees[2 * o + c].build(spheres, &ids);
    }
  };
  // The queue: each worker takes the largest object not yet taken.
  std::atomic<size_t> next{0};
  int workers = tbb::this_task_arena::max_concurrency();
  tbb::parallel_for(
      tbb::blocked_range<int>(0, workers, 1),
      [&](const tbb::blocked_range<int>&) {
        for (size_t k; (k = next.fetch_add(1)) < order.size();) build_one(order[k]);
      },
      tbb::simple_partitioner());
  // Buckets: every node of a sphere tree (only leaves are used), one per non-empty centre tree.
  const size_t trees = 2 * object_count;
  maps->first_bucket.assign(trees + 1, 0);
  for (size_t t = 0; t < trees; ++t) {
    const uint32_t n =
        centre_tree ? (maps->centre_trees[t].empty() ? 0 : 1) : maps->sphere_trees[t].node_count();
    maps->first_bucket[t + 1] = maps->first_bucket[t] + n;
  }
}

}  // namespace bpm
