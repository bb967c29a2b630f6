// The backward maps' buckets: a query made in two steps (the bucket of its point, then the query in
// that bucket), as the light pass gathers its hits, finds what a plain query finds, in its order.
#include "bpm/backward_maps.h"

#include <gtest/gtest.h>

#include "base/rng.h"

namespace bpm {
namespace {

TEST(BackwardMaps, BucketQueriesFindWhatQueriesFind) {
  // Object 0 has no backward photons; object 1 has caustic-only, indirect-only and both; object 2
  // has indirect ones only, so its caustic tree is empty.
  Rng rng(stream_key(11, 0));
  ObjectPhotonLists lists(3);
  for (uint32_t i = 0; i < 3000; ++i) {
    BackwardPhoton bp{};
    bp.p = Vec3(rng.uniform() * 4, rng.uniform() * 4, rng.uniform() * 0.1f);
    bp.radius = i % 5 == 0 ? 0.3f * rng.uniform() : 0.05f * rng.uniform();
    bp.pixel = i;
    const uint32_t object = i % 3 == 0 ? 2 : 1;
    bp.accepts = object == 2 ? uint8_t(kAcceptsIndirect)
                             : uint8_t(1 + i % 3);  // caustic, indirect or both (AcceptMask bits)
    lists[object].push_back(bp);
  }
  for (bool centre_tree : {false, true}) {
    ObjectPhotonLists copy = lists;
    std::vector<ObjectPhotonLists*> per_thread{&copy};
    BackwardMaps maps;
    build_backward_maps(per_thread, 3, centre_tree, &maps);
    size_t found = 0;
    for (int q = 0; q < 2000; ++q) {
      const Vec3 p(rng.uniform() * 4.4f - 0.2f, rng.uniform() * 4.4f - 0.2f, rng.uniform() * 0.2f);
      for (int object = 0; object < 3; ++object)
        for (PhotonClass cls : {PhotonClass::kCaustic, PhotonClass::kIndirect}) {
          std::vector<uint32_t> plain, bucketed;
          maps.query(object, cls, p, [&](uint32_t g) { plain.push_back(g); });
          const uint32_t b = maps.bucket_of(object, cls, p);
          const bool empty_tree = object == 0 || (object == 2 && cls == PhotonClass::kCaustic);
          ASSERT_EQ(b == BackwardMaps::kNoBucket, empty_tree) << object << " " << centre_tree;
          if (b != BackwardMaps::kNoBucket) {
            ASSERT_LT(b, maps.bucket_count());
            maps.query_bucket(b, object, cls, p, [&](uint32_t g) { bucketed.push_back(g); });
          }
          ASSERT_EQ(bucketed, plain) << "object " << object << ", centre tree " << centre_tree;
          found += plain.size();
        }
    }
    EXPECT_GT(found, 1000u) << "the queries should find backward photons";
  }
}

}  // namespace
}  // namespace bpm
