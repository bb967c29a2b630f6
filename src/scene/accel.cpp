// Embree 3 acceleration structure: one geometry per object (triangle meshes natively, spheres,
// disks and cylinders as user geometry with analytic intersection); the geometries of the objects
// that emit are also attached, under the same ids, to a scene of their own (may_reach_emitter).
#include <cmath>
#include <limits>

#include "base/error.h"
#include "scene/render_scene.h"

namespace bpm {

namespace {

void embree_error(void*, RTCError code, const char* str) {
  // Embree reports misuse and allocation failures here; neither is recoverable mid-render.
  std::fprintf(stderr, "Embree error %d: %s\n", int(code), str ? str : "");
}

// What the callbacks of one geometry need. textures is the Accel's own copy (the RenderScene,
// and so its members, may move after the build; its vectors' elements do not).
struct UserShape {
  const Shape* shape;
  const Object* object;
  const TextureSet* textures;
};

bool alpha_rejects(const UserShape* us, int prim, Vec2 bary, Vec3 o, Vec3 d, float t) {
  if (!us->object->has_alpha()) return false;
  SurfacePoint sp = surface_point(*us->shape, prim, bary, o + d * t, d);
  return alpha_passes(*us->textures, us->object->alpha, sp, o, d);
}

// Intersection and occlusion filter of alpha-masked triangle meshes: drops the hits the surface's
// alpha lets through, so that Embree goes on to the next one.
void alpha_filter(const RTCFilterFunctionNArguments* args) {
  const auto* us = static_cast<const UserShape*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    Vec3 o(RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i),
           RTCRayN_org_z(args->ray, args->N, i));
    Vec3 d(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
           RTCRayN_dir_z(args->ray, args->N, i));
    float t = RTCRayN_tfar(args->ray, args->N, i);
    Vec2 bary(RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i));
    if (alpha_rejects(us, int(RTCHitN_primID(args->hit, args->N, i)), bary, o, d, t))
      args->valid[i] = 0;
  }
}

void user_bounds(const RTCBoundsFunctionArguments* args) {
  const auto* us = static_cast<const UserShape*>(args->geometryUserPtr);
  Bounds3 b = world_bounds(*us->shape, 0);
  args->bounds_o->lower_x = b.lo.x;
  args->bounds_o->lower_y = b.lo.y;
  args->bounds_o->lower_z = b.lo.z;
  args->bounds_o->upper_x = b.hi.x;
  args->bounds_o->upper_y = b.hi.y;
  args->bounds_o->upper_z = b.hi.z;
}

double user_hit(const UserShape* us, RTCRayN* ray, unsigned N, unsigned i) {
  Vec3 o(RTCRayN_org_x(ray, N, i), RTCRayN_org_y(ray, N, i), RTCRayN_org_z(ray, N, i));
  Vec3 d(RTCRayN_dir_x(ray, N, i), RTCRayN_dir_y(ray, N, i), RTCRayN_dir_z(ray, N, i));
  double t0 = RTCRayN_tnear(ray, N, i), t1 = RTCRayN_tfar(ray, N, i);
  // Analytic shapes meet a ray at most twice: the hits alpha lets through are skipped here.
  for (int k = 0; k < 4; ++k) {
    double t = intersect_analytic(*us->shape, o, d, t0, t1);
    if (t <= 0 || !alpha_rejects(us, 0, {}, o, d, float(t))) return t;
    t0 = t;
  }
  return -1;
}

void user_intersect(const RTCIntersectFunctionNArguments* args) {
  const auto* us = static_cast<const UserShape*>(args->geometryUserPtr);
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    double t = user_hit(us, ray, args->N, i);
    if (t <= 0) continue;
    RTCRayN_tfar(ray, args->N, i) = float(t);
    RTCHitN_Ng_x(hit, args->N, i) = 0;
    RTCHitN_Ng_y(hit, args->N, i) = 0;
    RTCHitN_Ng_z(hit, args->N, i) = 1;
    RTCHitN_u(hit, args->N, i) = 0;
    RTCHitN_v(hit, args->N, i) = 0;
    RTCHitN_primID(hit, args->N, i) = args->primID;
    RTCHitN_geomID(hit, args->N, i) = args->geomID;
    RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
  }
}

void user_occluded(const RTCOccludedFunctionNArguments* args) {
  const auto* us = static_cast<const UserShape*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    if (user_hit(us, args->ray, args->N, i) > 0)
      RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity();
  }
}

}  // namespace

class Accel {
 public:
  Accel(const std::vector<Object>& objects, const TextureSet& textures) : textures_(textures) {
    device_ = rtcNewDevice(nullptr);
    if (!device_)
      throw Error("cannot create the Embree device (error " +
                  std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(device_, embree_error, nullptr);
    scene_ = rtcNewScene(device_);
    rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
    emitters_ = rtcNewScene(device_);
    rtcSetSceneFlags(emitters_, RTC_SCENE_FLAG_ROBUST);
    user_shapes_.reserve(objects.size());
    for (size_t id = 0; id < objects.size(); ++id) {
      const Object& obj = objects[id];
      RTCGeometry g;
      if (auto* m = std::get_if<TriangleMesh>(&obj.shape)) {
        g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                   m->positions.data(), 0, sizeof(Vec3), m->positions.size());
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m->indices.data(),
                                   0, 3 * sizeof(uint32_t), m->indices.size() / 3);
        triangles_ += m->indices.size() / 3;
        if (obj.has_alpha()) {
          user_shapes_.push_back(UserShape{&obj.shape, &obj, &textures_});
          rtcSetGeometryUserData(g, &user_shapes_.back());
          rtcSetGeometryIntersectFilterFunction(g, alpha_filter);
          rtcSetGeometryOccludedFilterFunction(g, alpha_filter);
        }
      } else if (auto* c = std::get_if<Curves>(&obj.shape)) {
        g = curve_geometry(*c);
        if (obj.has_alpha()) {
          user_shapes_.push_back(UserShape{&obj.shape, &obj, &textures_});
          rtcSetGeometryUserData(g, &user_shapes_.back());
          rtcSetGeometryIntersectFilterFunction(g, alpha_filter);
          rtcSetGeometryOccludedFilterFunction(g, alpha_filter);
        }
      } else {
        g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
        user_shapes_.push_back(UserShape{&obj.shape, &obj, &textures_});
        rtcSetGeometryUserPrimitiveCount(g, 1);
        rtcSetGeometryUserData(g, &user_shapes_.back());
        rtcSetGeometryBoundsFunction(g, user_bounds, nullptr);
        rtcSetGeometryIntersectFunction(g, user_intersect);
        rtcSetGeometryOccludedFunction(g, user_occluded);
      }
      rtcCommitGeometry(g);
      unsigned gid = rtcAttachGeometry(scene_, g);
      BPM_CHECK(gid == id);
      if (obj.first_light >= 0) rtcAttachGeometryByID(emitters_, g, unsigned(id));
      rtcReleaseGeometry(g);
    }
    rtcCommitScene(scene_);
    rtcCommitScene(emitters_);
    RTCError err = rtcGetDeviceError(device_);
    if (err != RTC_ERROR_NONE)
      throw Error("Embree failed to build the scene (error " + std::to_string(int(err)) + ")");
  }
  ~Accel() {
    rtcReleaseScene(emitters_);
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
  }

  bool intersect(const Ray& ray, Hit* hit) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    rh.ray.org_x = ray.o.x;
    rh.ray.org_y = ray.o.y;
    rh.ray.org_z = ray.o.z;
    rh.ray.dir_x = ray.d.x;
    rh.ray.dir_y = ray.d.y;
    rh.ray.dir_z = ray.d.z;
    rh.ray.tnear = 0;
    rh.ray.tfar = ray.t_max;
    rh.ray.time = 0;
    rh.ray.mask = ~0u;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit->object = int(rh.hit.geomID);
    hit->primitive = int(rh.hit.primID);
    hit->barycentric = {rh.hit.u, rh.hit.v};
    hit->t = rh.ray.tfar;
    return true;
  }

  void intersect_coherent(const Ray* rays, int n, Hit* hits, bool* found) const {
    static_assert(RenderScene::kBundle == 8, "an RTCRayHit8 packet");
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    alignas(32) RTCRayHit8 rh;
    alignas(32) int valid[8];
    for (int i = 0; i < 8; ++i) {
      const bool on = i < n;
      valid[i] = on ? -1 : 0;
      const Ray& ray = rays[on ? i : 0];
      rh.ray.org_x[i] = ray.o.x;
      rh.ray.org_y[i] = ray.o.y;
      rh.ray.org_z[i] = ray.o.z;
      rh.ray.dir_x[i] = ray.d.x;
      rh.ray.dir_y[i] = ray.d.y;
      rh.ray.dir_z[i] = ray.d.z;
      rh.ray.tnear[i] = 0;
      rh.ray.tfar[i] = ray.t_max;
      rh.ray.time[i] = 0;
      rh.ray.mask[i] = ~0u;
      rh.ray.id[i] = unsigned(i);
      rh.ray.flags[i] = 0;
      rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.primID[i] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, scene_, &ctx, &rh);
    for (int i = 0; i < n; ++i) {
      found[i] = rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
      if (!found[i]) continue;
      hits[i].object = int(rh.hit.geomID[i]);
      hits[i].primitive = int(rh.hit.primID[i]);
      hits[i].barycentric = {rh.hit.u[i], rh.hit.v[i]};
      hits[i].t = rh.ray.tfar[i];
    }
  }

  // Flat (ray-facing) or normal-oriented cubic Bezier curves, from the shape's own buffers.
  RTCGeometry curve_geometry(const Curves& c) {
    const bool ribbon = c.type == Curves::Type::kRibbon;
    RTCGeometry g = rtcNewGeometry(device_, ribbon ? RTC_GEOMETRY_TYPE_NORMAL_ORIENTED_BEZIER_CURVE
                                                   : RTC_GEOMETRY_TYPE_FLAT_BEZIER_CURVE);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, c.control.data(), 0,
                               4 * sizeof(float), c.control.size() / 4);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, c.first.data(), 0,
                               sizeof(uint32_t), c.first.size());
    // Embree cuts flat curves into this many straight pieces per segment (4 by default, which
    // shows as kinks where pbrt-v4's curves bend smoothly).
    rtcSetGeometryTessellationRate(g, 32);
    if (ribbon)
      rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3,
                                 c.control_normals.data(), 0, sizeof(Vec3),
                                 c.control_normals.size());
    return g;
  }

  // Embree's point query: visit for each primitive whose bounds come within `radius` of p.
  void visit_near(Vec3 p, float radius, RenderScene::NearVisit visit, void* ctx) const {
    struct Query {
      RenderScene::NearVisit visit;
      void* ctx;
      bool stopped;
    } q{visit, ctx, false};
    RTCPointQuery pq;
    pq.x = p.x;
    pq.y = p.y;
    pq.z = p.z;
    pq.time = 0;
    pq.radius = radius;
    RTCPointQueryContext pctx;
    rtcInitPointQueryContext(&pctx);
    rtcPointQuery(
        scene_, &pq, &pctx,
        [](RTCPointQueryFunctionArguments* args) {
          auto* q = static_cast<Query*>(args->userPtr);
          if (q->stopped || q->visit(q->ctx, int(args->geomID), int(args->primID))) return false;
          q->stopped = true;  // a radius of zero ends the traversal
          args->query->radius = 0;
          return true;
        },
        &q);
  }

  // Whether anything lies along the ray (occluded), or any emitting surface (meets_emitter).
  bool occluded(const Ray& ray) const { return any_hit(scene_, ray); }
  bool meets_emitter(const Ray& ray) const { return any_hit(emitters_, ray); }

  size_t triangles() const { return triangles_; }

 private:
  static bool any_hit(RTCScene scene, const Ray& ray) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r;
    r.org_x = ray.o.x;
    r.org_y = ray.o.y;
    r.org_z = ray.o.z;
    r.dir_x = ray.d.x;
    r.dir_y = ray.d.y;
    r.dir_z = ray.d.z;
    r.tnear = 0;
    r.tfar = ray.t_max;
    r.time = 0;
    r.mask = ~0u;
    r.id = 0;
    r.flags = 0;
    rtcOccluded1(scene, &ctx, &r);
    return r.tfar < 0;
  }

  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  RTCScene emitters_ = nullptr;  // the geometries of the objects that emit, under their own IDs
  TextureSet textures_;
  std::vector<UserShape> user_shapes_;
  size_t triangles_ = 0;
};

RenderScene::RenderScene() = default;
RenderScene::~RenderScene() = default;
RenderScene::RenderScene(RenderScene&&) noexcept = default;
RenderScene& RenderScene::operator=(RenderScene&&) noexcept = default;

void RenderScene::commit() {
  has_interfaces = false;
  for (const Object& o : objects)
    if (size_t(o.material) < materials.size() &&
        std::holds_alternative<InterfaceMaterial>(materials[size_t(o.material)]))
      has_interfaces = true;
  for (Object& o : objects)
    if (auto* m = std::get_if<TriangleMesh>(&o.shape)) {
      m->compute_face_normals();
      m->compute_open_edges();
    }
  bounds = Bounds3();
  for (const Object& o : objects)
    for (int p = 0; p < primitive_count(o.shape); ++p) bounds.expand(world_bounds(o.shape, p));
  if (bounds.empty()) bounds.expand(Vec3(0, 0, 0));
  bounds_info.center = bounds.center();
  bounds_info.radius = std::fmax(1e-3f, 0.5f * length(bounds.diagonal()));
  std::vector<float> weights;
  infinite_lights.clear();
  bsdf_finds_lights = false;
  for (size_t i = 0; i < lights.size(); ++i) {
    weights.push_back(std::fmax(0.0f, light_power(lights[i], bounds_info).average()));
    if (light_is_environment(lights[i])) infinite_lights.push_back(int(i));
    bsdf_finds_lights |= !light_is_delta(lights[i]);
  }
  light_distribution = Distribution1D(weights);
  accel_ = std::make_unique<Accel>(objects, textures);
}

bool RenderScene::intersect(const Ray& ray, Hit* hit) const { return accel_->intersect(ray, hit); }
void RenderScene::intersect_bundle(const Ray* rays, int n, Hit* hits, bool* found) const {
  BPM_CHECK(n >= 0 && n <= kBundle);
  accel_->intersect_coherent(rays, n, hits, found);
}
bool RenderScene::occluded_ray(const Ray& ray) const { return accel_->occluded(ray); }
void RenderScene::visit_near(Vec3 p, float radius, NearVisit visit, void* ctx) const {
  accel_->visit_near(p, radius, visit, ctx);
}
bool RenderScene::may_reach_emitter(const Ray& ray) const {
  return !infinite_lights.empty() || accel_->meets_emitter(ray);
}
bool RenderScene::occluded(Vec3 a, Vec3 b) const {
  Vec3 d = b - a;
  float len = length(d);
  if (len == 0) return false;
  return accel_->occluded(Ray{a, d / len, len * (1 - 1e-4f)});
}
size_t RenderScene::triangle_count() const { return accel_ ? accel_->triangles() : 0; }

}  // namespace bpm
