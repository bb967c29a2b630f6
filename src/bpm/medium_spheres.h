// The backward photons inside scattering media (bpm/eye_pass.h), as spheres at which photon beams
// are gathered: per medium and photon class, an Embree scene of sphere points. A beam (a photon's
// way through a medium to the next surface, photons/light_path.h) reaches a sphere when the point
// of the beam nearest its centre lies within its radius r: the beam's flux there, blurred over the
// disc of radius r across the beam (Jarosz et al. 2011, "beam x point" with a 2D kernel), is the
// light the sphere's point gathers, flux exp(-sigma_t t) p / (pi r^2) per photon emitted. One
// traversal per beam finds every sphere it reaches.
#pragma once
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "base/ray.h"
#include "bpm/backward_maps.h"

namespace bpm {

// What a beam's gathering reads of a backward photon in a medium, in one record: the sphere (the
// first 16 bytes, which Embree reads as the sphere point's centre and radius), and the photon's
// direction, pixel, throughput and depth, and its offset from a surface that cuts its discs.
struct alignas(16) MediumSphere {
  Vec3 p;
  float radius;
  Vec3 wo;
  uint32_t pixel;
  Spectrum tau;
  uint32_t index;  // the backward photon's in the maps
  uint16_t eye_depth;
  bool hero_only;
  Vec3 cut;  // photons/medium_cuts.h (zero: none)
};

class MediumSpheres {
 public:
  MediumSpheres();
  ~MediumSpheres();
  MediumSpheres(const MediumSpheres&) = delete;
  MediumSpheres& operator=(const MediumSpheres&) = delete;

  // The spheres of the backward photons of maps past the first object_count objects (whose lists
  // are the media's, in order), by the classes they accept.
  void build(const BackwardMaps& maps, size_t object_count, size_t media);
  bool empty() const { return spheres_ == 0; }
  size_t size() const { return spheres_; }  // spheres in all the scenes
  // Their records, and Embree's trees over them (an estimate: a node per two spheres).
  size_t bytes() const { return spheres_ * (sizeof(MediumSphere) + 64); }
  // Appends to *found (the sphere, t of the beam's point nearest its centre) for every sphere of
  // `medium` that accepts `cls`, whose eye path has at most max_eye_depth scattering events, and
  // that the beam from ray.o along the unit ray.d over [0, t_max] reaches, in the order of the
  // backward photons' indices.
  void query(int medium, PhotonClass cls, const Ray& ray, float t_max, int max_eye_depth,
             std::vector<std::pair<const MediumSphere*, float>>* found) const;

 private:
  struct Scenes;
  std::unique_ptr<Scenes> scenes_;
  size_t spheres_ = 0;
};

}  // namespace bpm
