#include "bpm/backward_maps.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <numeric>

namespace bpm {

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
  maps->sphere_trees.clear();
  maps->centre_trees.clear();
  if (centre_tree)
    maps->centre_trees.resize(2 * object_count);
  else
    maps->sphere_trees.resize(2 * object_count);

  std::vector<uint32_t> order;
  for (uint32_t o = 0; o < object_count; ++o)
    if (maps->has_photons(int(o))) order.push_back(o);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return maps->object_begin[a + 1] - maps->object_begin[a] >
           maps->object_begin[b + 1] - maps->object_begin[b];
  });
  auto build_one = [&](uint32_t o) {
    BackwardPhoton* dst = maps->photons.data() + maps->object_begin[o];
    size_t n = 0;
    for (ObjectPhotonLists* l : per_thread) {
      if (o >= l->size()) continue;
      std::vector<BackwardPhoton>& src = (*l)[o];
      std::copy(src.begin(), src.end(), dst + n);
      n += src.size();
      std::vector<BackwardPhoton>().swap(src);
    }
    std::sort(dst, dst + n,
              [](const BackwardPhoton& a, const BackwardPhoton& b) { return a.key() < b.key(); });
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
}

}  // namespace bpm
