#include "base/noise.h"

#include <cmath>
#include <cstdint>

namespace bpm {
namespace {

// Perlin's permutation of 0..255 (his reference implementation's), read modulo 256.
constexpr uint8_t kPermutation[256] = {
    151, 160, 137, 91,  90,  15,  131, 13,  201, 95,  96,  53,  194, 233, 7,   225, 140, 36,  103,
    30,  69,  142, 8,   99,  37,  240, 21,  10,  23,  190, 6,   148, 247, 120, 234, 75,  0,   26,
    197, 62,  94,  252, 219, 203, 117, 35,  11,  32,  57,  177, 33,  88,  237, 149, 56,  87,  174,
    20,  125, 136, 171, 168, 68,  175, 74,  165, 71,  134, 139, 48,  27,  166, 77,  146, 158, 231,
    83,  111, 229, 122, 60,  211, 133, 230, 220, 105, 92,  41,  55,  46,  245, 40,  244, 102, 143,
    54,  65,  25,  63,  161, 1,   216, 80,  73,  209, 76,  132, 187, 208, 89,  18,  169, 200, 196,
    135, 130, 116, 188, 159, 86,  164, 100, 109, 198, 173, 186, 3,   64,  52,  217, 226, 250, 124,
    123, 5,   202, 38,  147, 118, 126, 255, 82,  85,  212, 207, 206, 59,  227, 47,  16,  58,  17,
    182, 189, 28,  42,  223, 183, 170, 213, 119, 248, 152, 2,   44,  154, 163, 70,  221, 153, 101,
    155, 167, 43,  172, 9,   129, 22,  39,  253, 19,  98,  108, 110, 79,  113, 224, 232, 178, 185,
    112, 104, 218, 246, 97,  228, 251, 34,  242, 193, 238, 210, 144, 12,  191, 179, 162, 241, 81,
    51,  145, 235, 249, 14,  239, 107, 49,  192, 214, 31,  181, 199, 106, 157, 184, 84,  204, 176,
    115, 121, 50,  45,  127, 4,   150, 254, 138, 236, 205, 93,  222, 114, 67,  29,  24,  72,  243,
    141, 128, 195, 78,  66,  215, 61,  156, 180};

int permute(int i) { return kPermutation[i & 255]; }

// The ramp of lattice point (x, y, z)'s gradient at offset (dx, dy, dz) from it: one of the
// twelve directions to the cube's edge midpoints (four of them twice), by a hash of the point.
float ramp(int x, int y, int z, float dx, float dy, float dz) {
  const int h = permute(permute(permute(x) + y) + z) & 15;
  const float a = h < 8 || h == 12 || h == 13 ? dx : dy;
  const float b = h < 4 || h == 12 || h == 13 ? dy : dz;
  return ((h & 1) ? -a : a) + ((h & 2) ? -b : b);
}

float fade(float t) { return t * t * t * (t * (t * 6 - 15) + 10); }
float mix(float t, float a, float b) { return a + t * (b - a); }

}  // namespace

float perlin_noise(Vec3 p) {
  // Far from the origin the lattice is found modulo 2^30, which keeps the cell within int range.
  float c[3] = {std::fmod(p.x, float(1 << 30)), std::fmod(p.y, float(1 << 30)),
                std::fmod(p.z, float(1 << 30))};
  int cell[3];
  float d[3];
  for (int a = 0; a < 3; ++a) {
    const float f = std::floor(c[a]);
    cell[a] = int(f) & 255;
    d[a] = c[a] - f;
  }
  const auto [x, y, z] = cell;
  const auto [dx, dy, dz] = d;
  const float wx = fade(dx), wy = fade(dy), wz = fade(dz);
  const float near_z =
      mix(wy, mix(wx, ramp(x, y, z, dx, dy, dz), ramp(x + 1, y, z, dx - 1, dy, dz)),
          mix(wx, ramp(x, y + 1, z, dx, dy - 1, dz), ramp(x + 1, y + 1, z, dx - 1, dy - 1, dz)));
  const float far_z =
      mix(wy, mix(wx, ramp(x, y, z + 1, dx, dy, dz - 1), ramp(x + 1, y, z + 1, dx - 1, dy, dz - 1)),
          mix(wx, ramp(x, y + 1, z + 1, dx, dy - 1, dz - 1),
              ramp(x + 1, y + 1, z + 1, dx - 1, dy - 1, dz - 1)));
  return mix(wz, near_z, far_z);
}

Vec3 perlin_noise_slope(Vec3 p) {
  constexpr float h = 0.01f;
  const float n = perlin_noise(p);
  return Vec3(perlin_noise(p + Vec3(h, 0, 0)) - n, perlin_noise(p + Vec3(0, h, 0)) - n,
              perlin_noise(p + Vec3(0, 0, h)) - n) /
         h;
}

}  // namespace bpm
