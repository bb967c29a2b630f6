// A ray and what it hits: the types every layer from the camera up exchanges.
#pragma once
#include "base/vec.h"

namespace bpm {

struct Ray {
  Vec3 o, d;
  float t_max = kInf;
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
