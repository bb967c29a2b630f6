// The records the two passes exchange. A backward photon is a diffuse vertex of an eye path
// (DESIGN.md, vocabulary) with the sphere over which it gathers; a photon's class says how the
// light reached the surface it hit, and each backward photon accepts some classes only.
#pragma once
#include <algorithm>
#include <cstdint>
#include <cstring>

#include "base/spectrum.h"
#include "base/vec.h"
#include "photons/light_path.h"

namespace bpm {

enum AcceptMask : uint8_t { kAcceptsCaustic = 1, kAcceptsIndirect = 2 };

// An eye path stores one backward photon at each of its diffuse vertices (D + 1 of them, D <= 3)
// and a second at the last, two more (as at a last vertex) where it takes both parts of a coat
// (EyePassParams::split_coats), and two at each of at most kMaxMediumSplits pieces of its rays
// through media where it splits (bpm/eye_pass.cpp).
constexpr int kMaxMediumSplits = 4;
constexpr int backward_photons_per_path(int diffuse_depth, bool splits) {
  return diffuse_depth + 4 + (splits ? 2 * kMaxMediumSplits : 0);
}
constexpr int kMaxBackwardPhotonsPerPath = backward_photons_per_path(3, true);

struct BackwardPhoton {
  Vec3 p;
  float radius;  // world units
  Vec3 ng, ns;   // geometric and shading normals
  Vec3 wo;       // toward the previous eye vertex
  Vec2 uv;       // surface coordinates, for textured materials
  Spectrum tau;  // throughput from the camera (the paper's transmittance)
  uint32_t pixel;
  uint32_t material;
  uint16_t eye_depth;         // scattering events on the eye path, this vertex included
  uint8_t accepts;            // AcceptMask bits
  uint8_t diffuse_index : 2;  // j - 1 for the j-th diffuse vertex (0..3)
  // With `combined`: the eye path went on from here with the probability 2^-continue_level
  // (EyePixels::continue_level), and the merge's weight counts the continuation's density so.
  uint8_t continue_level : 3 = 0;
  // The eye path went on from here (combined estimators, photons/merge_weights.h): the photons
  // it gathers are weighed against that.
  uint8_t combined : 1 = 0;
  // The disc's probes looked (DiscProbes::looked: other geometry is near): each photon is
  // gathered only where nothing stands between it and the point (photon_cut_off).
  uint8_t cut_off_tested : 1 = 0;
  // Its disc may be cut, and is probed after the light pass if it gathers light
  // (bpm/disc_shares.h); until then disc_found and disc_cut are 0, a share of 1.
  uint8_t probes_pending : 1 = 0;
  uint8_t hero_only : 1;  // the eye path keeps its hero wavelength alone (PathState)
  // The one backward photon of its eye path that photons' vertices are joined to (vertex
  // connections, bpm/vertex_connections.h): the first that accepts indirect light on a surface
  // where paths are combined.
  uint8_t vertex_target : 1 = 0;
  uint8_t disc_cut = 0;    // the disc probes that found no surface (photons/disc_probes.h)
  uint8_t disc_found = 0;  // and those that found some
  uint8_t place = 0;       // its rank among its eye path's backward photons, in storing order
  // A point inside a scattering medium, this one (-1: a surface point): a sphere that gathers
  // photon beams, with no surface coordinates or material, and no normals: ng holds instead its
  // offset from the plane of a surface that cuts its discs (photons/medium_cuts.h; zero: none).
  int16_t medium = -1;
  // The point's floating-point error bound (SurfacePoint::error), for the pending probes: the upper
  // half of its float, rounded up.
  uint16_t error_high = 0;
  void set_error(float e) {
    uint32_t bits;
    std::memcpy(&bits, &e, 4);
    error_high = uint16_t(std::min<uint32_t>((bits + 0xffffu) >> 16, 0x7f80u));
  }
  float error() const {
    const uint32_t bits = uint32_t(error_high) << 16;
    float e;
    std::memcpy(&e, &bits, 4);
    return e;
  }

  // Whether its radius is the small one, k0 footprints: a first vertex's disc for caustic light
  // alone (bpm/eye_pass.h); every other is k1 footprints.
  bool small_disc() const { return diffuse_index == 0 && accepts == kAcceptsCaustic; }

  // Sort key that fixes the order of backward photons whatever thread stored them (an eye path
  // stores fewer than 16: kMaxBackwardPhotonsPerPath).
  uint64_t key() const { return (uint64_t(pixel) << 4) | place; }
};
static_assert(sizeof(BackwardPhoton) == 112, "the maps' memory: keep a backward photon small");

}  // namespace bpm
