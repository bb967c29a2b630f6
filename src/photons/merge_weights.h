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
//                                                 BSDF, y0 by next-event estimation or by the BSDF
//                                                 (B0 is the sum of the two)
// The emission densities are the unguided ones (lights by power, uniform points, cosine
// directions): guided emission changes the photons' weights, not what they are weighed against.
// Every light combines: an area light's point is an area density; a point-like light's position
// (point, spot, goniometric, projection) is a delta that both sides leave out, and no BSDF sample
// finds it; a light at infinity starts its path with a direction, in whose solid-angle measure
// both sides count y0 (the photon's entry disc's density turned into an area density at z1), the
// direction of a distant light again a delta left out. Paths whose vertices z are points in
// scattering media or on surfaces (not curves) with gathered lobes, or with traced lobes only (a
// mirror, glass, a thin pane: the eye path goes on through them as the photon does, without
// next-event estimation there), and at least one of them not traced (a caustic at x stays the
// merge's), are combined; at a delta lobe both sides count the probability of choosing it and
// leave its delta out. A segment through a scattering medium is got across by the photon and by
// the BSDF sample with the same probability (PathState::pass: the segment's depth is the same both
// ways), which is left out of both products (where it would cancel), but for next-event
// estimation's shadow ray, which gets across for certain: its density in B0 is divided by that
// probability. At a point in a medium the phase function stands for the BSDF (its density is the
// same both ways) and the free flight's density of stopping there over that of getting across,
// about sigma_t there (DensityEnd: the mean over the wavelengths), for |cos|. Both passes compute
// the same products, each from its own end of the path, so that the weights of a path sum to one.
#pragma once
#include <cmath>

#include "integrator/path_vertex.h"
#include "scene/render_scene.h"

namespace bpm {

// Whether a combined path may pass through v: a point in a medium, a surface (not a curve) with
// gathered lobes, not Phong's (whose sampling is not reciprocal), or one whose lobes are all
// traced, but for a coat's (whose density is only estimated). Where a coat splits (BsdfPart), only
// the share of the light that the photon draws through the gathered part is combined: the photon's
// vertex then counts in A with the density of that draw, and the continuation's path is weighed by
// the same share (bsdf_gathered_probability); the share drawn through the coat stays the photon's
// alone.
bool combinable_vertex(const PathVertex& v);

// The photon's density (A), in the combined products, of a path through the combinable vertex v
// leaving along `to` having arrived from `from` (local directions): the BSDF's through the
// gathered part (times its share where a coat splits), the whole BSDF's where every lobe is
// traced; for a delta lobe (delta_probability > 0, the sample's) the probability of choosing it,
// its delta left out.
double combined_density(const PathVertex& v, Vec3 from, Vec3 to, TransportMode mode,
                        float delta_probability);

// For a delta lobe's sample, the probability of choosing its lobe, which stands for both sides'
// densities (a choice as probable both ways: Fresnel's reflectance is the same from either side,
// a mirror has one lobe; the deltas cancel); 0 for any other sample.
inline float delta_choice_probability(const BsdfSample& bs) {
  return bs.is_specular() ? bs.pdf_solid_angle : 0.0f;
}

// A vertex of a combined path where a segment ends, as the densities see it: a point on a surface
// of geometric normal n, where a solid-angle density turns into an area density by |cos| / d^2;
// or a point inside a medium (sigma > 0), where it turns into a volume density by sigma / d^2,
// sigma the mean over the wavelengths of sigma_t there: a free flight's density of stopping there
// over its probability of getting that far, which the products leave out (PathState::pass).
struct DensityEnd {
  Vec3 p, n;
  double sigma = 0;
  // |cos| or sigma for a segment along d (of length len) ending here.
  double factor(Vec3 d, double len) const {
    return sigma > 0 ? sigma : std::fabs(double(dot(n, d))) / len;
  }
};
inline DensityEnd density_end(const RenderScene& scene, const PathVertex& v,
                              const Wavelengths& wl) {
  if (v.medium >= 0)
    return {v.sp.p, Vec3(), double(medium_mean_sigma_t(scene, v.medium, v.sp.p, wl))};
  return {v.sp.p, v.sp.ng};
}

// A solid-angle density at `from` of the direction to `to.p`, turned into an area (or volume)
// density there.
inline double area_density(double pdf_solid_angle, Vec3 from, const DensityEnd& to) {
  const Vec3 d = to.p - from;
  const double d2 = double(length_squared(d));
  if (!(d2 > 0)) return 0;
  return pdf_solid_angle * to.factor(d, std::sqrt(d2)) / d2;
}

// A0 A1 as an area (or volume) density at `at`: the density of unguided emission (the light by
// power; on an area light a uniform point and a cosine-weighted direction) of leaving light
// `light` at y (geometric normal n, zero without a surface) along the unit direction w and
// arriving there; for a point-like light without its position's delta; for a light at infinity
// the entry disc's density there times that of the direction (a distant light's left out).
double emission_density(const RenderScene& scene, int light, Vec3 y, Vec3 n, Vec3 w,
                        const DensityEnd& at);

// A solid-angle density at p of the direction toward the point y (normal n) of light l, in the
// measure in which both sides count y: an area density at y; a light at infinity's direction
// itself; 0 for a delta light (no BSDF sample finds it).
double light_end_density(const Light& l, double pdf_solid_angle, Vec3 p, Vec3 y, Vec3 n);

// B0 by next-event estimation from p (sample_direct_light: the light by power, then its own
// sampling) of the point y (normal n) on light `light`, in light_end_density's measure; for a
// delta light (point-like or distant) the light's probability alone.
double light_sample_density(const RenderScene& scene, int light, Vec3 p, Vec3 y, Vec3 n);

// The running products of a photon's path (the light pass's side): after its k-th vertex z_k,
// B0 .. B(k-2) over A0 .. Ak. start() at emission, arrive() at each vertex (on a surface or in a
// medium), scatter() or scatter_in_medium() when it leaves one; merge_factor() is what a merge at
// a backward photon needs of it.
class PhotonMis {
 public:
  // The photon leaves light `light` at y, of geometric normal n (zero without a surface), along
  // the unit direction w.
  void start(const RenderScene& scene, int light, Vec3 y, Vec3 n, Vec3 w);
  // The photon arrives at its k-th vertex v (k from 1; on a surface or in a medium), having got
  // across the media on the way with the probability `pass` (PathState::pass).
  void arrive(const RenderScene& scene, const PathVertex& v, int k, float pass,
              const Wavelengths& wl);
  // It leaves v, its k-th vertex, along the world direction wi, drawn as the sample bs.
  void scatter(const PathVertex& v, const BsdfSample& bs, Vec3 wi, int k);
  // It leaves its k-th vertex, in a medium, along a direction that the phase function drew with
  // the density `phase` (the same both ways).
  void scatter_in_medium(float phase, int k);
  // The path is the photon's alone: from a light at infinity through a scattering medium that
  // reaches past the scene (the photon enters at the scene's bounds, where the eye path's shadow
  // ray toward the light never gets out).
  void stop() { on_ = false; }
  // For a merge at the vertex just arrived at: B0 .. B(m-1) over A0 .. A(m+1) times |cos| (sigma
  // in a medium, DensityEnd) at the vertex before over the squared distance (the factor that turns
  // the eye's solid-angle density into the measure of that vertex; merges start at the second),
  // so that the merge's weight is 1 / (1 + factor * p / (pi r^2 N)) with p the eye's BSDF density
  // at x of the photon's direction. 0: not combined (the merge counts the path in full).
  float merge_factor() const { return on_ && gathered_ ? float(r_ * seg_cos_ / seg_d2_) : 0.0f; }
  // Whether the path so far may be combined.
  bool on() const { return on_; }
  // A of the vertex just arrived at (k >= 2): the adjoint BSDF's density at the vertex before (a
  // surface), of the way here, as an area density here, times the probability of getting across the
  // media on the way (which a connection's shadow ray does not share); 0 at the first vertex, after
  // a traced vertex or a point in a medium (no connection joins one) or when not combined.
  float arrival_density() const { return on_ ? float(arrival_) : 0.0f; }
  // For a connection from the vertex just arrived at, z_k, to an eye vertex (vertex connections):
  // B0 .. B(k-1) over A0 .. Ak, given eye_pdf, the eye's BSDF density at z_k, arriving from the eye
  // vertex, of the way toward where the photon came from.
  double connection_ratio(double eye_pdf) const {
    return r_ * (eye_pdf * seg_cos_ / seg_d2_ + (k_ == 1 ? b0_ : 0.0));
  }

 private:
  bool on_ = false;
  bool gathered_ = false;     // a vertex with gathered lobes left behind (not a caustic)
  bool last_traced_ = false;  // the vertex before the current one has traced lobes only
  double r_ = 0, b0_ = 0;
  double a_ = 0, arrival_ = 0;  // the solid-angle A of the last scatter; the area A of the arrival
  int light_ = -1, k_ = 0;
  Vec3 y_, n_y_, w_;  // the light's point and normal, the emission's direction
  bool at_infinity_ = false, delta_ = false;
  DensityEnd prev_;  // the vertex before the current one
  DensityEnd here_;  // the current one
  // |cos| (sigma in a medium) at prev toward the current vertex and their squared distance; from
  // a light at infinity to the first vertex 1 and 1 (the direction's own measure; 0 and 1 for a
  // distant light).
  double seg_cos_ = 0, seg_d2_ = 1;
};

}  // namespace bpm
