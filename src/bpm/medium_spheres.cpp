#include "bpm/medium_spheres.h"

#include <embree3/rtcore.h>

#include <algorithm>

#include "base/error.h"

namespace bpm {

// Per medium, per class (BackwardMaps::tree_class): a scene, its spheres in the order of its
// primitives (and of the backward photons' indices; Embree reads its vertex buffer from them), and
// its largest radius.
struct MediumSpheres::Scenes {
  RTCDevice device = nullptr;
  std::vector<RTCScene> scenes;
  std::vector<std::vector<MediumSphere>> spheres;
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
  const MediumSphere* spheres;
  Vec3 o, d;  // the beam
  float t_max;
  int max_eye_depth;
  std::vector<std::pair<const MediumSphere*, float>>* found;
};

// Every sphere the extended ray meets is a candidate, reported once or twice (its near and far
// hits, one after the other); the beam reaches it when its nearest point to the centre lies on
// the beam and within the radius.
void collect_sphere(const RTCFilterFunctionNArguments* args) {
  auto* q = reinterpret_cast<QueryContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    args->valid[i] = 0;  // go on to the next sphere
    const MediumSphere* s = q->spheres + RTCHitN_primID(args->hit, args->N, i);
    if (!q->found->empty() && q->found->back().first == s) continue;
    if (s->eye_depth > q->max_eye_depth) continue;
    const Vec3 oc = s->p - q->o;
    const float t = dot(oc, q->d);
    if (!(t >= 0 && t <= q->t_max)) continue;
    if (length_squared(oc - q->d * t) < s->radius * s->radius) q->found->push_back({s, t});
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
  s.spheres.resize(2 * media);
  s.max_radius.assign(2 * media, 0);
  for (size_t m = 0; m < media; ++m) {
    const uint32_t begin = maps.object_begin[object_count + m];
    const uint32_t end = maps.object_begin[object_count + m + 1];
    for (int c = 0; c < 2; ++c) {
      const size_t k = 2 * m + size_t(c);
      const uint8_t accepts = c == 0 ? kAcceptsCaustic : kAcceptsIndirect;
      std::vector<MediumSphere>& spheres = s.spheres[k];
      spheres.clear();
      for (uint32_t g = begin; g < end; ++g) {
        const BackwardPhoton& bp = maps.photons[g];
        if (!(bp.accepts & accepts)) continue;
        spheres.push_back(
            {bp.p, bp.radius, bp.wo, bp.pixel, bp.tau, g, bp.eye_depth, bool(bp.hero_only), bp.ng});
        s.max_radius[k] = std::max(s.max_radius[k], bp.radius);
      }
      if (spheres.empty()) continue;
      spheres_ += spheres.size();
      RTCGeometry geom = rtcNewGeometry(s.device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
      rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, spheres.data(),
                                 0, sizeof(MediumSphere), spheres.size());
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
                          int max_eye_depth,
                          std::vector<std::pair<const MediumSphere*, float>>* found) const {
  const size_t k = 2 * size_t(medium) + size_t(BackwardMaps::tree_class(cls));
  if (medium < 0 || k >= scenes_->scenes.size() || !scenes_->scenes[k]) return;
  const size_t first = found->size();
  QueryContext q{{}, scenes_->spheres[k].data(), ray.o, ray.d, t_max, max_eye_depth, found};
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
