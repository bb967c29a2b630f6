#include "materials/layered.h"

#include <bit>
#include <cmath>

#include "base/rng.h"
#include "base/sampling.h"
#include "materials/dielectric.h"
#include "materials/microfacet.h"

namespace bpm {
namespace {

TransportMode adjoint(TransportMode mode) {
  return mode == TransportMode::kRadiance ? TransportMode::kImportance : TransportMode::kRadiance;
}

// Attenuation across the layer along w: unit extinction over the thickness, as pbrt-v4's Tr.
float layer_transmittance(float thickness, Vec3 w) {
  return w.z == 0 ? 0.0f : std::exp(-thickness / std::fabs(w.z));
}

uint64_t bits(float x) { return std::bit_cast<uint32_t>(x); }
uint64_t key_of(Vec3 a, Vec3 b) {
  return stream_key(0x6c6179657265ull, bits(a.x) | bits(a.y) << 32, bits(a.z) | bits(b.x) << 32,
                    bits(b.y) | bits(b.z) << 32);
}

// A sample that can be used: it exists, carries value and has a density.
bool usable(const std::optional<BsdfSample>& s) {
  return s && !s->f.is_black() && s->pdf_solid_angle > 0 && s->wi.z != 0;
}

// The reflector under the coating, seen from inside the layer: a Lambertian or a conductor
// (any non-transmitting Material would do).
struct Base {
  Material m;
  bool specular;
  explicit Base(Material mat) : m(std::move(mat)), specular(bsdf_is_specular(m)) {}
  Spectrum f(Vec3 wo, Vec3 wi, TransportMode mode) const { return bsdf_f(m, wo, wi, mode); }
  float pdf(Vec3 wo, Vec3 wi, TransportMode mode) const { return bsdf_pdf(m, wo, wi, mode); }
  std::optional<BsdfSample> sample(Vec3 wo, Rng& rng, TransportMode mode) const {
    float uc = rng.uniform();
    return bsdf_sample(m, wo, uc, {rng.uniform(), rng.uniform()}, mode);
  }
};

struct Layer {
  DielectricMaterial top;
  Base base;
  float thickness;
  int max_depth, samples;
  // Which lobes to see (BsdfPart): the coating's own reflection (`coat`), the walks under it
  // (`walks`), or both. A material whose coating is not traced, or whose base is traced as well,
  // does not split: it is seen whole.
  bool coat = true, walks = true;
  Layer(const CoatLayer& c, Material base_material, BsdfPart part)
      : top{c.eta, c.roughness, nullptr},
        base(std::move(base_material)),
        thickness(c.thickness),
        max_depth(c.max_depth),
        samples(c.samples) {
    const bool splits = c.roughness.traced() && !(base.specular || base_traced());
    if (splits && part == BsdfPart::kGathered) coat = false;
    if (splits && part == BsdfPart::kTraced) walks = false;
  }
  bool base_traced() const {
    const auto* c = std::get_if<ConductorMaterial>(&base.m);
    return c && c->roughness.traced();
  }
};

Spectrum layered_f(const Layer& L, Vec3 wo, Vec3 wi, TransportMode mode) {
  // Two-sided: seen from below, the material is the same as from above.
  if (wo.z < 0) {
    wo = -wo;
    wi = -wi;
  }
  // The base does not transmit, so light leaves on the side it arrived from.
  if (wo.z == 0 || wi.z <= 0) return {};
  const DielectricMaterial& top = L.top;
  const bool top_smooth = top.roughness.effectively_smooth();
  // Reflection off the coating itself (zero for a smooth coating: its mirror lobe is a delta).
  Spectrum f = L.coat ? dielectric_f(top, wo, wi, mode) * float(L.samples) : Spectrum();
  if (!L.walks) return f / float(L.samples);
  Rng rng(key_of(wo, wi));
  for (int s = 0; s < L.samples; ++s) {
    // Into the layer along wo, and the way out toward wi traced backwards (adjoint transport).
    auto in = dielectric_sample(top, wo, rng.uniform(), {rng.uniform(), rng.uniform()}, mode,
                                kTransmission);
    if (!usable(in)) continue;
    auto out = dielectric_sample(top, wi, rng.uniform(), {rng.uniform(), rng.uniform()},
                                 adjoint(mode), kTransmission);
    if (!usable(out)) continue;
    Spectrum beta = in->f * (std::fabs(in->wi.z) / in->pdf_solid_angle);
    Vec3 w = in->wi;  // direction of travel inside the layer
    bool at_top = true;
    for (int depth = 0; depth < L.max_depth; ++depth) {
      if (depth > 3 && beta.max_component() < 0.25f) {
        float q = std::fmax(0.0f, 1 - beta.max_component());
        if (rng.uniform() < q) break;
        beta /= 1 - q;
      }
      beta *= layer_transmittance(L.thickness, w);
      at_top = !at_top;
      if (at_top) {
        // Reflected back into the layer by the coating, from inside.
        auto r = dielectric_sample(top, -w, rng.uniform(), {rng.uniform(), rng.uniform()}, mode,
                                   kReflection);
        if (!usable(r)) break;
        beta *= r->f * (std::fabs(r->wi.z) / r->pdf_solid_angle);
        w = r->wi;
        continue;
      }
      // At the base. Next-event estimation through the coating along the presampled way out
      // (impossible for a mirror base), weighted against reaching it by sampling the base (power
      // heuristic) unless the coating is smooth, where only this strategy can find it.
      Vec3 wb = -w, to_exit = -out->wi;
      if (!L.base.specular) {
        float wt =
            top_smooth ? 1 : power_heuristic(out->pdf_solid_angle, L.base.pdf(wb, to_exit, mode));
        f += beta * L.base.f(wb, to_exit, mode) *
             (std::fabs(out->wi.z) * wt * layer_transmittance(L.thickness, out->wi) /
              out->pdf_solid_angle) *
             out->f;
      }
      auto b = L.base.sample(wb, rng, mode);
      if (!usable(b)) break;
      beta *= b->f * (std::fabs(b->wi.z) / b->pdf_solid_angle);
      w = b->wi;
      if (!top_smooth) {
        Spectrum f_exit = dielectric_f(top, -w, wi, mode);
        if (!f_exit.is_black()) {
          // Both strategies' densities over the same variable, the direction leaving the base:
          // the other strategy would have drawn it by refracting wi into the layer.
          float wt_exit =
              L.base.specular
                  ? 1
                  : power_heuristic(b->pdf_solid_angle, dielectric_pdf(top, wi, -w, kTransmission));
          f += beta * f_exit * (layer_transmittance(L.thickness, w) * wt_exit);
        }
      }
    }
  }
  return f / float(L.samples);
}

float layered_pdf(const Layer& L, Vec3 wo, Vec3 wi, TransportMode mode) {
  if (wo.z < 0) {
    wo = -wo;
    wi = -wi;
  }
  float sum = 0;
  if (wi.z > 0 && wo.z > 0) {
    const DielectricMaterial& top = L.top;
    const bool top_smooth = top.roughness.effectively_smooth();
    if (L.coat) sum = float(L.samples) * dielectric_pdf(top, wo, wi, kReflection);
    if (!L.walks) return sum / float(L.samples);
    Rng rng(key_of(wi, wo));
    for (int s = 0; s < L.samples; ++s) {
      // Transmission, base reflection, transmission: the dominant path.
      auto in = dielectric_sample(top, wo, rng.uniform(), {rng.uniform(), rng.uniform()}, mode,
                                  kTransmission);
      auto out = dielectric_sample(top, wi, rng.uniform(), {rng.uniform(), rng.uniform()},
                                   adjoint(mode), kTransmission);
      if (!usable(in) || !usable(out)) continue;
      if (top_smooth) {
        sum += L.base.pdf(-in->wi, -out->wi, mode);
        continue;
      }
      auto b = L.base.sample(-in->wi, rng, mode);
      if (!usable(b)) continue;
      if (!L.base.specular) {
        float p_base = L.base.pdf(-in->wi, -out->wi, mode);
        sum += power_heuristic(out->pdf_solid_angle, p_base) * p_base;
      }
      float p_top = dielectric_pdf(top, -b->wi, wi, kTransmission);
      sum += (L.base.specular ? 1 : power_heuristic(b->pdf_solid_angle, p_top)) * p_top;
    }
  }
  // Mixed with a uniform density (pbrt-v4 does the same), so that no direction the walk can
  // produce gets a zero MIS density.
  return 0.1f / (4 * kPi) + 0.9f * sum / float(L.samples);
}

std::optional<BsdfSample> layered_sample(const Layer& L, Vec3 wo, float uc, Vec2 u,
                                         TransportMode mode) {
  const bool flip = wo.z < 0;
  if (flip) wo = -wo;
  const DielectricMaterial& top = L.top;
  auto bs = dielectric_sample(top, wo, uc, u, mode,
                              L.walks ? kReflection | kTransmission : unsigned(kReflection));
  if (!usable(bs)) return std::nullopt;
  if (!bs->is_transmission()) {  // reflected by the coating
    if (!L.coat) return std::nullopt;
    if (flip) bs->wi = -bs->wi;
    if (top.roughness.traced()) bs->flags |= kTraced;
    return bs;
  }
  Rng rng(key_of(wo, Vec3(uc, u.x, u.y)));
  Spectrum f = bs->f * std::fabs(bs->wi.z);
  float pdf = bs->pdf_solid_angle;
  Vec3 w = bs->wi;
  bool at_top = true, specular_path = bs->is_specular();
  for (int depth = 0; depth < L.max_depth; ++depth) {
    float rr = f.max_component() / pdf;
    if (depth > 3 && rr < 0.25f) {
      float q = std::fmax(0.0f, 1 - rr);
      if (rng.uniform() < q) return std::nullopt;
      pdf *= 1 - q;
    }
    if (w.z == 0) return std::nullopt;
    f *= layer_transmittance(L.thickness, w);
    at_top = !at_top;
    std::optional<BsdfSample> t;
    if (!at_top) {
      t = L.base.sample(-w, rng, mode);
    } else {
      float uc2 = rng.uniform();
      t = dielectric_sample(top, -w, uc2, {rng.uniform(), rng.uniform()}, mode,
                            kReflection | kTransmission);
    }
    if (!usable(t)) return std::nullopt;
    f *= t->f;
    pdf *= t->pdf_solid_angle;
    specular_path = specular_path && t->is_specular();
    w = t->wi;
    if (t->is_transmission()) {
      // Out through the coating: a reflection of the whole material.
      if (flip) w = -w;
      return BsdfSample{f, w, pdf, kReflection | (specular_path ? kSpecular : kGlossy), 1};
    }
    f *= std::fabs(w.z);
  }
  return std::nullopt;
}

Layer layer_of(const Material& m, BsdfPart part) {
  if (auto* d = std::get_if<CoatedDiffuseMaterial>(&m))
    return Layer(d->layer, DiffuseMaterial{d->reflectance}, part);
  const auto& c = std::get<CoatedConductorMaterial>(m);
  return Layer(c.layer, c.conductor, part);
}

}  // namespace

Spectrum layered_f(const Material& m, Vec3 wo, Vec3 wi, TransportMode mode, BsdfPart part) {
  return layered_f(layer_of(m, part), wo, wi, mode);
}
float layered_pdf(const Material& m, Vec3 wo, Vec3 wi, TransportMode mode, BsdfPart part) {
  return layered_pdf(layer_of(m, part), wo, wi, mode);
}
std::optional<BsdfSample> layered_sample(const Material& m, Vec3 wo, float uc, Vec2 u,
                                         TransportMode mode, BsdfPart part) {
  return layered_sample(layer_of(m, part), wo, uc, u, mode);
}

}  // namespace bpm
