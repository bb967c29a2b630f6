#include "materials/layered.h"

#include <bit>
#include <cmath>

#include "base/rng.h"
#include "base/sampling.h"
#include "materials/dielectric.h"
#include "materials/microfacet.h"

namespace bpm {
namespace {

DielectricMaterial coating(const CoatedDiffuseMaterial& m) { return DielectricMaterial{m.eta, m.roughness}; }

TransportMode adjoint(TransportMode mode) {
  return mode == TransportMode::kRadiance ? TransportMode::kImportance : TransportMode::kRadiance;
}

// Attenuation across the layer along w: unit extinction over the thickness, as pbrt-v4's Tr.
float layer_transmittance(float thickness, Vec3 w) {
  return w.z == 0 ? 0.0f : std::exp(-thickness / std::fabs(w.z));
}

uint64_t bits(float x) { return std::bit_cast<uint32_t>(x); }
uint64_t key_of(Vec3 a, Vec3 b) {
  return stream_key(0x6c6179657265ull, bits(a.x) | bits(a.y) << 32, bits(a.z) | bits(b.x) << 32, bits(b.y) | bits(b.z) << 32);
}

// A sample that can be used: it exists, carries value and has a density.
bool usable(const std::optional<BsdfSample>& s) {
  return s && !s->f.is_black() && s->pdf_solid_angle > 0 && s->wi.z != 0;
}

// The Lambertian base, seen from inside the layer (directions above it, z > 0).
float base_pdf(Vec3 wo, Vec3 wi) { return wo.z * wi.z > 0 ? std::fabs(wi.z) * kInvPi : 0; }

}  // namespace

Spectrum coated_diffuse_f(const CoatedDiffuseMaterial& m, Vec3 wo, Vec3 wi, TransportMode mode) {
  // Two-sided: seen from below, the material is the same as from above.
  if (wo.z < 0) {
    wo = -wo;
    wi = -wi;
  }
  // The base does not transmit, so light leaves on the side it arrived from.
  if (wo.z == 0 || wi.z <= 0) return {};
  const DielectricMaterial top = coating(m);
  const bool top_smooth = m.roughness.effectively_smooth();
  // Reflection off the coating itself (zero for a smooth coating: its mirror lobe is a delta).
  Spectrum f = dielectric_f(top, wo, wi, mode) * float(m.samples);
  Rng rng(key_of(wo, wi));
  for (int s = 0; s < m.samples; ++s) {
    // Into the layer along wo, and the way out toward wi traced backwards (adjoint transport).
    auto in = dielectric_sample(top, wo, rng.uniform(), {rng.uniform(), rng.uniform()}, mode, kTransmission);
    if (!usable(in)) continue;
    auto out = dielectric_sample(top, wi, rng.uniform(), {rng.uniform(), rng.uniform()}, adjoint(mode), kTransmission);
    if (!usable(out)) continue;
    Spectrum beta = in->f * (std::fabs(in->wi.z) / in->pdf_solid_angle);
    Vec3 w = in->wi;  // direction of travel inside the layer
    bool at_top = true;
    for (int depth = 0; depth < m.max_depth; ++depth) {
      if (depth > 3 && beta.max_component() < 0.25f) {
        float q = std::fmax(0.0f, 1 - beta.max_component());
        if (rng.uniform() < q) break;
        beta /= 1 - q;
      }
      beta *= layer_transmittance(m.thickness, w);
      at_top = !at_top;
      if (at_top) {
        // Reflected back into the layer by the coating, from inside.
        auto r = dielectric_sample(top, -w, rng.uniform(), {rng.uniform(), rng.uniform()}, mode, kReflection);
        if (!usable(r)) break;
        beta *= r->f * (std::fabs(r->wi.z) / r->pdf_solid_angle);
        w = r->wi;
        continue;
      }
      // At the base. Next-event estimation through the coating along the presampled way out,
      // weighted against reaching it by sampling the base (power heuristic) unless the coating
      // is smooth, where only this strategy can find it.
      Vec3 wb = -w, to_exit = -out->wi;
      Spectrum base = wb.z * to_exit.z > 0 ? m.reflectance * kInvPi : Spectrum();
      float wt = top_smooth ? 1 : power_heuristic(out->pdf_solid_angle, base_pdf(wb, to_exit));
      f += beta * base * (std::fabs(out->wi.z) * wt * layer_transmittance(m.thickness, out->wi) / out->pdf_solid_angle) *
           out->f;
      // Sample the base: f cos / pdf = reflectance for a cosine-distributed direction.
      Vec3 nw = sample_cosine_hemisphere({rng.uniform(), rng.uniform()});
      if (nw.z == 0) break;
      float pdf_b = cosine_hemisphere_pdf_solid_angle(nw.z);
      beta *= m.reflectance;
      w = nw;
      if (!top_smooth) {
        Spectrum f_exit = dielectric_f(top, -w, wi, mode);
        if (!f_exit.is_black()) {
          // Both strategies' densities over the same variable, the direction leaving the base:
          // the other strategy would have drawn it by refracting wi into the layer.
          float wt_exit = power_heuristic(pdf_b, dielectric_pdf(top, wi, -w, kTransmission));
          f += beta * f_exit * (layer_transmittance(m.thickness, w) * wt_exit);
        }
      }
    }
  }
  return f / float(m.samples);
}

float coated_diffuse_pdf(const CoatedDiffuseMaterial& m, Vec3 wo, Vec3 wi, TransportMode mode) {
  if (wo.z < 0) {
    wo = -wo;
    wi = -wi;
  }
  float sum = 0;
  if (wi.z > 0 && wo.z > 0) {
    const DielectricMaterial top = coating(m);
    const bool top_smooth = m.roughness.effectively_smooth();
    sum = float(m.samples) * dielectric_pdf(top, wo, wi, kReflection);
    Rng rng(key_of(wi, wo));
    for (int s = 0; s < m.samples; ++s) {
      // Transmission, base reflection, transmission: the dominant path.
      auto in = dielectric_sample(top, wo, rng.uniform(), {rng.uniform(), rng.uniform()}, mode, kTransmission);
      auto out = dielectric_sample(top, wi, rng.uniform(), {rng.uniform(), rng.uniform()}, adjoint(mode), kTransmission);
      if (!usable(in) || !usable(out)) continue;
      if (top_smooth) {
        sum += base_pdf(-in->wi, -out->wi);
        continue;
      }
      float p_base = base_pdf(-in->wi, -out->wi);
      sum += power_heuristic(out->pdf_solid_angle, p_base) * p_base;
      Vec3 nw = sample_cosine_hemisphere({rng.uniform(), rng.uniform()});
      float pdf_b = cosine_hemisphere_pdf_solid_angle(nw.z);
      if (pdf_b == 0) continue;
      float p_top = dielectric_pdf(top, -nw, wi, kTransmission);
      sum += power_heuristic(pdf_b, p_top) * p_top;
    }
  }
  // Mixed with a uniform density (pbrt-v4 does the same), so that no direction the walk can
  // produce gets a zero MIS density.
  return 0.1f / (4 * kPi) + 0.9f * sum / float(m.samples);
}

std::optional<BsdfSample> coated_diffuse_sample(const CoatedDiffuseMaterial& m, Vec3 wo, float uc, Vec2 u,
                                                TransportMode mode) {
  const bool flip = wo.z < 0;
  if (flip) wo = -wo;
  const DielectricMaterial top = coating(m);
  auto bs = dielectric_sample(top, wo, uc, u, mode, kReflection | kTransmission);
  if (!usable(bs)) return std::nullopt;
  if (!bs->is_transmission()) {  // reflected by the coating
    if (flip) bs->wi = -bs->wi;
    return bs;
  }
  Rng rng(key_of(wo, Vec3(uc, u.x, u.y)));
  Spectrum f = bs->f * std::fabs(bs->wi.z);
  float pdf = bs->pdf_solid_angle;
  Vec3 w = bs->wi;
  bool at_top = true;
  for (int depth = 0; depth < m.max_depth; ++depth) {
    float rr = f.max_component() / pdf;
    if (depth > 3 && rr < 0.25f) {
      float q = std::fmax(0.0f, 1 - rr);
      if (rng.uniform() < q) return std::nullopt;
      pdf *= 1 - q;
    }
    if (w.z == 0) return std::nullopt;
    f *= layer_transmittance(m.thickness, w);
    at_top = !at_top;
    if (!at_top) {
      Vec3 nw = sample_cosine_hemisphere({rng.uniform(), rng.uniform()});
      float pdf_b = cosine_hemisphere_pdf_solid_angle(nw.z);
      if (pdf_b == 0) return std::nullopt;
      f *= m.reflectance * (kInvPi * nw.z);
      pdf *= pdf_b;
      w = nw;
      continue;
    }
    auto t = dielectric_sample(top, -w, rng.uniform(), {rng.uniform(), rng.uniform()}, mode, kReflection | kTransmission);
    if (!usable(t)) return std::nullopt;
    f *= t->f;
    pdf *= t->pdf_solid_angle;
    w = t->wi;
    if (t->is_transmission()) {
      // Out through the coating: a reflection of the whole material, never a delta (the base is
      // diffuse).
      if (flip) w = -w;
      return BsdfSample{f, w, pdf, kReflection | kGlossy, 1};
    }
    f *= std::fabs(w.z);
  }
  return std::nullopt;
}

}  // namespace bpm
