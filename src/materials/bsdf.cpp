#include <complex>

#include "base/sampling.h"
#include "materials/dielectric.h"
#include "materials/layered.h"
#include "materials/material.h"
#include "materials/microfacet.h"

namespace bpm {

// pbrt-v4 treats alpha below 1e-3 as a perfect mirror or smooth boundary.
bool Roughness::effectively_smooth() const { return std::fmax(alpha_x, alpha_y) < 1e-3f; }
bool Roughness::traced() const { return std::fmax(alpha_x, alpha_y) <= kTracedAlpha; }

float fresnel_dielectric(float cos_i, float eta) {
  cos_i = std::clamp(cos_i, -1.0f, 1.0f);
  if (cos_i < 0) {
    eta = 1 / eta;
    cos_i = -cos_i;
  }
  float sin2_i = 1 - cos_i * cos_i;
  float sin2_t = sin2_i / (eta * eta);
  if (sin2_t >= 1) return 1;
  float cos_t = std::sqrt(std::fmax(0.0f, 1 - sin2_t));
  float r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return (r_parl * r_parl + r_perp * r_perp) / 2;
}

Spectrum fresnel_complex(float cos_i, const Spectrum& eta, const Spectrum& k) {
  using C = std::complex<float>;
  cos_i = std::clamp(cos_i, 0.0f, 1.0f);
  Spectrum out;
  for (int c = 0; c < Spectrum::kChannels; ++c) {
    C e(eta[c], k[c]);
    float sin2_i = 1 - cos_i * cos_i;
    C sin2_t = sin2_i / (e * e);
    C cos_t = std::sqrt(C(1) - sin2_t);
    C r_parl = (e * cos_i - cos_t) / (e * cos_i + cos_t);
    C r_perp = (cos_i - e * cos_t) / (cos_i + e * cos_t);
    out[c] = (std::norm(r_parl) + std::norm(r_perp)) / 2;
  }
  return out;
}

namespace {

inline Vec3 reflect(Vec3 wo, Vec3 n) { return -wo + n * (2 * dot(wo, n)); }

// Refraction of wi about n (both pointing away from the surface); eta = inside/outside with the
// outside on n's side. Returns false for total internal reflection.
bool refract(Vec3 wi, Vec3 n, float eta, float* etap, Vec3* wt) {
  float cos_i = dot(n, wi);
  if (cos_i < 0) {
    eta = 1 / eta;
    cos_i = -cos_i;
    n = -n;
  }
  float sin2_i = std::fmax(0.0f, 1 - cos_i * cos_i);
  float sin2_t = sin2_i / (eta * eta);
  if (sin2_t >= 1) return false;
  float cos_t = std::sqrt(1 - sin2_t);
  *wt = -wi / eta + n * (cos_i / eta - cos_t);
  if (etap) *etap = eta;
  return true;
}

// ---- diffuse ----
Spectrum f_of(const DiffuseMaterial& m, Vec3 wo, Vec3 wi, TransportMode) {
  return same_hemisphere(wo, wi) ? m.reflectance * kInvPi : Spectrum();
}
float pdf_of(const DiffuseMaterial&, Vec3 wo, Vec3 wi, TransportMode) {
  return same_hemisphere(wo, wi) ? cosine_hemisphere_pdf_solid_angle(std::fabs(wi.z)) : 0;
}
std::optional<BsdfSample> sample_of(const DiffuseMaterial& m, Vec3 wo, float, Vec2 u,
                                    TransportMode) {
  Vec3 wi = sample_cosine_hemisphere(u);
  if (wo.z < 0) wi.z = -wi.z;
  float pdf = cosine_hemisphere_pdf_solid_angle(std::fabs(wi.z));
  if (pdf == 0) return std::nullopt;
  return BsdfSample{m.reflectance * kInvPi, wi, pdf, kReflection | kDiffuse};
}

// ---- conductor ----
Spectrum f_of(const ConductorMaterial& m, Vec3 wo, Vec3 wi, TransportMode) {
  if (!same_hemisphere(wo, wi) || m.roughness.effectively_smooth()) return {};
  float co = std::fabs(wo.z), ci = std::fabs(wi.z);
  if (co == 0 || ci == 0) return {};
  Vec3 wm = wi + wo;
  if (length_squared(wm) == 0) return {};
  wm = normalize(wm);
  TrowbridgeReitz d(m.roughness.alpha_x, m.roughness.alpha_y);
  Spectrum F = fresnel_complex(absdot(wo, wm), m.eta, m.k);
  return F * (d.d(wm) * d.g(wo, wi) / (4 * co * ci));
}
float pdf_of(const ConductorMaterial& m, Vec3 wo, Vec3 wi, TransportMode) {
  if (!same_hemisphere(wo, wi) || m.roughness.effectively_smooth()) return 0;
  Vec3 wm = wo + wi;
  if (length_squared(wm) == 0) return 0;
  wm = face_forward(normalize(wm), Vec3(0, 0, 1));
  TrowbridgeReitz d(m.roughness.alpha_x, m.roughness.alpha_y);
  return d.d_visible(wo, wm) / (4 * absdot(wo, wm));
}
std::optional<BsdfSample> sample_of(const ConductorMaterial& m, Vec3 wo, float, Vec2 u,
                                    TransportMode) {
  if (m.roughness.effectively_smooth()) {
    Vec3 wi(-wo.x, -wo.y, wo.z);
    float c = std::fabs(wi.z);
    if (c == 0) return std::nullopt;
    return BsdfSample{fresnel_complex(c, m.eta, m.k) / c, wi, 1, kReflection | kSpecular};
  }
  if (wo.z == 0) return std::nullopt;
  TrowbridgeReitz d(m.roughness.alpha_x, m.roughness.alpha_y);
  Vec3 wm = d.sample_wm(wo, u);
  Vec3 wi = reflect(wo, wm);
  if (!same_hemisphere(wo, wi)) return std::nullopt;
  const float d_wm = d.d(wm), lambda_o = d.lambda(wo);
  float pdf = TrowbridgeReitz::d_visible(wo, wm, d_wm, lambda_o) / (4 * absdot(wo, wm));
  float co = std::fabs(wo.z), ci = std::fabs(wi.z);
  if (ci == 0 || pdf == 0) return std::nullopt;
  Spectrum F = fresnel_complex(absdot(wo, wm), m.eta, m.k);
  return BsdfSample{F * (d_wm * d.g(lambda_o, wi) / (4 * co * ci)), wi, pdf, kReflection | kGlossy};
}

// ---- dielectric ----
// Half vector of a generalized (reflection or refraction) pair, or nullopt when degenerate or
// when the microfacet faces away from either direction.
struct HalfVector {
  Vec3 wm;
  float etap;
  bool reflect;
};
std::optional<HalfVector> dielectric_half_vector(float eta, Vec3 wo, Vec3 wi) {
  float co = wo.z, ci = wi.z;
  bool reflect = co * ci > 0;
  float etap = 1;
  if (!reflect) etap = co > 0 ? eta : 1 / eta;
  Vec3 wm = wi * etap + wo;
  if (ci == 0 || co == 0 || length_squared(wm) == 0) return std::nullopt;
  wm = face_forward(normalize(wm), Vec3(0, 0, 1));
  if (dot(wm, wi) * ci < 0 || dot(wm, wo) * co < 0) return std::nullopt;
  return HalfVector{wm, etap, reflect};
}

Spectrum f_of(const DielectricMaterial& m, Vec3 wo, Vec3 wi, TransportMode mode) {
  if (m.eta == 1 || m.roughness.effectively_smooth()) return {};
  auto h = dielectric_half_vector(m.eta, wo, wi);
  if (!h) return {};
  TrowbridgeReitz d(m.roughness.alpha_x, m.roughness.alpha_y);
  float F = fresnel_dielectric(dot(wo, h->wm), m.eta);
  if (h->reflect) return Spectrum(d.d(h->wm) * d.g(wo, wi) * F / std::fabs(4 * wi.z * wo.z));
  float denom = dot(wi, h->wm) + dot(wo, h->wm) / h->etap;
  denom = denom * denom * wi.z * wo.z;
  float ft =
      d.d(h->wm) * (1 - F) * d.g(wo, wi) * std::fabs(dot(wi, h->wm) * dot(wo, h->wm) / denom);
  if (mode == TransportMode::kRadiance) ft /= h->etap * h->etap;
  return Spectrum(ft);
}
}  // namespace

Spectrum dielectric_f(const DielectricMaterial& m, Vec3 wo, Vec3 wi, TransportMode mode) {
  return f_of(m, wo, wi, mode);
}

// With `lobes` restricting the choice, reflection and transmission are picked in proportion to
// the Fresnel terms of the lobes allowed (pbrt-v4's BxDFReflTransFlags).
float dielectric_pdf(const DielectricMaterial& m, Vec3 wo, Vec3 wi, unsigned lobes) {
  if (m.eta == 1 || m.roughness.effectively_smooth()) return 0;
  auto h = dielectric_half_vector(m.eta, wo, wi);
  if (!h) return 0;
  TrowbridgeReitz d(m.roughness.alpha_x, m.roughness.alpha_y);
  float R = fresnel_dielectric(dot(wo, h->wm), m.eta), T = 1 - R;
  float pr = (lobes & kReflection) ? R : 0, pt = (lobes & kTransmission) ? T : 0;
  if (pr + pt == 0) return 0;
  float dvis = d.d_visible(wo, h->wm);  // symmetric in the sign of wo
  if (h->reflect) return dvis / (4 * absdot(wo, h->wm)) * pr / (pr + pt);
  float denom = dot(wi, h->wm) + dot(wo, h->wm) / h->etap;
  float dwm_dwi = absdot(wi, h->wm) / (denom * denom);
  return dvis * dwm_dwi * pt / (pr + pt);
}

std::optional<BsdfSample> dielectric_sample(const DielectricMaterial& m, Vec3 wo, float uc, Vec2 u,
                                            TransportMode mode, unsigned lobes) {
  if (m.eta == 1 || m.roughness.effectively_smooth()) {
    float R = fresnel_dielectric(wo.z, m.eta), T = 1 - R;
    float pr = (lobes & kReflection) ? R : 0, pt = (lobes & kTransmission) ? T : 0;
    if (pr + pt == 0) return std::nullopt;
    if (uc < pr / (pr + pt)) {
      Vec3 wi(-wo.x, -wo.y, wo.z);
      return BsdfSample{Spectrum(R / std::fabs(wi.z)), wi, pr / (pr + pt), kReflection | kSpecular};
    }
    Vec3 wi;
    float etap;
    if (!refract(wo, Vec3(0, 0, 1), m.eta, &etap, &wi) || wi.z == 0) return std::nullopt;
    float ft = T / std::fabs(wi.z);
    if (mode == TransportMode::kRadiance) ft /= etap * etap;
    return BsdfSample{Spectrum(ft), wi, pt / (pr + pt), kTransmission | kSpecular, etap};
  }
  TrowbridgeReitz d(m.roughness.alpha_x, m.roughness.alpha_y);
  // wm lies in the upper hemisphere whichever side wo is on, so that dot(wo, wm) < 0 tells the
  // Fresnel term and refract() that the ray comes from inside.
  Vec3 wm = d.sample_wm(wo, u);
  float R = fresnel_dielectric(dot(wo, wm), m.eta), T = 1 - R;
  float pr = (lobes & kReflection) ? R : 0, pt = (lobes & kTransmission) ? T : 0;
  if (pr + pt == 0) return std::nullopt;
  const float d_wm = d.d(wm), lambda_o = d.lambda(wo);
  float dvis = TrowbridgeReitz::d_visible(wo, wm, d_wm, lambda_o);
  if (uc < pr / (pr + pt)) {
    Vec3 wi = reflect(wo, wm);
    if (!same_hemisphere(wo, wi)) return std::nullopt;
    float pdf = dvis / (4 * absdot(wo, wm)) * pr / (pr + pt);
    Spectrum f(d_wm * d.g(lambda_o, wi) * R / std::fabs(4 * wi.z * wo.z));
    return BsdfSample{f, wi, pdf, kReflection | kGlossy};
  }
  Vec3 wi;
  float etap;
  if (!refract(wo, wm, m.eta, &etap, &wi) || same_hemisphere(wo, wi) || wi.z == 0)
    return std::nullopt;
  float denom = dot(wi, wm) + dot(wo, wm) / etap;
  denom *= denom;
  float dwm_dwi = absdot(wi, wm) / denom;
  float pdf = dvis * dwm_dwi * pt / (pr + pt);
  float ft =
      T * d_wm * d.g(lambda_o, wi) * std::fabs(dot(wi, wm) * dot(wo, wm) / (wi.z * wo.z * denom));
  if (mode == TransportMode::kRadiance) ft /= etap * etap;
  return BsdfSample{Spectrum(ft), wi, pdf, kTransmission | kGlossy, etap};
}

namespace {

float pdf_of(const DielectricMaterial& m, Vec3 wo, Vec3 wi, TransportMode) {
  return dielectric_pdf(m, wo, wi, kReflection | kTransmission);
}
std::optional<BsdfSample> sample_of(const DielectricMaterial& m, Vec3 wo, float uc, Vec2 u,
                                    TransportMode mode) {
  return dielectric_sample(m, wo, uc, u, mode, kReflection | kTransmission);
}

// ---- thin dielectric ----
Spectrum f_of(const ThinDielectricMaterial&, Vec3, Vec3, TransportMode) { return {}; }
float pdf_of(const ThinDielectricMaterial&, Vec3, Vec3, TransportMode) { return 0; }
std::optional<BsdfSample> sample_of(const ThinDielectricMaterial& m, Vec3 wo, float uc, Vec2,
                                    TransportMode) {
  float R = fresnel_dielectric(std::fabs(wo.z), m.eta), T = 1 - R;
  // Sum of the geometric series of inter-reflections inside the slab.
  if (R < 1) {
    R += T * T * R / (1 - R * R);
    T = 1 - R;
  }
  if (wo.z == 0) return std::nullopt;
  if (uc < R / (R + T)) {
    Vec3 wi(-wo.x, -wo.y, wo.z);
    return BsdfSample{Spectrum(R / std::fabs(wi.z)), wi, R / (R + T), kReflection | kSpecular};
  }
  Vec3 wi = -wo;
  return BsdfSample{Spectrum(T / std::fabs(wi.z)), wi, T / (R + T), kTransmission | kSpecular};
}

// ---- diffuse transmission ----
Spectrum f_of(const DiffuseTransmissionMaterial& m, Vec3 wo, Vec3 wi, TransportMode) {
  return (same_hemisphere(wo, wi) ? m.reflectance : m.transmittance) * kInvPi;
}
float pdf_of(const DiffuseTransmissionMaterial& m, Vec3 wo, Vec3 wi, TransportMode) {
  float pr = m.reflectance.max_component(), pt = m.transmittance.max_component();
  if (pr + pt == 0) return 0;
  float c = cosine_hemisphere_pdf_solid_angle(std::fabs(wi.z));
  return (same_hemisphere(wo, wi) ? pr : pt) / (pr + pt) * c;
}
std::optional<BsdfSample> sample_of(const DiffuseTransmissionMaterial& m, Vec3 wo, float uc, Vec2 u,
                                    TransportMode) {
  float pr = m.reflectance.max_component(), pt = m.transmittance.max_component();
  if (pr + pt == 0) return std::nullopt;
  Vec3 wi = sample_cosine_hemisphere(u);
  float c = cosine_hemisphere_pdf_solid_angle(wi.z);
  if (c == 0) return std::nullopt;
  if (uc < pr / (pr + pt)) {
    if (wo.z < 0) wi.z = -wi.z;
    return BsdfSample{m.reflectance * kInvPi, wi, pr / (pr + pt) * c, kReflection | kDiffuse};
  }
  if (wo.z > 0) wi.z = -wi.z;
  return BsdfSample{m.transmittance * kInvPi, wi, pt / (pr + pt) * c, kTransmission | kDiffuse};
}

// ---- phong (not reciprocal; see material.h) ----
// Lobe density about the mirror direction of wo, which is also the sampling pdf.
float phong_lobe(const PhongMaterial& m, Vec3 wo, Vec3 wi) {
  if (!same_hemisphere(wo, wi)) return 0;
  float c = dot(wi, Vec3(-wo.x, -wo.y, wo.z));
  if (c <= 0) return 0;
  return (m.exponent + 1) * (0.5f * kInvPi) * std::pow(c, m.exponent);
}
Spectrum f_of(const PhongMaterial& m, Vec3 wo, Vec3 wi, TransportMode mode) {
  float lobe = phong_lobe(m, wo, wi);
  if (lobe == 0) return {};
  // The physical direction of light flow is wi -> wo for radiance and wo -> wi for importance;
  // the 1/cos belongs to the direction the light leaves in.
  float cos_out = std::fabs(mode == TransportMode::kRadiance ? wo.z : wi.z);
  return m.reflectance * (lobe / cos_out);
}
float pdf_of(const PhongMaterial& m, Vec3 wo, Vec3 wi, TransportMode) {
  return phong_lobe(m, wo, wi);
}
std::optional<BsdfSample> sample_of(const PhongMaterial& m, Vec3 wo, float, Vec2 u,
                                    TransportMode mode) {
  if (wo.z == 0) return std::nullopt;
  // cos^n lobe about the mirror direction (pdf (n+1)/(2 pi) cos^n).
  float cos_a = std::pow(u.x, 1 / (m.exponent + 1));
  float sin_a = std::sqrt(std::fmax(0.0f, 1 - cos_a * cos_a));
  float phi = 2 * kPi * u.y;
  Frame frame = Frame::from_z(Vec3(-wo.x, -wo.y, wo.z));
  Vec3 wi = frame.to_world(Vec3(sin_a * std::cos(phi), sin_a * std::sin(phi), cos_a));
  float pdf = phong_lobe(m, wo, wi);
  if (pdf == 0) return std::nullopt;
  return BsdfSample{f_of(m, wo, wi, mode), wi, pdf, kReflection | kGlossy};
}

// ---- interface: no scattering; the integrators skip such surfaces ----
Spectrum f_of(const InterfaceMaterial&, Vec3, Vec3, TransportMode) { return {}; }
float pdf_of(const InterfaceMaterial&, Vec3, Vec3, TransportMode) { return 0; }
std::optional<BsdfSample> sample_of(const InterfaceMaterial&, Vec3, float, Vec2, TransportMode) {
  return std::nullopt;
}

}  // namespace

// Layered materials take the whole Material (materials/layered.h); the others their own struct.
// A part matters only for layered materials: any other has one part, which callers ask for alone.
Spectrum bsdf_f(const Material& m, Vec3 wo, Vec3 wi, TransportMode mode, BsdfPart part) {
  return std::visit(
      [&](const auto& x) {
        if constexpr (kLayered<std::decay_t<decltype(x)>>)
          return layered_f(m, wo, wi, mode, part);
        else
          return f_of(x, wo, wi, mode);
      },
      m);
}
float bsdf_pdf(const Material& m, Vec3 wo, Vec3 wi, TransportMode mode, BsdfPart part) {
  return std::visit(
      [&](const auto& x) {
        if constexpr (kLayered<std::decay_t<decltype(x)>>)
          return layered_pdf(m, wo, wi, mode, part);
        else
          return pdf_of(x, wo, wi, mode);
      },
      m);
}
std::optional<BsdfSample> bsdf_sample(const Material& m, Vec3 wo, float uc, Vec2 u,
                                      TransportMode mode, BsdfPart part) {
  auto s = std::visit(
      [&](const auto& x) {
        if constexpr (kLayered<std::decay_t<decltype(x)>>)
          return layered_sample(m, wo, uc, u, mode, part);
        else
          return sample_of(x, wo, uc, u, mode);
      },
      m);
  if (s && (s->pdf_solid_angle <= 0 || !s->f.is_finite() || !std::isfinite(s->pdf_solid_angle)))
    return std::nullopt;
  if (s) {
    // A layered material's walk gives an exact weight but no density; MIS takes its estimate.
    // Light paths never weigh their samples (importance transport): they skip the estimate, which
    // costs a few walks of its own.
    bool layered = std::visit([](const auto& x) { return kLayered<std::decay_t<decltype(x)>>; }, m);
    bool estimated = layered && !s->is_specular() && part != BsdfPart::kTraced &&
                     mode == TransportMode::kRadiance;
    s->mis_pdf = estimated ? bsdf_pdf(m, wo, s->wi, mode, part) : s->pdf_solid_angle;
    if (!s->is_specular() && bsdf_all_traced(m)) s->flags |= kTraced;
  }
  return s;
}
namespace {

// Whether every lobe of m is sharp, where sharp(roughness) says it of a microfacet lobe: delta
// lobes (bsdf_is_specular) or traced ones (bsdf_all_traced).
template <class Sharp>
bool all_lobes(const Material& m, Sharp&& sharp) {
  struct V {
    Sharp& sharp;
    bool operator()(const DiffuseMaterial&) const { return false; }
    bool operator()(const ConductorMaterial& c) const { return sharp(c.roughness); }
    bool operator()(const DielectricMaterial& d) const { return d.eta == 1 || sharp(d.roughness); }
    bool operator()(const ThinDielectricMaterial&) const { return true; }
    bool operator()(const DiffuseTransmissionMaterial&) const { return false; }
    bool operator()(const PhongMaterial&) const { return false; }
    bool operator()(const InterfaceMaterial&) const { return true; }
    bool operator()(const CoatedDiffuseMaterial&) const { return false; }
    // A sharp coat over a sharp conductor; otherwise the walk has rough exits.
    bool operator()(const CoatedConductorMaterial& c) const {
      return sharp(c.layer.roughness) && sharp(c.conductor.roughness);
    }
  };
  return std::visit(V{sharp}, m);
}

const CoatLayer* coat_layer(const Material& m) {
  if (const auto* d = std::get_if<CoatedDiffuseMaterial>(&m)) return &d->layer;
  if (const auto* c = std::get_if<CoatedConductorMaterial>(&m)) return &c->layer;
  return nullptr;
}

}  // namespace

bool bsdf_all_traced(const Material& m) {
  return all_lobes(m, [](const Roughness& r) { return r.traced(); });
}

bool bsdf_gathers_glossy(const Material& m, BsdfPart part) {
  if (part == BsdfPart::kTraced) return false;
  struct V {
    bool operator()(const DiffuseMaterial&) const { return false; }
    bool operator()(const ConductorMaterial& c) const { return !c.roughness.traced(); }
    bool operator()(const DielectricMaterial& d) const {
      return d.eta != 1 && !d.roughness.traced();
    }
    bool operator()(const ThinDielectricMaterial&) const { return false; }
    bool operator()(const DiffuseTransmissionMaterial&) const { return false; }
    bool operator()(const PhongMaterial&) const { return true; }
    bool operator()(const InterfaceMaterial&) const { return false; }
    // A traced coat leaves the diffuse walks under it to the gathered part.
    bool operator()(const CoatedDiffuseMaterial& c) const { return !c.layer.roughness.traced(); }
    bool operator()(const CoatedConductorMaterial& c) const {
      return !c.layer.roughness.traced() || !c.conductor.roughness.traced();
    }
  };
  return std::visit(V{}, m);
}

float bsdf_gathered_probability(const Material& m, Vec3 wo, Vec3 wi, TransportMode mode) {
  if (bsdf_all_traced(m)) return 0;
  if (std::holds_alternative<CoatedDiffuseMaterial>(m) ||
      std::holds_alternative<CoatedConductorMaterial>(m))
    return layered_gathered_probability(m, wo, wi, mode);
  return 1;
}

float bsdf_traced_part_probability(const Material& m, Vec3 wo) {
  const CoatLayer* layer = coat_layer(m);
  if (!layer || !layer->roughness.traced() || bsdf_all_traced(m)) return 0;
  return std::fmax(0.25f, fresnel_dielectric(std::fabs(wo.z), layer->eta));
}

bool bsdf_part_has_nondelta(const Material& m, BsdfPart part) {
  if (part == BsdfPart::kGathered) return true;
  if (part == BsdfPart::kTraced)
    if (const CoatLayer* layer = coat_layer(m)) return !layer->roughness.effectively_smooth();
  return !bsdf_is_specular(m);
}

bool bsdf_is_specular(const Material& m) {
  return all_lobes(m, [](const Roughness& r) { return r.effectively_smooth(); });
}

}  // namespace bpm
