#include "bpm/medium_spheres.h"

#include <embree3/rtcore.h>

#include <algorithm>

#include "base/error.h"

namespace bpm {

// Per medium, per class (BackwardMaps::tree_class): a scene, its spheres' backward photon
// indices, and its largest radius.
struct MediumSpheres::Scenes {
  RTCDevice device = nullptr;
  std::vector<RTCScene> scenes;
  std::vector<std::vector<uint32_t>> ids;
  // Each scene's vertex buffer (centre and radius per sphere, in its primitives' order, alive as
  // long as the scene): the filter reads these rather than the larger backward photon records.
  std::vector<const float*> spheres;
  std::vector<float> max_radius;
  void release() {
    for (RTCScene s : scenes)
      if (s) rtcReleaseScene(s);
    scenes.clear();
  }
  ~Scenes() {
    release();
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

struct QueryContext {
  RTCIntersectContext embree;  // first: Embree hands the filter this pointer
  const std::vector<uint32_t>* ids;
  const float* spheres;  // x, y, z, radius per primitive
  Vec3 o, d;             // the beam
  float t_max;
  std::vector<std::pair<uint32_t, float>>* found;
};

// Every sphere the extended ray meets is a candidate, reported once or twice (its near and far
// hits, one after the other); the beam reaches it when its nearest point to the centre lies on
// the beam and within the radius.
void collect_sphere(const RTCFilterFunctionNArguments* args) {
  auto* q = reinterpret_cast<QueryContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    args->valid[i] = 0;  // go on to the next sphere
    const uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
    const uint32_t g = (*q->ids)[prim];
    if (!q->found->empty() && q->found->back().first == g) continue;
    const float* s = q->spheres + 4 * size_t(prim);
    const Vec3 oc = Vec3(s[0], s[1], s[2]) - q->o;
    const float t = dot(oc, q->d);
    if (!(t >= 0 && t <= q->t_max)) continue;
    if (length_squared(oc - q->d * t) < s[3] * s[3]) q->found->push_back({g, t});
  }
}

}  // namespace

MediumSpheres::MediumSpheres() : scenes_(std::make_unique<Scenes>()) {
  scenes_->device = rtcNewDevice(nullptr);
  if (!scenes_->device) throw Error("cannot start Embree for the spheres in media");
}

MediumSpheres::~MediumSpheres() = default;

void MediumSpheres::build(const BackwardMaps& maps, size_t object_count, size_t media) {
  spheres_ = 0;
  Scenes& s = *scenes_;
  s.release();
  s.scenes.assign(2 * media, nullptr);
  s.ids.resize(2 * media);
  s.spheres.assign(2 * media, nullptr);
  s.max_radius.assign(2 * media, 0);
  for (size_t m = 0; m < media; ++m) {
    const uint32_t begin = maps.object_begin[object_count + m];
    const uint32_t end = maps.object_begin[object_count + m + 1];
    for (int c = 0; c < 2; ++c) {
      const size_t k = 2 * m + size_t(c);
      const uint8_t accepts = c == 0 ? kAcceptsCaustic : kAcceptsIndirect;
      std::vector<uint32_t>& ids = s.ids[k];
      ids.clear();
      for (uint32_t g = begin; g < end; ++g)
        if (maps.photons[g].accepts & accepts) ids.push_back(g);
      if (ids.empty()) continue;
      spheres_ += ids.size();
      RTCGeometry geom = rtcNewGeometry(s.device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                            RTC_FORMAT_FLOAT4, 16, ids.size()));
      for (size_t j = 0; j < ids.size(); ++j) {
        const BackwardPhoton& bp = maps.photons[ids[j]];
        v[4 * j] = bp.p.x;
        v[4 * j + 1] = bp.p.y;
        v[4 * j + 2] = bp.p.z;
        v[4 * j + 3] = bp.radius;
        s.max_radius[k] = std::max(s.max_radius[k], bp.radius);
      }
      s.spheres[k] = v;
      rtcSetGeometryOccludedFilterFunction(geom, collect_sphere);
      rtcCommitGeometry(geom);
      s.scenes[k] = rtcNewScene(s.device);
      rtcSetSceneFlags(s.scenes[k], RTC_SCENE_FLAG_ROBUST);
      rtcAttachGeometry(s.scenes[k], geom);
      rtcReleaseGeometry(geom);
      rtcCommitScene(s.scenes[k]);
    }
  }
}

void MediumSpheres::query(int medium, PhotonClass cls, const Ray& ray, float t_max,
                          std::vector<std::pair<uint32_t, float>>* found) const {
  const size_t k = 2 * size_t(medium) + size_t(BackwardMaps::tree_class(cls));
  if (medium < 0 || k >= scenes_->scenes.size() || !scenes_->scenes[k]) return;
  const size_t first = found->size();
  QueryContext q{{}, &scenes_->ids[k], scenes_->spheres[k], ray.o, ray.d, t_max, found};
  rtcInitIntersectContext(&q.embree);
  // The ray runs a largest radius beyond both ends of the beam, so that it meets the surface of
  // every sphere whose centre's nearest point lies on the beam, even one that holds the whole beam.
  const float pad = scenes_->max_radius[k];
  RTCRay r{};
  r.org_x = ray.o.x - ray.d.x * pad;
  r.org_y = ray.o.y - ray.d.y * pad;
  r.org_z = ray.o.z - ray.d.z * pad;
  r.dir_x = ray.d.x;
  r.dir_y = ray.d.y;
  r.dir_z = ray.d.z;
  r.tnear = 0;
  r.tfar = std::isfinite(t_max) ? t_max + 2 * pad : kInf;
  r.mask = ~0u;
  rtcOccluded1(scenes_->scenes[k], &q.embree, &r);
  std::sort(found->begin() + long(first), found->end());
  found->erase(std::unique(found->begin() + long(first), found->end(),
                           [](const auto& a, const auto& b) { return a.first == b.first; }),
               found->end());
}

}  // namespace bpm
