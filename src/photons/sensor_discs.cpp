#include "photons/sensor_discs.h"

#include <embree3/rtcore.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "base/error.h"
#include "base/sampling.h"
#include "photons/density.h"

namespace bpm {

// The mid-air sensors as Embree's oriented discs, one geometry of them all (a query collects every
// disc along a segment through an occlusion filter that records each and lets the ray go on), and
// the sensors on surfaces as spheres of their radii.
struct SensorDiscs::Tree {
  RTCDevice device = nullptr;
  RTCScene discs = nullptr;
  SphereKdTree spheres;
  ~Tree() {
    if (discs) rtcReleaseScene(discs);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

struct QueryContext {
  RTCIntersectContext embree;  // first: Embree hands the filter this pointer
  const std::vector<Sensor>* sensors;
  const std::vector<uint32_t>* in_air;
  Vec3 d;
  std::vector<std::pair<uint32_t, float>>* found;  // (sensor, t)
};

void collect_crossing(const RTCFilterFunctionNArguments* args) {
  auto* q = reinterpret_cast<QueryContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const uint32_t s = (*q->in_air)[RTCHitN_primID(args->hit, args->N, i)];
    // Only photons arriving from the front of the sensor count.
    if (dot(q->d, (*q->sensors)[s].n) < 0)
      q->found->push_back({s, RTCRayN_tfar(args->ray, args->N, i)});
    args->valid[i] = 0;  // go on to the next disc
  }
}

// Whether the sensor lies on a surface: one within its lift on either side of its point.
bool lies_on_surface(const RenderScene& scene, const Sensor& s) {
  const float lift = sensor_lift(scene);
  Hit hit;
  return scene.intersect(Ray{s.p + s.n * lift, -s.n, 2 * lift}, &hit);
}

}  // namespace

SensorDiscs::SensorDiscs(const RenderScene& scene, const std::vector<Sensor>& sensors,
                         std::vector<float> base_radius, float normal_cos)
    : sensors_(sensors),
      base_radius_(std::move(base_radius)),
      on_surface_(sensors.size()),
      normal_cos_(normal_cos),
      tree_(std::make_unique<Tree>()) {
  BPM_CHECK(base_radius_.size() == sensors_.size());
  tbb::parallel_for(size_t(0), sensors_.size(),
                    [&](size_t i) { on_surface_[i] = lies_on_surface(scene, sensors_[i]); });
  for (size_t i = 0; i < sensors_.size(); ++i)
    if (!on_surface_[i]) in_air_.push_back(uint32_t(i));
  tree_->device = rtcNewDevice(nullptr);
  if (!tree_->device) throw Error("cannot start Embree for the sensors");
  set_scale(1);
}

SensorDiscs::~SensorDiscs() = default;

void SensorDiscs::set_scale(float scale) {
  scale_ = scale;
  std::vector<SphereRef> spheres;
  std::vector<uint32_t> ids;
  for (size_t i = 0; i < sensors_.size(); ++i)
    if (on_surface_[i]) {
      spheres.push_back({sensors_[i].p, radius(i)});
      ids.push_back(uint32_t(i));
    }
  tree_->spheres.build(spheres, &ids);
  if (tree_->discs) rtcReleaseScene(tree_->discs);
  tree_->discs = rtcNewScene(tree_->device);
  rtcSetSceneFlags(tree_->discs, RTC_SCENE_FLAG_ROBUST);
  if (!in_air_.empty()) {
    RTCGeometry g = rtcNewGeometry(tree_->device, RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT);
    const size_t n = in_air_.size();
    auto* centre = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 16, n));
    auto* normal = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3, 12, n));
    for (size_t k = 0; k < n; ++k) {
      const Sensor& s = sensors_[in_air_[k]];
      for (int c = 0; c < 3; ++c) {
        centre[4 * k + size_t(c)] = s.p[c];
        normal[3 * k + size_t(c)] = s.n[c];
      }
      centre[4 * k + 3] = radius(in_air_[k]);
    }
    rtcSetGeometryOccludedFilterFunction(g, collect_crossing);
    rtcCommitGeometry(g);
    rtcAttachGeometry(tree_->discs, g);
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(tree_->discs);
}

void SensorDiscs::reach(const RenderScene& scene, const Wavelengths& wl, const PhotonSegment& seg,
                        uint32_t i, float t, std::vector<SensorCrossing>* out) const {
  const Sensor& s = sensors_[i];
  const Vec3 x = seg.ray.o + seg.ray.d * t;
  const float lift = sensor_lift(scene);
  if (scene.occluded(s.p + s.n * lift, x + s.n * lift)) return;
  Spectrum flux = seg.flux;
  if (seg.medium >= 0) {
    const float len = length(seg.ray.d);
    flux *=
        medium_transmittance(scene, seg.medium, Ray{seg.ray.o, seg.ray.d / len, kInf}, t * len, wl);
  }
  const float value = spectrum_to_luminance(flux, wl);
  if (!(value > 0) || !std::isfinite(value)) return;
  const float d2 = length_squared(x - s.p), r2 = radius(i) * radius(i);
  out->push_back({i, 2 * d2 < r2, 4 * d2 < r2, value});
}

void SensorDiscs::cross(const RenderScene& scene, const Wavelengths& wl, const PhotonSegment& seg,
                        std::vector<SensorCrossing>* out) const {
  if (seg.cls != PhotonClass::kCaustic) return;
  // Sensors on the surface the segment ends at: those within their radius of the end.
  if (std::isfinite(seg.t_max) && tree_->spheres.node_count() > 0) {
    const Vec3 end = seg.ray.o + seg.ray.d * seg.t_max;
    tree_->spheres.query(end, [&](uint32_t i) {
      const Vec3 n = sensors_[i].n;
      if (dot(seg.ray.d, n) < 0 && std::fabs(dot(seg.end_ng, n)) >= normal_cos_)
        reach(scene, wl, seg, i, seg.t_max, out);
    });
  }
  if (in_air_.empty()) return;
  // Sensors in mid-air whose discs the segment crosses.
  // The discs found, in a list of the thread's own kept from call to call (one call a segment).
  thread_local std::vector<std::pair<uint32_t, float>> found;
  found.clear();
  QueryContext q{{}, &sensors_, &in_air_, seg.ray.d, &found};
  rtcInitIntersectContext(&q.embree);
  RTCRay r{};
  r.org_x = seg.ray.o.x;
  r.org_y = seg.ray.o.y;
  r.org_z = seg.ray.o.z;
  r.dir_x = seg.ray.d.x;
  r.dir_y = seg.ray.d.y;
  r.dir_z = seg.ray.d.z;
  r.tnear = 0;
  // A little past the surface the segment ends at: a sensor just above it may lie beyond the
  // rounded end.
  r.tfar = std::isfinite(seg.t_max) ? seg.t_max * (1 + 1e-4f) : kInf;
  r.mask = ~0u;
  rtcOccluded1(tree_->discs, &q.embree, &r);
  for (const auto& [i, t] : found) reach(scene, wl, seg, i, t, out);
}

std::unique_ptr<SensorDiscs> make_sensor_discs(const RenderScene& scene,
                                               const std::vector<Sensor>& sensors,
                                               const Camera& camera,
                                               const PhotonSettings& settings) {
  if (sensors.empty()) return nullptr;
  std::vector<float> r(sensors.size());
  for (size_t i = 0; i < sensors.size(); ++i) {
    float footprint = settings.k1 * camera.footprint_at(sensors[i].p);
    if (sensors[i].cell > 0) footprint = std::min(footprint, 0.5f * sensors[i].cell);
    r[i] = std::max(footprint, 1e-6f * scene.bounds_info.radius);
  }
  return std::make_unique<SensorDiscs>(scene, sensors, std::move(r), settings.normal_cos);
}

void SensorIteration::clear() {
  std::fill(all_.begin(), all_.end(), 0.0);
  std::fill(half_.begin(), half_.end(), 0.0);
  std::fill(quarter_.begin(), quarter_.end(), 0.0);
}

void SensorIteration::add(const std::vector<SensorCrossing>& crossings) {
  for (const SensorCrossing& c : crossings) {
    all_[c.sensor] += c.value;
    if (c.inner) half_[c.sensor] += c.value;
    if (c.quarter) quarter_[c.sensor] += c.value;
  }
}

void SensorIteration::finish(const RenderScene& scene, const SensorDiscs& discs, int max_depth,
                             BiasModel model, uint64_t seed, int it, uint64_t emitted) {
  estimate_.assign(discs.size(), 0.0);
  bias_.assign(discs.size(), 0.0);
  tbb::parallel_for(size_t(0), discs.size(), [&](size_t i) {
    double traced = 0;  // what the paths from the sensor find: all but the caustics
    PathCounters counters;
    for (int k = 0; k < kSensorSamplesPerPass; ++k) {
      Rng rng(stream_key(seed ^ kSensorStreams, uint64_t(it), i, uint64_t(k)));
      const Wavelengths wl = sample_wavelengths(rng.uniform());
      const Spectrum E = sensor_irradiance(scene, discs.sensor(i), max_depth, wl, rng, counters,
                                           /*caustics_elsewhere=*/true);
      if (E.is_finite() && !E.has_negative()) traced += spectrum_to_luminance(E, wl);
    }
    const float r = discs.radius(i);
    const float norm = float(1 / (kPi * double(r) * r * double(std::max<uint64_t>(emitted, 1))));
    NestedSums sums;
    sums.all = Spectrum(float(all_[i]));
    sums.half = Spectrum(float(half_[i]));
    sums.quarter = Spectrum(float(quarter_[i]));
    estimate_[i] = traced / kSensorSamplesPerPass + all_[i] * norm;
    bias_[i] = radius_bias(sums, norm, model)[0];
  });
}

void SensorIteration::record(Film* film) const {
  for (size_t i = 0; i < estimate_.size(); ++i) film->add_sensor_pass(i, estimate_[i], bias_[i]);
}

}  // namespace bpm
