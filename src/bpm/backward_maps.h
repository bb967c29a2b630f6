// The backward photon maps of one iteration: every backward photon of the eye pass, grouped by
// scene object, and per object one kd-tree for each class of photon (section 2 of the paper:
// per-object maps keep trees small and light from leaking between objects; per class, a caustic
// photon tests only the small caustic spheres and an indirect photon only the spheres that accept
// it). A backward photon that accepts both classes is in both trees.
#pragma once
#include <cstdint>
#include <vector>

#include "bpm/backward_photon.h"
#include "bpm/eye_pass.h"
#include "photons/sphere_kdtree.h"

namespace bpm {

struct BackwardMaps {
  // Object by object; within an object along a Morton curve, ties by key().
  std::vector<BackwardPhoton> photons;
  std::vector<uint32_t>
      object_begin;  // photons of object o: [object_begin[o], object_begin[o + 1])
  bool centre_tree = false;
  // Index 2 * object + tree_class(class); items are global photon indices.
  std::vector<SphereKdTree> sphere_trees;  // empty when centre_tree
  std::vector<CentreKdTree> centre_trees;  // empty unless centre_tree

  static int tree_class(PhotonClass c) { return c == PhotonClass::kCaustic ? 0 : 1; }
  bool has_photons(int object) const { return object_begin[object + 1] > object_begin[object]; }
  // Calls f(global index) for every backward photon of `object` that accepts class `cls` (caustic
  // or indirect) and whose sphere contains p.
  template <class F>
  void query(int object, PhotonClass cls, Vec3 p, F&& f) const {
    const size_t t = 2 * size_t(object) + size_t(tree_class(cls));
    if (centre_tree)
      centre_trees[t].query(p, f);
    else
      sphere_trees[t].query(p, f);
  }
  // Queries grouped by bucket are answered from cache (the light pass gathers its hits bucket by
  // bucket): a bucket is a leaf of a sphere tree, or a whole centre tree. Buckets are numbered
  // over all trees, tree by tree; first_bucket has one more entry than there are trees.
  static constexpr uint32_t kNoBucket = ~0u;  // the tree is empty: the query finds nothing
  std::vector<uint32_t> first_bucket;
  uint32_t bucket_count() const { return first_bucket.empty() ? 0 : first_bucket.back(); }
  uint32_t bucket_of(int object, PhotonClass cls, Vec3 p) const {
    const size_t t = 2 * size_t(object) + size_t(tree_class(cls));
    if (first_bucket[t] == first_bucket[t + 1]) return kNoBucket;
    return centre_tree ? first_bucket[t] : first_bucket[t] + sphere_trees[t].leaf_of(p);
  }
  // query() for a point of bucket b (bucket_of(object, cls, p), not kNoBucket): the same photons,
  // in the same order.
  template <class F>
  void query_bucket(uint32_t b, int object, PhotonClass cls, Vec3 p, F&& f) const {
    const size_t t = 2 * size_t(object) + size_t(tree_class(cls));
    if (centre_tree)
      centre_trees[t].query(p, f);
    else
      sphere_trees[t].query_leaf(b - first_bucket[t], p, f);
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
