// Materials as a closed set (std::variant) of plain parameter structs, and the BSDF functions
// that evaluate and sample them in the local shading frame (z = shading normal).
//
// Conventions (as pbrt-v4): wo and wi point away from the surface; f() includes no cosine;
// sample() returns f, wi, and pdf_solid_angle; `mode` says whether radiance (camera paths) or
// importance (light paths) flows, which matters for refraction (eta^2 scaling, Veach 1997 5.2).
#pragma once
#include <memory>
#include <optional>
#include <variant>

#include "base/color.h"
#include "base/spectrum.h"
#include "base/vec.h"
#include "textures/texture.h"

namespace bpm {

enum class TransportMode { kRadiance, kImportance };

struct DiffuseMaterial {
  Spectrum reflectance{0.5f};
};

// Trowbridge-Reitz (GGX) roughness; below kSmoothAlpha the lobe is treated as a delta lobe.
struct Roughness {
  float alpha_x = 0, alpha_y = 0;
  bool effectively_smooth() const;
  // Sharp enough that the photon methods trace the lobe rather than gather it (BsdfPart).
  bool traced() const;
};

// The photon methods' split of a material's lobes (DESIGN.md's vocabulary): delta lobes, and
// glossy ones whose roughness alpha is at most kTracedAlpha, are *traced*: paths go on through
// them as through specular vertices (a photon's estimate would be all noise: f peaks at about
// 1 / (pi alpha^2)). The others are *gathered*: a diffuse vertex. A material may have both (a
// smooth or sharp coating over a diffuse or rough base); functions that take a part see its lobes
// only.
enum class BsdfPart : unsigned char { kAll, kGathered, kTraced };
constexpr float kTracedAlpha = 0.1f;

struct ConductorMaterial {
  Spectrum eta{1.0f}, k{0.0f};  // complex index of refraction per channel
  Roughness roughness;
};

// Textured roughness: float textures for u and v (-1: the constant), remapped as pbrt-v4's
// RoughnessToAlpha when remap is set.
struct RoughnessTextures {
  int u = -1, v = -1;
  bool remap = true;
  bool any() const { return u >= 0 || v >= 0; }
  Roughness eval(const Roughness& constant, const TextureSet& ts, const TextureContext& ctx) const;
};

// A dielectric whose index depends on the wavelength (dispersion) keeps its curve; resolved at a
// path's wavelengths, eta is the index at the first (hero) wavelength, and the path follows that
// wavelength alone from there on (pbrt-v4's TerminateSecondary; see PathState).
using EtaSpectrum = std::shared_ptr<const SpectrumCurve>;

struct DielectricMaterial {
  float eta = 1.5f;  // inside over outside; the outside is the side the normal points to
  Roughness roughness;
  EtaSpectrum eta_spectrum;         // null: eta at every wavelength
  RoughnessTextures roughness_tex;  // textured roughness, resolved per surface point
};

struct ThinDielectricMaterial {
  float eta = 1.5f;
  EtaSpectrum eta_spectrum;  // null: eta at every wavelength
};

struct DiffuseTransmissionMaterial {
  Spectrum reflectance{0.25f}, transmittance{0.25f};
};

// A glossy lobe that is not reciprocal (bpm's own "phong", not a pbrt-v4 material): light arriving
// from w_l leaves toward w_v with
//   f(w_l -> w_v) = R (n + 1) / (2 pi) cos^n(angle(w_v, reflect(w_l))) / |cos theta_v|,
// so that for every incident direction the scattered power is R times the part of the lobe above
// the horizon (normalised per incident direction, as measured BSDFs are). Swapping the directions
// changes the value (the 1/cos follows the outgoing direction), so f(wo, wi) != f(wi, wo): the
// case the paper's Helmholtz compensation (section 2) is for. Sampling draws the lobe about the
// mirror direction, which is exact for light transport; camera paths carry the ratio of the two
// BSDF values, |cos theta_i| / |cos theta_o|, as their compensation.
struct PhongMaterial {
  Spectrum reflectance{0.5f};
  float exponent = 20;
};

// The coat of pbrt-v4's layered materials: a dielectric boundary (index eta, GGX roughness) over a
// base, with a layer of the given thickness between them that attenuates as exp(-thickness / |cos|)
// and, with an albedo, scatters (a Henyey-Greenstein medium of unit extinction per unit of
// thickness). Light bounces inside the layer; the BSDF is the expected value of those
// random walks (pbrt-v4's stochastic LayeredBxDF, two-sided, at most max_depth bounces, `samples`
// walks per value): f and pdf are estimates seeded by the directions (materials/layered.h).
struct CoatLayer {
  Roughness roughness;
  float eta = 1.5f, thickness = 0.01f;
  int max_depth = 10, samples = 1;
  // The medium between coat and base (pbrt-v4's "albedo" and "g"): unit extinction per unit of
  // thickness, this single-scattering albedo (black: no scattering, only attenuation) and a
  // Henyey-Greenstein phase function of asymmetry g.
  Spectrum albedo{0.0f};
  float g = 0;
};

struct CoatWalkTable;  // materials/layered.h

// pbrt-v4's "coateddiffuse": the coat over a Lambertian base.
struct CoatedDiffuseMaterial {
  Spectrum reflectance{0.5f};
  CoatLayer layer;
  // The walks' expectation for this coat (owned by the scene's description), or null: f is then
  // the stochastic walk's estimate.
  const CoatWalkTable* walk_table = nullptr;
};

// pbrt-v4's "coatedconductor": the coat over a conductor base (smooth or rough).
struct CoatedConductorMaterial {
  ConductorMaterial conductor;
  CoatLayer layer;
};

// Marks a boundary that does not scatter (pbrt-v4 "interface"): rays pass straight through.
struct InterfaceMaterial {};

using Material = std::variant<DiffuseMaterial, ConductorMaterial, DielectricMaterial,
                              ThinDielectricMaterial, DiffuseTransmissionMaterial, PhongMaterial,
                              InterfaceMaterial, CoatedDiffuseMaterial, CoatedConductorMaterial>;

// The scene's description of a material, with its colours as spectral curves or textures.
// resolve_material evaluates it at a path's wavelengths (and, when textured, at the surface point)
// into the Material the BSDF functions take. The alternatives are in the same order as Material's.

struct DiffuseDesc {
  SpectrumParam reflectance{SpectrumCurve(0.5f)};
};
struct ConductorDesc {
  SpectrumParam eta, k;
  // pbrt-v4's "reflectance" form: eta = 1 and k from the reflectance at each wavelength.
  std::optional<SpectrumParam> reflectance;
  Roughness roughness;
  RoughnessTextures roughness_tex;
};
struct DiffuseTransmissionDesc {
  SpectrumParam reflectance{SpectrumCurve(0.25f)}, transmittance{SpectrumCurve(0.25f)};
};
struct PhongDesc {
  SpectrumParam reflectance{SpectrumCurve(0.5f)};
  float exponent = 20;
};
struct CoatedDiffuseDesc {
  SpectrumParam reflectance{SpectrumCurve(0.5f)};
  CoatLayer layer;
  SpectrumParam albedo{SpectrumCurve(0.0f)};  // the layer's medium (CoatLayer::albedo)
  RoughnessTextures roughness_tex;            // the coat's
  // For the constant coat (make_coat_walk_table); null when the roughness is textured.
  std::shared_ptr<const CoatWalkTable> walk_table;
};
struct CoatedConductorDesc {
  ConductorDesc conductor;
  CoatLayer layer;
  SpectrumParam albedo{SpectrumCurve(0.0f)};  // the layer's medium (CoatLayer::albedo)
  RoughnessTextures roughness_tex;            // the coat's
};
// pbrt-v4's "mix": at each surface point one of two scene materials (indices into the scene's
// list), the second with probability `amount`, chosen by a hash of the point so that every path
// meeting that point sees the same choice. Resolved by material_at (render_scene.h).
struct MixDesc {
  int materials[2] = {0, 0};
  FloatParam amount{0.5f, -1};
};
using MaterialDesc =
    std::variant<DiffuseDesc, ConductorDesc, DielectricMaterial, ThinDielectricMaterial,
                 DiffuseTransmissionDesc, PhongDesc, InterfaceMaterial, CoatedDiffuseDesc,
                 CoatedConductorDesc, MixDesc>;

// A material without textures at the wavelengths.
Material resolve_material(const MaterialDesc& desc, const Wavelengths& wl);
// Any material, at the wavelengths and the surface point.
Material resolve_material(const MaterialDesc& desc, const Wavelengths& wl,
                          const TextureSet& textures, const TextureContext& ctx);
// True when a parameter of the material is a texture, or it is a mix (it must be resolved per
// surface point).
bool material_is_textured(const MaterialDesc& desc);
// True for a dielectric whose index depends on the wavelength.
bool material_is_dispersive(const Material& m);

enum BsdfFlags : unsigned {
  kReflection = 1,
  kTransmission = 2,
  kDiffuse = 4,
  kGlossy = 8,
  kSpecular = 16,
  kTraced = 32,  // a glossy lobe the photon methods trace (BsdfPart); delta lobes are traced too
};

struct BsdfSample {
  Spectrum f;
  Vec3 wi;
  float pdf_solid_angle = 0;
  unsigned flags = 0;
  float eta = 1;  // relative index of refraction across the boundary, 1 for reflection
  // The density to use in multiple importance sampling. It equals pdf_solid_angle except for
  // layered materials, whose sample weight f / pdf is exact while their density is only
  // estimated (pbrt-v4's pdfIsProportional): bsdf_sample fills it. Only camera paths (radiance
  // transport) get the estimate; in importance transport, where nothing weighs light paths'
  // samples, it is pdf_solid_angle.
  float mis_pdf = 0;
  bool is_specular() const { return flags & kSpecular; }
  bool is_traced() const { return flags & (kSpecular | kTraced); }
  bool is_transmission() const { return flags & kTransmission; }
};

// f(wo, wi) of the lobes of `part`; zero for delta lobes.
Spectrum bsdf_f(const Material& m, Vec3 wo, Vec3 wi, TransportMode mode,
                BsdfPart part = BsdfPart::kAll);
// Density with which bsdf_sample returns wi; zero for delta lobes.
float bsdf_pdf(const Material& m, Vec3 wo, Vec3 wi, TransportMode mode,
               BsdfPart part = BsdfPart::kAll);
// uc picks among lobes, u picks the direction. Samples of traced lobes are flagged kTraced (or
// kSpecular). With a part, a sample of the other part's lobes is not returned (its weight is
// still exact for the part: f of the part over the density of drawing it).
std::optional<BsdfSample> bsdf_sample(const Material& m, Vec3 wo, float uc, Vec2 u,
                                      TransportMode mode, BsdfPart part = BsdfPart::kAll);
// All lobes of the material are delta lobes (no use in next-event estimation).
bool bsdf_is_specular(const Material& m);
// Every lobe of the material is traced (BsdfPart): never a gathering vertex.
bool bsdf_all_traced(const Material& m);
// The probability that bsdf_sample of all lobes draws wi at wo through the gathered part
// (BsdfPart): 1 for a material with gathered lobes only, 0 for one whose every lobe is traced; for
// a coated material that splits, the walks' share of the density at wi; -1 where that share is
// not known (a split coat without a walk table). The combined estimators weigh paths by it
// (photons/merge_weights.h).
float bsdf_gathered_probability(const Material& m, Vec3 wo, Vec3 wi, TransportMode mode);
// Whether the lobes of `part` include a glossy one (a microfacet lobe rougher than kTracedAlpha,
// or a rough coat's): there a photon estimate is noisy where f peaks, and bpm combines its merges
// with the eye path's continuation by default (photons/merge_weights.h).
bool bsdf_gathers_glossy(const Material& m, BsdfPart part);
// For a material with both parts, the probability with which the photon methods' eye paths take
// the traced part at wo: the coating's reflectance, but at least 1/4 (highlights come through it);
// 0 for a material with one part only.
float bsdf_traced_part_probability(const Material& m, Vec3 wo);
// Whether the part has lobes that are not delta lobes (next-event estimation has use there).
bool bsdf_part_has_nondelta(const Material& m, BsdfPart part);
// True when the material has a non-delta lobe (a diffuse vertex in DESIGN.md's sense).
inline bool bsdf_has_nonspecular(const Material& m) { return !bsdf_is_specular(m); }

// Fresnel reflectance of a dielectric boundary; cos_i may be negative (ray from inside).
float fresnel_dielectric(float cos_theta_i, float eta);
// Fresnel reflectance of a conductor with complex index eta + i k, per channel.
Spectrum fresnel_complex(float cos_theta_i, const Spectrum& eta, const Spectrum& k);

}  // namespace bpm
