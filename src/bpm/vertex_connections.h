// Vertex connection (Georgiev et al. 2012; docs/METHOD.md, "Vertex connections"): a photon's
// vertex z on a surface with gathered lobes, reached through such vertices only (a path that may
// be combined, photons/merge_weights.h), is joined by a shadow ray to the last diffuse vertex x of
// the eye path of a pixel drawn uniformly from the image's P pixels (that eye path's target
// backward photon, BackwardPhoton::vertex_target). The light path y0 .. z, x is then made three
// ways, each weighed by its density over the sum (the balance heuristic): the connection, with
// density N / P A0 .. Am per iteration (N photons, z = z_m); the merge at x, N A0 .. A(m+1)
// pi r^2; the eye path's continuation from x, 2^-level B0 .. Bm. Against the merge the
// connection's density is 1 / (pi r^2 P A(m+1)), A(m+1) the adjoint BSDF's density at z of the
// way to x as an area density at x: the merge, the continuation (continue_eye_path) and the
// connection each add that term.
#pragma once
#include <cstdint>
#include <vector>

#include "base/spectrum.h"
#include "bpm/backward_maps.h"
#include "materials/material.h"
#include "photons/light_path.h"
#include "scene/render_scene.h"

namespace bpm {

// What the light pass needs to join photons' vertices to eye vertices in one iteration.
struct VertexConnections {
  static constexpr uint32_t kNone = ~0u;
  // Per pixel of the image (P of them, each drawn with probability 1 / P), the index in the maps
  // of its backward photon marked vertex_target, or kNone.
  std::vector<uint32_t> target;
  double photons = 0;  // N: the photons per iteration the merges' densities count
  // The connections take the merges' share of their paths, the merges none
  // (ConnectionMode::kAlone).
  bool alone = false;
  double pixels() const { return double(target.size()); }
};

// Sets vc's targets from the backward photons of maps marked vertex_target, for an image of
// `pixels` pixels and N = photons.
void find_vertex_targets(const BackwardMaps& maps, size_t pixels, double photons,
                         VertexConnections* vc);

// A photon's vertex joined to an eye vertex, before it is added to the pixel's sum.
struct VertexHit {
  uint32_t pixel;
  Spectrum value;  // per photon emitted (before 1 / N): the pixel's tau, P and the weight included
  bool odd;        // a photon of odd index in its chunk (LightPassResult::flux_odd)
};

// The connection's density over the merge's at a target backward photon of radius r, for a path
// whose last light vertex reaches x with the area density a_x (A(m+1)).
inline double connection_over_merge(double r, double pixels, double a_x) {
  return 1 / (kPi * r * r * pixels * a_x);
}

// Joins photon hit h (h.mis set: the path may be combined; on a surface of material m_z) to
// backward photon bp (the target of `pixel`; its material m_x), within max_depth scattering
// events: appends the connection to `out` where nothing but media stands between (their
// transmittance at the wavelengths wl in its value; the probability of getting across them in
// the merge's and the continuation's densities, which the shadow ray does not share). Counts its
// shadow ray in *rays.
void connect_to_eye_vertex(const RenderScene& scene, const VertexConnections& vc,
                           const PhotonHit& h, const Material& m_z, const BackwardPhoton& bp,
                           uint32_t pixel, const Material& m_x, int max_depth, bool odd,
                           const Wavelengths& wl, uint64_t* rays, std::vector<VertexHit>& out);

}  // namespace bpm
