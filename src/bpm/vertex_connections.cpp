#include "bpm/vertex_connections.h"

#include <tbb/parallel_for.h>

#include <cmath>

#include "base/color.h"
#include "integrator/direct_light.h"
#include "integrator/path_vertex.h"
#include "photons/density.h"

namespace bpm {

void find_vertex_targets(const BackwardMaps& maps, size_t pixels, double photons,
                         VertexConnections* vc) {
  vc->photons = photons;
  vc->target.assign(pixels, VertexConnections::kNone);
  // An eye path marks one backward photon at most, so each pixel's slot is written once.
  tbb::parallel_for(size_t(0), maps.photons.size(), [&](size_t g) {
    const BackwardPhoton& bp = maps.photons[g];
    if (bp.vertex_target && bp.pixel < pixels) vc->target[bp.pixel] = uint32_t(g);
  });
}

void connect_to_eye_vertex(const RenderScene& scene, const VertexConnections& vc,
                           const PhotonHit& h, const Material& m_z, const BackwardPhoton& bp,
                           uint32_t pixel, const Material& m_x, int max_depth, bool odd,
                           const Wavelengths& wl, uint64_t* rays, std::vector<VertexHit>& out) {
  // The photon would arrive at x after one more bounce: within the merge's depth.
  if (int(bp.eye_depth) + h.bounces + 1 > max_depth) return;
  const Vec3 d = bp.p - h.sp.p;
  const float d2 = length_squared(d);
  if (!(d2 > 0)) return;
  const Vec3 w = d / std::sqrt(d2);  // from z toward x
  const float cos_z = std::fabs(dot(h.sp.ng, w)), cos_x = std::fabs(dot(bp.ng, w));
  if (cos_z == 0 || cos_x == 0) return;
  // The photon's light leaving z toward x through the gathered lobes, as a photon that went there
  // would carry it (scatter_photon_at_surface: the adjoint BSDF, whose order matters where a
  // material is not reciprocal, with the shading normal's correction) with the density of its
  // direction replaced by that of x's area; then what x's backward photon makes of it (a merge's
  // entry).
  const Frame fz = Frame::from_z(h.sp.ns);
  const Vec3 wo_z = fz.to_local(h.wi), wx_z = fz.to_local(w);
  const float cos_in = std::fabs(dot(h.wi, h.sp.ng));
  if (cos_in == 0) return;
  Spectrum leaving = h.flux *
                     bsdf_f(m_z, wo_z, wx_z, TransportMode::kImportance, BsdfPart::kGathered) *
                     (std::fabs(wo_z.z) / cos_in);
  bool hero_only = h.hero_only;
  if (!hero_only && material_is_dispersive(m_z)) {
    leaving = hero_wavelength_only(leaving);
    hero_only = true;
  }
  if (leaving.is_black()) return;
  Spectrum value =
      photon_contribution(m_x, bp.ng, bp.ns, bp.wo, -w, leaving * (cos_z * cos_x / d2));
  value *= hero_join_factor(bp.hero_only, hero_only);
  if (value.is_black()) return;
  // The densities (vertex_connections.h): the merge's over the connection's, and the
  // continuation's where the eye path went on from x.
  const double a_x =
      double(bsdf_gathered_probability(m_z, wo_z, wx_z, TransportMode::kImportance)) *
      bsdf_pdf(m_z, wo_z, wx_z, TransportMode::kImportance) * cos_x / d2;
  if (!(a_x > 0)) return;
  double merge = 1 / connection_over_merge(bp.radius, vc.pixels(), a_x), continuation = 0;
  if (bp.combined) {
    const Frame fx = Frame::from_z(bp.ns);
    const Vec3 wo_x = fx.to_local(bp.wo);
    // The lobes the eye path gathered with at x (light_pass.cpp, combined_merge_weight).
    const BsdfPart part =
        bsdf_traced_part_probability(m_x, wo_x) == 0 ? BsdfPart::kAll : BsdfPart::kGathered;
    const double b_x =
        double(bsdf_pdf(m_x, wo_x, fx.to_local(-w), TransportMode::kRadiance, part)) * cos_z / d2;
    const double b_z = bsdf_pdf(m_z, wx_z, wo_z, TransportMode::kRadiance);
    continuation = std::ldexp(vc.pixels() / vc.photons, -int(bp.continue_level)) *
                   h.mis->connection_ratio(b_z) * b_x;
  }
  if (!std::isfinite(merge + continuation)) return;
  ++*rays;
  const Vec3 origin = offset_origin(h.sp.p, h.sp.ng, w, h.sp.error);
  Spectrum seen(1.0f);
  if (scene.media.empty()) {
    if (scene.occluded(origin, bp.p)) return;
  } else {
    // Through media the shadow ray carries their transmittance (a weight); the photon and the
    // eye path from x get across them with the probability `pass`, which the merge's and the
    // continuation's densities count and the connection's does not.
    float pass = 1;
    seen = shadow_transmittance(scene, origin, bp.p,
                                medium_toward(scene, h.object, h.sp.ng, w, h.ray_medium), false, wl,
                                &pass);
    if (seen.is_black()) return;
    merge *= double(pass);
    continuation *= double(pass);
  }
  const double others = merge + continuation;
  const double weight = vc.alone ? (1 + merge) / (1 + others) : 1 / (1 + others);
  if (!(weight > 0) || !std::isfinite(weight)) return;
  out.push_back({pixel, bp.tau * value * seen * float(vc.pixels() * weight), odd});
}

}  // namespace bpm
