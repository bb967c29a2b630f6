// The share of a photon estimate's disc where photons can land (bpm's backward photons, fpm's
// gathers). Eq. (2) divides the photons gathered by pi r^2, the whole disc; but where a wall stands
// inside the disc, or the surface ends at an edge, photons land on part of it only, and the
// estimate falls short: dark seams along every corner and edge, and in a bright closed room about
// 1% of all its light (indirect light gathered near corners is carried everywhere). Probe rays
// measure the share, and the estimate is divided by it instead. The share tends to 1 as the radius
// shrinks, wherever the point is not on an edge, so the estimator stays consistent.
//
// Probing every disc would cost as much as the rest of the eye pass; most discs are whole. A disc
// can be cut only by geometry near its point, which the camera sees around the pixel: one ray
// through each pixel's centre, before the first iteration, finds where objects, creases and depth
// steps are, and only pixels within a disc's radius of one probe their first vertex. Later
// vertices (seen through specular ones, bpm's at D > 0, fpm's final gathers) are always probed.
// What is probed depends only on the scene, the camera and the iteration, never on another
// iteration, so an iteration is the same computation in any process and after a resume.
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include "base/rng.h"
#include "camera/camera.h"
#include "integrator/counters.h"
#include "photons/density.h"
#include "scene/render_scene.h"

namespace bpm {

// Probes per disc. They lie uniformly over the disc, stratified by area so that
// probes 0-1 fall within r/2 and 0-3 within r/sqrt 2 (the nested discs of the bias estimate,
// density.h). Bit i of `found` says that probe i found surface where photons count, of `cut`
// that it found none (a wall, an edge, a crease); a probe in neither says nothing (below).
constexpr int kDiscProbes = 8;
struct DiscProbes {
  uint8_t found = 0, cut = 0;
  bool looked = false;  // probes were cast: the disc is not plainly whole (below)
};

// Where the photons an estimate gathers may lie: on the gathering point's own object (bpm keeps a
// map per object), or on any object that holds photons (fpm's maps hold them all: any with a
// gathered lobe, so not glass, interfaces or a smooth conductor).
enum class PhotonSurfaces { kOwnObject, kAnyObject };

// Probes the disc of `radius` about sp.p in its tangent plane, on the side wo points to. A probe
// is a ray from above the point, 60 degrees off the plane, aimed at a point of the disc: it finds
// surface when it hits `object` inside the sphere of `radius` with a normal that agrees with sp's
// to within normal_cos, as a photon must to be gathered (under kAnyObject, also any other object
// that holds photons, its normal compared with its sign as fpm's gather does). A wall in between
// stops it; past an edge it misses the surface; another object's surface in the disc's plane (floor
// tiles) is a cut unless it counts. Where the surface curves away below the plane, the probe
// meets it outside the sphere and says nothing. The probes count in rays.probe_rays. A disc with
// nothing within two radii but flat triangles of its own mesh, and no border of the mesh inside
// it, is whole on sight of the scene's tree: then no probe is cast and every bit of `found` is set.
// `primitive` (the triangle the point lies on, when known) lets a point on a curved or folded
// mesh skip that look.
DiscProbes probe_disc(const RenderScene& scene, const SurfacePoint& sp, Vec3 wo, int object,
                      PhotonSurfaces where, float radius, float normal_cos, Rng& rng,
                      PathCounters& rays, int primitive = -1);

// probe_disc in two steps, for a caller that casts the probes later or not at all: the look at
// the scene's tree (no rays; true: the disc is whole), and the probes themselves (sp.p, sp.ng and
// sp.error are read).
bool disc_plainly_whole(const RenderScene& scene, const SurfacePoint& sp, int object, int primitive,
                        float radius, float normal_cos);
DiscProbes cast_disc_probes(const RenderScene& scene, const SurfacePoint& sp, Vec3 wo, int object,
                            PhotonSurfaces where, float radius, float normal_cos, Rng& rng,
                            PathCounters& rays);

// Whether a photon that landed at q is cut off from the disc's point p, as a probe would judge the
// disc cut there: the segment from p to q, lifted off the surface along n (the normal on the
// gathering side) by a thousandth of the radius, meets another object that light does not cross
// (a shelf standing on a wall between them), or `object` where its normal disagrees (a crease).
// The probes measure the share of the disc that photons reach along the surface; photons from the
// rest of it (past a thin board, in a shadow the probes happened to miss) would otherwise leak
// light across. Asked for the discs whose probes looked (DiscProbes::looked).
bool photon_cut_off(const RenderScene& scene, Vec3 p, Vec3 n, Vec3 q, int object, float radius,
                    float normal_cos, PathCounters& rays);

// Whether the probes apply to the shape: not to spheres and cylinders, whose surface inside a
// gathering sphere is whole (on a sphere its area is pi r^2 exactly, Archimedes' hat-box theorem)
// unless another object cuts into it, and whose curvature would send the probes past it.
inline bool may_cut_discs(const Shape& shape) {
  return std::holds_alternative<TriangleMesh>(shape) || std::holds_alternative<Disk>(shape);
}

// The share of the disc (nested = 0), of the one of radius r / sqrt 2 (1) or of r / 2 (2) where
// photons can land: the probes that found surface among those that found surface or a cut, at
// least half a probe's worth; 1 when no probe found a cut.
inline float disc_share(uint8_t found, uint8_t cut, int nested) {
  constexpr uint8_t kBits[3] = {0xff, 0x0f, 0x03};
  const int in = __builtin_popcount(unsigned(found & kBits[nested])),
            out = __builtin_popcount(unsigned(cut & kBits[nested]));
  return out == 0 ? 1.0f : std::fmax(float(in), 0.5f) / float(in + out);
}

// Per pixel, whether the surface seen through its centre meets another there or nearby: a change
// of object between neighbours, a crease, a step off the plane, or no surface (the sky, an
// interface-only path), from one camera ray per pixel.
std::vector<uint8_t> find_edges(const RenderScene& scene, const Camera& camera, int width,
                                int height);

// Per pixel, bit 0: some cut of the large disc is possible, bit 1: of the small one; that is, an
// edge pixel (find_edges) or the image's border lies within radius_px1 or radius_px0 pixels (the
// discs' radii on screen, rounded up, with the filter's reach).
void mark_near_edges(const std::vector<uint8_t>& edges, int width, int height, int radius_px0,
                     int radius_px1, std::vector<uint8_t>* near);

// The pixels near edges for each iteration's discs: the edges found once, before the first
// iteration, spread over the discs' radii on screen with the pixel filter's reach (where in or
// around the pixel its sample falls), anew whenever their rounded sizes change.
class NearEdges {
 public:
  // Not enabled (no probes, or radii in world units, whose sizes on screen are unknown): no
  // marks are made, and every disc may be cut. filter_radius: the pixel filter's, in pixels.
  NearEdges(bool enabled, const RenderScene& scene, const Camera& camera, int width, int height,
            Vec2 filter_radius);
  // Marks the pixels for discs of radius_px0 and radius_px1 pixels (the iteration's k0 and k1
  // times its radius scale); nothing to do when the rounded sizes have not changed.
  void mark(float radius_px0, float radius_px1);
  // The pixel's mark_near_edges bits: 3 (both discs may be cut) when not enabled.
  uint8_t at(size_t pixel) const { return near_.empty() ? uint8_t(3) : near_[pixel]; }

 private:
  std::vector<uint8_t> edges_, near_;
  int width_, height_, radii_[2] = {-1, -1};
  float reach_;
};

// Divides the nested sums by the shares of their discs where photons can land (disc_share).
inline void divide_by_disc_shares(NestedSums* sums, uint8_t found, uint8_t cut) {
  if (!cut) return;
  sums->all /= disc_share(found, cut, 0);
  sums->half /= disc_share(found, cut, 1);
  sums->quarter /= disc_share(found, cut, 2);
}

}  // namespace bpm
