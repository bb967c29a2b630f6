// The backward photon maps of one iteration: every backward photon of the eye pass, grouped by
// scene object, and one kd-tree per object (section 2 of the paper: per-object maps keep trees
// small and light from leaking between objects).
#pragma once
#include <cstdint>
#include <vector>

#include "bpm/backward_photon.h"
#include "bpm/eye_pass.h"
#include "photons/sphere_kdtree.h"

namespace bpm {

struct BackwardMaps {
  std::vector<BackwardPhoton> photons;  // object by object; within an object sorted by key()
  std::vector<uint32_t>
      object_begin;  // photons of object o: [object_begin[o], object_begin[o + 1])
  bool centre_tree = false;
  std::vector<SphereKdTree> sphere_trees;  // per object (empty when centre_tree)
  std::vector<CentreKdTree> centre_trees;  // per object (empty unless centre_tree)

  bool has_photons(int object) const { return object_begin[object + 1] > object_begin[object]; }
  // Calls f(global index) for every backward photon of `object` whose sphere contains p.
  template <class F>
  void query(int object, Vec3 p, F&& f) const {
    uint32_t base = object_begin[object];
    auto g = [&](uint32_t local) { f(base + local); };
    if (centre_tree)
      centre_trees[object].query(p, g);
    else
      sphere_trees[object].query(p, g);
  }
  size_t photon_bytes() const { return photons.size() * sizeof(BackwardPhoton); }
  size_t tree_bytes() const;
};

// Merges the threads' per-object lists (in an order that does not depend on the threads) and
// builds the trees in parallel: objects sorted by photon count, largest first, taken from a
// queue by free threads (section 3). The lists are emptied.
void build_backward_maps(std::vector<ObjectPhotonLists*>& per_thread, size_t object_count,
                         bool centre_tree, BackwardMaps* maps);

}  // namespace bpm
