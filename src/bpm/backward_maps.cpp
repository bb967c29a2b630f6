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
  // Each photon as its code (high half) and its place in src (low half), sorted by code with
  // three passes of a radix sort (10 bits each), then each run of one code by key() (kept beside
  // the codes: the records lie far apart).
  std::vector<const BackwardPhoton*> src;
  std::vector<uint64_t> items, sorted(n), keys;
  src.reserve(n);
  items.reserve(n);
  keys.reserve(n);
  for (const ObjectPhotonLists* l : per_thread)
    if (o < l->size())
      for (const BackwardPhoton& bp : (*l)[o]) {
        const uint32_t code = spread_bits(cell(bp.p.x, b.lo.x, extent.x)) |
                              spread_bits(cell(bp.p.y, b.lo.y, extent.y)) << 1 |
                              spread_bits(cell(bp.p.z, b.lo.z, extent.z)) << 2;
        items.push_back(uint64_t(code) << 32 | src.size());
        src.push_back(&bp);
        keys.push_back(bp.key());
      }
  for (int shift = 32; shift < 62; shift += 10) {
    uint32_t start[1025] = {};
    for (uint64_t v : items) ++start[((v >> shift) & 1023) + 1];
    for (int d = 1; d <= 1024; ++d) start[d] += start[d - 1];
    for (uint64_t v : items) sorted[start[(v >> shift) & 1023]++] = v;
    items.swap(sorted);
  }
  auto photon = [&](uint64_t v) { return src[uint32_t(v)]; };
  for (size_t i = 0, j; i < n; i = j) {
    for (j = i + 1; j < n && items[j] >> 32 == items[i] >> 32;) ++j;
    if (j - i > 1)
      std::sort(items.begin() + long(i), items.begin() + long(j),
                [&](uint64_t a, uint64_t c) { return keys[uint32_t(a)] < keys[uint32_t(c)]; });
  }
  // The records are read out of order: fetched a few ahead.
  constexpr size_t kAhead = 8;
  for (size_t k = 0; k < n; ++k) {
    if (k + kAhead < n) {
      const char* next = reinterpret_cast<const char*>(photon(items[k + kAhead]));
      __builtin_prefetch(next);
      __builtin_prefetch(next + sizeof(BackwardPhoton) - 1);
    }
    dst[k] = *photon(items[k]);
  }
  return n;
}

// Each object's range of the photon array, from the threads' list sizes. The trees of the last
// iteration are rebuilt in place (keeping their memory); those of objects without backward
// photons are emptied.
void lay_out_maps(const std::vector<ObjectPhotonLists*>& per_thread, size_t object_count,
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
}

// Object o's photons into its range of the map, and its two trees.
void build_object_map(std::vector<ObjectPhotonLists*>& per_thread, uint32_t o, bool centre_tree,
                      BackwardMaps* maps) {
  BackwardPhoton* dst = maps->photons.data() + maps->object_begin[o];
  const size_t n = gather_in_space(per_thread, o, dst);
  // Emptied, keeping their memory for the next iteration's eye pass (the memory budget counts
  // two copies of every backward photon).
  for (ObjectPhotonLists* l : per_thread)
    if (o < l->size()) (*l)[o].clear();
  // Per class (caustic, indirect), the spheres that accept it, in one pass over the records.
  std::vector<SphereRef> spheres_of[2];
  std::vector<uint32_t> ids_of[2];
  for (int c = 0; c < 2; ++c) {
    spheres_of[c].reserve(n);
    ids_of[c].reserve(n);
  }
  constexpr uint8_t kAcceptsOf[2] = {kAcceptsCaustic, kAcceptsIndirect};
  for (size_t k = 0; k < n; ++k) {
    const BackwardPhoton& bp = dst[k];
    for (int c = 0; c < 2; ++c)
      if (bp.accepts & kAcceptsOf[c]) {
        spheres_of[c].push_back({bp.p, bp.radius});
        ids_of[c].push_back(maps->object_begin[o] + uint32_t(k));
      }
  }
  for (int c = 0; c < 2; ++c) {
    if (centre_tree)
      maps->centre_trees[2 * o + c].build(spheres_of[c], &ids_of[c]);
    else
      maps->sphere_trees[2 * o + c].build(spheres_of[c], &ids_of[c]);
  }
}

// Buckets: every node of a sphere tree (only leaves are used), one per non-empty centre tree.
void number_buckets(size_t object_count, bool centre_tree, BackwardMaps* maps) {
  const size_t trees = 2 * object_count;
  maps->first_bucket.assign(trees + 1, 0);
  for (size_t t = 0; t < trees; ++t) {
    const uint32_t n =
        centre_tree ? (maps->centre_trees[t].empty() ? 0 : 1) : maps->sphere_trees[t].node_count();
    maps->first_bucket[t + 1] = maps->first_bucket[t] + n;
  }
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
  lay_out_maps(per_thread, object_count, centre_tree, maps);
  std::vector<uint32_t> order;
  for (uint32_t o = 0; o < object_count; ++o)
    if (maps->has_photons(int(o))) order.push_back(o);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return maps->object_begin[a + 1] - maps->object_begin[a] >
           maps->object_begin[b + 1] - maps->object_begin[b];
  });
  // The queue: each worker takes the largest object not yet taken.
  std::atomic<size_t> next{0};
  int workers = tbb::this_task_arena::max_concurrency();
  tbb::parallel_for(
      tbb::blocked_range<int>(0, workers, 1),
      [&](const tbb::blocked_range<int>&) {
        for (size_t k; (k = next.fetch_add(1)) < order.size();)
          build_object_map(per_thread, order[k], centre_tree, maps);
      },
      tbb::simple_partitioner());
  number_buckets(object_count, centre_tree, maps);
}

}  // namespace bpm
