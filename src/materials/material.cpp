#include "materials/material.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bpm {

namespace {

struct Resolver {
  const Wavelengths& wl;
  const TextureSet* ts;  // null when the material has no textures
  const TextureContext* ctx;

  Spectrum eval(const SpectrumParam& p) const {
    return p.textured() ? ts->spectrum(p.texture, *ctx, wl) : p.curve.sample(wl);
  }
  Roughness rough(const Roughness& r, const RoughnessTextures& t) const {
    return t.any() ? t.eval(r, *ts, *ctx) : r;
  }
  Material operator()(const DiffuseDesc& d) const { return DiffuseMaterial{eval(d.reflectance)}; }
  Material operator()(const ConductorDesc& d) const {
    ConductorMaterial c;
    c.roughness = rough(d.roughness, d.roughness_tex);
    if (d.reflectance) {
      // pbrt-v4's ConductorMaterial: k = 2 sqrt(r) / sqrt(1 - r) with eta = 1 gives reflectance r
      // at normal incidence.
      Spectrum r = eval(*d.reflectance);
      c.eta = Spectrum(1.0f);
      for (int i = 0; i < Spectrum::kChannels; ++i) {
        float rr = std::clamp(r[i], 0.0f, 0.9999f);
        c.k[i] = 2 * std::sqrt(rr) / std::sqrt(1 - rr);
      }
    } else {
      c.eta = eval(d.eta);
      c.k = eval(d.k);
    }
    return c;
  }
  Material operator()(const DielectricMaterial& d) const {
    DielectricMaterial r = d;
    if (d.eta_spectrum) r.eta = d.eta_spectrum->value(wl.lambda[0]);
    r.roughness = rough(d.roughness, d.roughness_tex);
    return r;
  }
  Material operator()(const ThinDielectricMaterial& d) const {
    ThinDielectricMaterial r = d;
    if (d.eta_spectrum) r.eta = d.eta_spectrum->value(wl.lambda[0]);
    return r;
  }
  Material operator()(const DiffuseTransmissionDesc& d) const {
    return DiffuseTransmissionMaterial{eval(d.reflectance), eval(d.transmittance)};
  }
  Material operator()(const PhongDesc& d) const {
    return PhongMaterial{eval(d.reflectance), d.exponent};
  }
  Material operator()(const InterfaceMaterial& d) const { return d; }
  Material operator()(const CoatedConductorDesc& d) const {
    CoatLayer layer = d.layer;
    layer.roughness = rough(d.layer.roughness, d.roughness_tex);
    layer.albedo = eval(d.albedo);
    return CoatedConductorMaterial{std::get<ConductorMaterial>((*this)(d.conductor)), layer};
  }
  Material operator()(const MixDesc&) const {
    // A mix names other materials: material_at chooses one before resolving.
    throw std::logic_error("resolve_material: a mix material must be chosen by material_at");
  }
  Material operator()(const CoatedDiffuseDesc& d) const {
    CoatLayer layer = d.layer;
    layer.roughness = rough(d.layer.roughness, d.roughness_tex);
    layer.albedo = eval(d.albedo);
    return CoatedDiffuseMaterial{eval(d.reflectance), layer, d.walk_table.get()};
  }
};

}  // namespace

Roughness RoughnessTextures::eval(const Roughness& constant, const TextureSet& ts,
                                  const TextureContext& ctx) const {
  auto alpha = [&](int tex, float fallback) {
    if (tex < 0) return fallback;
    float r = std::max(0.0f, ts.value(tex, ctx));
    return remap ? std::sqrt(r) : r;
  };
  return Roughness{alpha(u, constant.alpha_x), alpha(v, constant.alpha_y)};
}

Material resolve_material(const MaterialDesc& desc, const Wavelengths& wl) {
  return std::visit(Resolver{wl, nullptr, nullptr}, desc);
}

Material resolve_material(const MaterialDesc& desc, const Wavelengths& wl,
                          const TextureSet& textures, const TextureContext& ctx) {
  return std::visit(Resolver{wl, &textures, &ctx}, desc);
}

bool material_is_textured(const MaterialDesc& desc) {
  struct V {
    bool operator()(const DiffuseDesc& d) const { return d.reflectance.textured(); }
    bool operator()(const ConductorDesc& d) const {
      return d.eta.textured() || d.k.textured() || (d.reflectance && d.reflectance->textured()) ||
             d.roughness_tex.any();
    }
    bool operator()(const DiffuseTransmissionDesc& d) const {
      return d.reflectance.textured() || d.transmittance.textured();
    }
    bool operator()(const PhongDesc& d) const { return d.reflectance.textured(); }
    bool operator()(const CoatedDiffuseDesc& d) const {
      return d.reflectance.textured() || d.roughness_tex.any() || d.albedo.textured();
    }
    bool operator()(const CoatedConductorDesc& d) const {
      return (*this)(d.conductor) || d.roughness_tex.any() || d.albedo.textured();
    }
    bool operator()(const DielectricMaterial& d) const { return d.roughness_tex.any(); }
    bool operator()(const ThinDielectricMaterial&) const { return false; }
    bool operator()(const InterfaceMaterial&) const { return false; }
    bool operator()(const MixDesc&) const { return true; }
  };
  return std::visit(V{}, desc);
}

bool material_is_dispersive(const Material& m) {
  if (const auto* d = std::get_if<DielectricMaterial>(&m)) return d->eta_spectrum != nullptr;
  if (const auto* t = std::get_if<ThinDielectricMaterial>(&m)) return t->eta_spectrum != nullptr;
  return false;
}

}  // namespace bpm
