#include "bpm/eye_pass.h"

#include <algorithm>
#include <cmath>

#include "base/sampling.h"

namespace bpm {

Spectrum trace_eye_path(const RenderScene& scene, const EyePassParams& prm, Ray ray, uint32_t pixel, Rng& rng,
                        ObjectPhotonLists& out, EyeCounters& counters) {
  const Wavelengths& wl = prm.materials->wl;
  Spectrum L, beta(1.0f);
  int diffuse = 0;      // diffuse vertices so far (j of DESIGN.md)
  int depth = 0;        // scattering events so far, as the path integrator counts them
  float length = 0;     // world distance along the path from the camera
  // The previous scattering vertex was diffuse and its BSDF sample led here through interfaces
  // only: an emitter found now is direct light at that vertex, shared with NEE by MIS.
  bool after_diffuse_sample = false;
  float prev_pdf_bsdf = 0;
  Vec3 prev_p;
  int medium = -1;  // the camera is in vacuum (flatten.cpp)
  ++counters.rays.camera_rays;
  for (int guard = 0; guard < 10000; ++guard) {
    Hit hit;
    if (counters.rays.log) counters.rays.log->closest_hit.push_back(ray);
    if (!scene.intersect(ray, &hit)) {
      cross_medium(scene, medium, kInf, wl, beta);  // escaping through a medium
      for (int li : scene.infinite_lights) {
        const Light& light = scene.lights[size_t(li)];
        Spectrum Le = environment_radiance(light, ray.d, wl);
        if (Le.is_black()) continue;
        if (diffuse == 0) {
          L += beta * Le;
        } else if (after_diffuse_sample) {
          float p_l = scene.light_distribution.pmf(li) * light_pdf_li(light, nullptr, prev_p, ray.d, {}, {});
          L += beta * Le * power_heuristic(prev_pdf_bsdf, p_l);
        }
      }
      break;
    }
    length += hit.t * bpm::length(ray.d);
    if (!cross_medium(scene, medium, hit.t * bpm::length(ray.d), wl, beta)) break;
    SurfacePoint sp = scene.surface(ray, hit);
    Vec3 wo = -ray.d;
    int light_index = scene.light_of_hit(hit);
    if (light_index >= 0 && (diffuse == 0 || after_diffuse_sample)) {
      const AreaLight& al = std::get<AreaLight>(scene.lights[light_index]);
      Spectrum Le = area_light_radiance(al, sp.ng, sp.uv, wo, wl);
      if (!Le.is_black()) {
        if (diffuse == 0) {
          L += beta * Le;  // seen from the camera through specular vertices only
        } else {
          const Light& light = scene.lights[light_index];
          float p_l = scene.light_distribution.pmf(light_index) *
                      light_pdf_li(light, scene.light_shape(light), prev_p, ray.d, sp.p, sp.ng);
          L += beta * Le * power_heuristic(prev_pdf_bsdf, p_l);
        }
      }
    }
    int material_index = scene.objects[hit.object].material;
    Material storage;
    const Material& m = prm.materials->at(material_index, texture_context(sp), storage);
    if (std::holds_alternative<InterfaceMaterial>(m)) {
      medium = medium_toward(scene, hit.object, sp.ng, ray.d, medium);
      ray = spawn_ray(sp, ray.d);
      ++counters.rays.bounce_rays;
      continue;
    }
    if (depth++ == prm.max_depth) break;
    Frame frame = Frame::from_z(sp.ns);
    Vec3 wo_local = frame.to_local(wo);
    if (wo_local.z == 0) break;
    bool is_diffuse = !bsdf_is_specular(m);
    if (is_diffuse) {
      ++diffuse;
      bool last = diffuse == prm.diffuse_depth + 1;
      // Direct light: shared by MIS with the BSDF sample that continues the path, or alone at the
      // last vertex, where the path ends.
      L += beta * sample_direct_light(scene, sp, hit.object, medium, m, frame, wo_local, !last, wl, rng, counters.rays);
      BackwardPhoton bp;
      bp.p = sp.p;
      bp.radius = length * (last ? prm.radius_per_length1 : prm.radius_per_length0);
      bp.ng = sp.ng;
      bp.ns = sp.ns;
      bp.uv = sp.uv;
      bp.wo = wo;
      bp.tau = beta;
      bp.pixel = pixel;
      bp.material = uint32_t(material_index);
      bp.eye_depth = uint16_t(std::min(depth, 65535));
      bp.accepts = last ? (kAcceptsCaustic | kAcceptsIndirect) : kAcceptsCaustic;
      bp.diffuse_index = uint8_t(diffuse - 1);
      if (bp.radius > 0 && !beta.is_black()) {
        out[hit.object].push_back(bp);
        ++counters.backward_photons;
      }
      if (last) break;
    }
    float uc = rng.uniform();
    Vec2 u{rng.uniform(), rng.uniform()};
    // Radiance-mode sampling; for a non-reciprocal BSDF the lobe drawn is the light-direction one
    // and the weight carries the ratio of the two BSDF values (the paper's Helmholtz
    // compensation, section 2; see PhongMaterial).
    auto bs = bsdf_sample(m, wo_local, uc, u, TransportMode::kRadiance);
    if (!bs) break;
    beta *= bs->f * (std::fabs(bs->wi.z) / bs->pdf_solid_angle);
    if (beta.is_black()) break;
    after_diffuse_sample = is_diffuse;
    prev_pdf_bsdf = bs->mis_pdf;
    prev_p = sp.p;
    Vec3 wi = frame.to_world(bs->wi);
    medium = medium_toward(scene, hit.object, sp.ng, wi, medium);
    ray = spawn_ray(sp, wi);
    ++counters.rays.bounce_rays;
  }
  return L;
}

}  // namespace bpm
