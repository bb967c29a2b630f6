// Random numbers. Every stream is keyed by what it samples (seed, pass, pixel or photon index),
// never by the thread that happens to run it, so images do not depend on the thread count.
#pragma once
#include <cstdint>

namespace bpm {

// SplitMix64 finaliser: a good 64-bit mixing function for deriving stream keys.
inline uint64_t mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

inline uint64_t stream_key(uint64_t seed, uint64_t a, uint64_t b = 0, uint64_t c = 0) {
  return mix64(mix64(mix64(seed ^ 0x5851f42d4c957f2dull) ^ a) ^ mix64(b + 0x632be59bd9b4e019ull) ^
               (c * 0x9e3779b97f4a7c15ull));
}

// PCG32 (O'Neill 2014): XSH RR output over a 64-bit LCG.
class Rng {
 public:
  explicit Rng(uint64_t key) {
    inc_ = (mix64(key ^ 0xda3e39cb94b95bdbull) << 1u) | 1u;
    state_ = 0;
    next_u32();
    state_ += mix64(key);
    next_u32();
  }
  uint32_t next_u32() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31));
  }
  // Uniform in [0, 1).
  float uniform() { return static_cast<float>(next_u32() >> 8) * 0x1p-24f; }

 private:
  uint64_t state_ = 0, inc_ = 1;
};

}  // namespace bpm
