// Combined estimators (DESIGN.md, "Where the estimator may go"): a light path that reaches the
// last diffuse vertex x of an eye path after bouncing on the way (indirect light there) is made
// two ways, by merging the photon at x's backward photon, and by continuing the eye path from x
// by BSDF sampling until it finds the light, by next-event estimation or by a BSDF sample. Each
// counts it with its density over the sum of all three (the balance heuristic; vertex connection
// and merging, Georgiev et al. 2012, restricted to these strategies). For the path
// y0 (on a light), z1 .. zm, x, in area measure and with the eye path up to x left out (common):
//   merging:       A0 A1 ... A(m+1) * pi r^2 N     the photon's densities: y0 and its direction by
//                                                 emission, z(k+1) by the adjoint BSDF at zk; the
//                                                 whole disc of radius r (its probes come after
//                                                 the light pass; any density both passes use alike
//                                                 keeps the weights summing to one), N photons per
//                                                 iteration
//   continuation:  B0 B1 ... Bm                    the eye's: zm from x, z(k-1) from zk by the
//   BSDF,
//                                                 y0 by next-event estimation or by the BSDF (B0 is
//                                                 the sum of the two)
// The emission densities are the unguided ones (lights by power, uniform points, cosine
// directions): guided emission changes the photons' weights, not what they are weighed against.
// Only paths whose light is an area light or point-like (combinable_light; a point-like light's
// position is a delta that both sides leave out) and whose vertices z all have gathered lobes only
// (on a surface, not a curve) are combined; every other path stays the merge's alone, and the
// continuation leaves it out. Both passes compute the same products, each from its own end of the
// path, so that the weights of a path sum to one.
#pragma once
#include <cmath>

#include "integrator/path_vertex.h"
#include "scene/render_scene.h"

namespace bpm {

// Whether a combined path may start on l: an area light, or a point-like one (point, spot,
// goniometric, projection), whose position's delta both sides leave out of their densities (it
// cancels in every ratio) and which no BSDF sample finds.
bool combinable_light(const Light& l);

// Whether a combined path may pass through v: a surface (not a curve) with gathered lobes, not
// Phong's (whose sampling is not reciprocal). Where a coat splits (BsdfPart), only the share of
// the light that the photon draws through the gathered part is combined: the photon's vertex then
// counts in A with the density of that draw, and the continuation's path is weighed by the same
// share (bsdf_gathered_probability); the share drawn through the coat stays the photon's alone.
bool combinable_vertex(const PathVertex& v);

// A solid-angle density at `from` of the direction to `to`, turned into an area density at `to`
// (whose geometric normal is n_to).
inline double area_density(double pdf_solid_angle, Vec3 from, Vec3 to, Vec3 n_to) {
  const Vec3 d = to - from;
  const double d2 = double(length_squared(d));
  if (!(d2 > 0)) return 0;
  return pdf_solid_angle * std::fabs(double(dot(n_to, d))) / (d2 * std::sqrt(d2));
}

// A0 times the solid-angle density of A1 for light `light` (unguided emission: the light by
// power; on an area light a uniform point and a cosine-weighted direction): the density of
// emitting along the unit direction w from a point of geometric normal n; for a point-like light
// the light's and its direction's alone; 0 for other lights.
double emission_density(const RenderScene& scene, int light, Vec3 n, Vec3 w);

// B0 by next-event estimation from p (sample_direct_light: the light by power, then its own
// sampling) of the point y on area light `light`, of geometric normal n: an area density; for a
// point-like light the light's density alone.
double light_sample_density(const RenderScene& scene, int light, Vec3 p, Vec3 y, Vec3 n);

// The running products of a photon's path (the light pass's side): after its k-th vertex z_k,
// B0 .. B(k-2) over A0 .. Ak. start() at emission, arrive() at each surface vertex, scatter() when
// it leaves one; merge_factor() is what a merge at a backward photon needs of it.
class PhotonMis {
 public:
  // The photon leaves light `light` at y, of geometric normal n (zero for a point-like light),
  // along the unit direction w. A light that combinable_light refuses: not combined.
  void start(const RenderScene& scene, int light, Vec3 y, Vec3 n, Vec3 w);
  // The photon arrives at its k-th vertex v (k from 1).
  void arrive(const RenderScene& scene, const PathVertex& v, int k);
  // It leaves v, its k-th vertex, along the world direction wi, drawn through a traced lobe or
  // not.
  void scatter(const PathVertex& v, Vec3 wi, bool traced, int k);
  // For a merge at the vertex just arrived at: B0 .. B(m-1) over A0 .. A(m+1) times the cosine at
  // the vertex before over the squared distance, so that the merge's weight is
  // 1 / (1 + factor * p / (pi r^2 N)) with p the eye's BSDF density at x of the photon's
  // direction. 0: not combined (the merge counts the path in full).
  float merge_factor() const { return on_ ? float(r_ * seg_cos_ / seg_d2_) : 0.0f; }
  // Whether the path so far may be combined.
  bool on() const { return on_; }
  // A of the vertex just arrived at (k >= 2): the adjoint BSDF's density at the vertex before, of
  // the way here, as an area density here; 0 at the first vertex or when not combined.
  float arrival_density() const { return on_ ? float(arrival_) : 0.0f; }
  // For a connection from the vertex just arrived at, z_k, to an eye vertex (vertex connections):
  // B0 .. B(k-1) over A0 .. Ak, given eye_pdf, the eye's BSDF density at z_k, arriving from the eye
  // vertex, of the way toward where the photon came from.
  double connection_ratio(double eye_pdf) const {
    return r_ * (eye_pdf * seg_cos_ / seg_d2_ + (k_ == 1 ? b0_ : 0.0));
  }

 private:
  bool on_ = false;
  double r_ = 0, b0_ = 0;
  double a_ = 0, arrival_ = 0;  // the solid-angle A of the last scatter; the area A of the arrival
  int light_ = -1, k_ = 0;
  Vec3 y_, n_y_;                     // the light's point and normal
  Vec3 prev_, prev_n_;               // the vertex before the current one, and its geometric normal
  double seg_cos_ = 0, seg_d2_ = 1;  // |cos| at prev toward the current vertex, squared distance
};

}  // namespace bpm
