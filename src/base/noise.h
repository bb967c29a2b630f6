// Ken Perlin's gradient noise ("Improving Noise", 2002), as pbrt-v4 evaluates it, so that a scene's
// procedural media (the "cloud" medium, scene/flatten_media.cpp) have pbrt-v4's density: his
// permutation of 0..255 picks one of twelve edge gradients at each lattice point, and the
// gradients' ramps are blended with the weight 6t^5 - 15t^4 + 10t^3 along each axis. Values lie
// in about [-1, 1], zero at every lattice point; the pattern repeats every 256 units.
#pragma once
#include "base/vec.h"

namespace bpm {

float perlin_noise(Vec3 p);

// pbrt-v4's derivative of the noise: forward differences over 0.01 along each axis.
Vec3 perlin_noise_slope(Vec3 p);

}  // namespace bpm
