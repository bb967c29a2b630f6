// A ray and what it hits: the types every layer from the camera up exchanges.
#pragma once
#include "base/vec.h"

namespace bpm {

struct Ray {
  Vec3 o, d;
  float t_max = kInf;
};

// A ray from the camera and the factor it carries into the radiance it brings back: 1 but for
// the realistic camera, whose lens weighs its rays (camera/lens_system.h); 0: no light comes
// along this ray. A camera inside a medium starts its rays in it.
struct CameraRay {
  Ray ray;
  float weight = 1;
  int medium = -1;  // the scene medium the ray starts in (-1: none)
};

// The closest hit of a ray: the scene object (Embree geometry id), its primitive, the barycentric
// coordinates on it and the distance along the ray in units of |d|.
struct Hit {
  int object = -1;
  int primitive = -1;
  Vec2 barycentric;
  float t = 0;
};

}  // namespace bpm
