#include <algorithm>
#include <cmath>

#include "materials/material.h"

namespace bpm {

Material resolve_material(const MaterialDesc& desc, const Wavelengths& wl) {
  struct V {
    const Wavelengths& wl;
    Material operator()(const DiffuseDesc& d) const { return DiffuseMaterial{d.reflectance.sample(wl)}; }
    Material operator()(const ConductorDesc& d) const {
      ConductorMaterial c;
      c.roughness = d.roughness;
      if (d.reflectance) {
        // pbrt-v4's ConductorMaterial: k = 2 sqrt(r) / sqrt(1 - r) with eta = 1 gives reflectance r
        // at normal incidence.
        Spectrum r = d.reflectance->sample(wl);
        c.eta = Spectrum(1.0f);
        for (int i = 0; i < Spectrum::kChannels; ++i) {
          float rr = std::clamp(r[i], 0.0f, 0.9999f);
          c.k[i] = 2 * std::sqrt(rr) / std::sqrt(1 - rr);
        }
      } else {
        c.eta = d.eta.sample(wl);
        c.k = d.k.sample(wl);
      }
      return c;
    }
    Material operator()(const DielectricMaterial& d) const { return d; }
    Material operator()(const ThinDielectricMaterial& d) const { return d; }
    Material operator()(const DiffuseTransmissionDesc& d) const {
      return DiffuseTransmissionMaterial{d.reflectance.sample(wl), d.transmittance.sample(wl)};
    }
    Material operator()(const PhongDesc& d) const { return PhongMaterial{d.reflectance.sample(wl), d.exponent}; }
    Material operator()(const InterfaceMaterial& d) const { return d; }
    Material operator()(const CoatedConductorDesc& d) const {
      return CoatedConductorMaterial{std::get<ConductorMaterial>((*this)(d.conductor)), d.layer};
    }
    Material operator()(const CoatedDiffuseDesc& d) const {
      return CoatedDiffuseMaterial{d.reflectance.sample(wl), d.layer};
    }
  };
  return std::visit(V{wl}, desc);
}

}  // namespace bpm
