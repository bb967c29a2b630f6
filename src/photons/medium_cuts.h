// Where a surface cuts the disc over which a point in a scattering medium gathers photon beams.
// A backward photon in a medium gathers each beam that passes within its radius r, blurred over
// the disc of radius r across the beam (bpm/medium_spheres.h). Beams end at surfaces: where a wall
// stands within r of the point, the part of that disc beyond the wall's plane holds no beam, and
// the estimate falls short, by up to half next to the wall. Over an image of fog above a floor
// that is a darkening of order r (the radii's usual bias is of order r^2), which the two-radius
// bias estimate sees about half of. As on surfaces (disc_probes.h), each beam's contribution is
// divided instead by the share of its disc on the point's side of the plane, which tends to 1 as
// the radius shrinks.
//
// The surface that matters most is the one the point's own ray left or met: a point drawn on a
// camera ray lies near a surface when it lies near the ray's end. So the ray's piece is probed
// both ways where its end lies within a few radii, and where a surface is met, the point's foot on
// it, which gives the plane. A wall that the ray passes near but does not meet (nor meets within a
// few radii: a grazing ray), and the second wall of a corner, are not seen; a thin opaque sheet in
// the medium, lit on both sides, is taken for a wall (its discs, which gather the beams beyond it
// through it, are then divided by their shares all the same: too bright near it).
#pragma once
#include "base/vec.h"
#include "integrator/counters.h"
#include "scene/render_scene.h"

namespace bpm {

// The point p's offset from the plane of the nearest surface within `radius` of it, found along
// its ray's direction d where the piece ends within kCutReach radii (to_end; from_start the other
// way, back to the piece's origin, which may be a surface, the camera or a point in the medium):
// the vector from the plane to p, whose length is the distance; zero where no surface was found.
// Only a surface at which the medium's beams end counts: not a curve, nor one that light crosses
// into the same medium. Up to two probe rays each way, counted in rays.probe_rays.
constexpr float kCutReach = 4;
Vec3 medium_cut(const RenderScene& scene, Vec3 p, Vec3 d, float to_end, float from_start,
                float radius, PathCounters& rays);

// The distance from the point to the line where the plane of `cut` (medium_cut) crosses the
// plane across a beam of unit direction d: h / sin(theta), theta the angle between the beam and
// the plane's normal; kInf without a cut, or for a beam along the normal.
float cut_line_distance(Vec3 cut, Vec3 d);
// The share of the disc of radius `radius` about the point that lies before a line at distance
// `line` from its centre: 1 where the line lies beyond the disc, 1/2 where it passes through the
// centre.
float disc_share_before(float line, float radius);
// Both: the share of the disc across the beam on the point's side of the plane.
inline float beam_disc_share(Vec3 cut, Vec3 d, float radius) {
  return disc_share_before(cut_line_distance(cut, d), radius);
}

}  // namespace bpm
