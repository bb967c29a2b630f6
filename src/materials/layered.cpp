#include "materials/layered.h"

#include <tbb/parallel_for.h>

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

constexpr int kGrid = 64;  // points per side of the grids of the coat's 2D integrals

float node_cos(int j) {
  float x = float(j) / (CoatWalkTable::kNodes - 1);
  return x * x;
}

// The table's value at cos_theta: its cell found on the square-root scale of the nodes, linear in
// cos inside it (exact for the values proportional to cos near grazing that a smooth coat has).
float lookup(const std::array<float, CoatWalkTable::kNodes>& t, float cos_theta) {
  const float c = std::clamp(cos_theta, 0.0f, 1.0f);
  const int j =
      std::min(int(std::sqrt(c) * (CoatWalkTable::kNodes - 1)), CoatWalkTable::kNodes - 2);
  const float c0 = node_cos(j), c1 = node_cos(j + 1);
  return t[j] + (t[j + 1] - t[j]) * ((c - c0) / (c1 - c0));
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
  Spectrum albedo;  // of the medium between coat and base (CoatLayer)
  float g;
  bool medium;  // whether the medium scatters; else it only attenuates
  // The walks' expectation, for a Lambertian base under the coat it was made for; else null.
  const CoatWalkTable* walk_table = nullptr;
  // Which lobes to see (BsdfPart): the coating's own reflection (`coat`), the walks under it
  // (`walks`), or both. A material whose coating is not traced, or whose base is traced as well,
  // does not split: it is seen whole.
  bool coat = true, walks = true;
  Layer(const CoatLayer& c, Material base_material, BsdfPart part)
      : top{c.eta, c.roughness, nullptr, {}},
        base(std::move(base_material)),
        thickness(c.thickness),
        max_depth(c.max_depth),
        samples(c.samples),
        albedo(c.albedo),
        g(c.g),
        medium(!c.albedo.is_black()) {
    const bool splits = c.roughness.traced() && !(base.specular || base_traced());
    if (splits && part == BsdfPart::kGathered) coat = false;
    if (splits && part == BsdfPart::kTraced) walks = false;
  }
  bool base_traced() const {
    const auto* c = std::get_if<ConductorMaterial>(&base.m);
    return c && c->roughness.traced();
  }
};

// With a walk table, the probability of drawing the walks' lobe: their share of the coat's own
// draws (enter), kept inside (0, 1) where both lobes are wanted so that neither goes undrawn; all
// draws for the walks' part alone, none for the coat's.
float walks_share(const Layer& L, float cos_o) {
  if (!L.walks) return 0;
  if (!L.coat) return 1;
  return std::clamp(lookup(L.walk_table->enter, cos_o), 1e-3f, 0.999f);
}

// Russian roulette on a walk's weight after its first steps: false ends the walk, else the weight
// is raised by the survival probability.
bool survives_roulette(int depth, Rng& rng, Spectrum& beta) {
  if (depth <= 3 || beta.max_component() >= 0.25f) return true;
  const float q = std::fmax(0.0f, 1 - beta.max_component());
  if (rng.uniform() < q) return false;
  beta /= 1 - q;
  return true;
}

// The walk's next event from height z along w (the coat at the thickness, the base at 0): with a
// scattering medium, where it scatters (a free flight of unit extinction), strictly inside the
// layer, or else the boundary it reaches; without one, the other boundary, with the layer's
// attenuation applied to `weight`.
float next_height(const Layer& L, float z, Vec3 w, Rng& rng, Spectrum& weight) {
  if (L.medium) {
    const float dz = -std::log1p(-rng.uniform()) * std::fabs(w.z);
    const float zp = w.z > 0 ? z + dz : z - dz;
    if (zp > 0 && zp < L.thickness) return zp;
    return zp <= 0 ? 0 : L.thickness;
  }
  weight *= layer_transmittance(L.thickness, w);
  return z == L.thickness ? 0 : L.thickness;
}

// A scattering in the layer's medium at height zp, on the walk of layered_f toward wi (outside)
// whose way out through the coat was presampled (`out`, drawn from wi): next-event estimation
// through the coat along it, then the phase function's sample, which may itself leave through a
// rough coat toward wi; each weighed against the other (power heuristic) where both can find
// the light. Updates the walk's weight beta and direction w, adds to f; false ends the walk.
bool scatter_in_layer(const Layer& L, Vec3 wi, const BsdfSample& out, float zp, TransportMode mode,
                      Rng& rng, Spectrum& beta, Vec3& w, Spectrum& f) {
  const bool top_smooth = L.top.roughness.effectively_smooth();
  const Vec3 to_exit = -out.wi;
  const float up = L.thickness - zp;  // distance to the coat, in height
  const float phase_nee = henyey_greenstein(dot(w, to_exit), L.g);
  const float wt = top_smooth ? 1 : power_heuristic(out.pdf_solid_angle, phase_nee);
  f += beta * L.albedo * out.f *
       (phase_nee * wt * std::exp(-up / std::fabs(out.wi.z)) / out.pdf_solid_angle);
  const Vec3 wn = sample_henyey_greenstein(w, L.g, {rng.uniform(), rng.uniform()});
  if (wn.z == 0) return false;
  const float phase_sampled = henyey_greenstein(dot(w, wn), L.g);
  beta *= L.albedo;  // the phase function over its own density
  w = wn;
  if (!top_smooth && w.z > 0) {
    const Spectrum f_exit = dielectric_f(L.top, -w, wi, mode);
    if (!f_exit.is_black()) {
      // Both densities over the direction leaving the scattering point (as at the base).
      const float wt_exit =
          power_heuristic(phase_sampled, dielectric_pdf(L.top, wi, -w, kTransmission));
      f += beta * f_exit * (std::exp(-up / std::fabs(w.z)) * wt_exit);
    }
  }
  return true;
}

// At the base, on the walk of layered_f toward wi: next-event estimation through the coating
// along the presampled way out (impossible for a mirror base), weighted against reaching it by
// sampling the base (power heuristic) unless the coating is smooth, where only this strategy can
// find it; then the base's sample, which may itself leave through a rough coat toward wi. Updates
// beta and w, adds to f; false ends the walk.
bool reflect_at_base(const Layer& L, Vec3 wi, const BsdfSample& out, TransportMode mode, Rng& rng,
                     Spectrum& beta, Vec3& w, Spectrum& f) {
  const bool top_smooth = L.top.roughness.effectively_smooth();
  const Vec3 wb = -w, to_exit = -out.wi;
  if (!L.base.specular) {
    const float wt =
        top_smooth ? 1 : power_heuristic(out.pdf_solid_angle, L.base.pdf(wb, to_exit, mode));
    f += beta * L.base.f(wb, to_exit, mode) *
         (std::fabs(out.wi.z) * wt * layer_transmittance(L.thickness, out.wi) /
          out.pdf_solid_angle) *
         out.f;
  }
  auto b = L.base.sample(wb, rng, mode);
  if (!usable(b)) return false;
  beta *= b->f * (std::fabs(b->wi.z) / b->pdf_solid_angle);
  w = b->wi;
  if (!top_smooth) {
    const Spectrum f_exit = dielectric_f(L.top, -w, wi, mode);
    if (!f_exit.is_black()) {
      // Both strategies' densities over the same variable, the direction leaving the base: the
      // other strategy would have drawn it by refracting wi into the layer.
      const float wt_exit =
          L.base.specular
              ? 1
              : power_heuristic(b->pdf_solid_angle, dielectric_pdf(L.top, wi, -w, kTransmission));
      f += beta * f_exit * (layer_transmittance(L.thickness, w) * wt_exit);
    }
  }
  return true;
}

Spectrum layered_f(const Layer& L, Vec3 wo, Vec3 wi, TransportMode mode) {
  // Two-sided: seen from below, the material is the same as from above.
  if (wo.z < 0) {
    wo = -wo;
    wi = -wi;
  }
  // The base does not transmit, so light leaves on the side it arrived from.
  if (wo.z == 0 || wi.z <= 0) return {};
  const DielectricMaterial& top = L.top;
  // Reflection off the coating itself (zero for a smooth coating: its mirror lobe is a delta).
  if (L.walk_table) {
    Spectrum f = L.coat ? dielectric_f(top, wo, wi, mode) : Spectrum();
    if (!L.walks) return f;
    const Spectrum& r = std::get<DiffuseMaterial>(L.base.m).reflectance;
    return f + L.walk_table->f(r, wo.z, wi.z);
  }
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
    Vec3 w = in->wi;        // direction of travel inside the layer
    float z = L.thickness;  // height in the layer: the coat at the thickness, the base at 0
    for (int depth = 0; depth < L.max_depth; ++depth) {
      if (!survives_roulette(depth, rng, beta)) break;
      const float zp = next_height(L, z, w, rng, beta);
      if (zp > 0 && zp < L.thickness) {
        if (!scatter_in_layer(L, wi, *out, zp, mode, rng, beta, w, f)) break;
        z = zp;
        continue;
      }
      z = zp;
      if (z == L.thickness) {
        // Reflected back into the layer by the coating, from inside.
        auto r = dielectric_sample(top, -w, rng.uniform(), {rng.uniform(), rng.uniform()}, mode,
                                   kReflection);
        if (!usable(r)) break;
        beta *= r->f * (std::fabs(r->wi.z) / r->pdf_solid_angle);
        w = r->wi;
        continue;
      }
      if (!reflect_at_base(L, wi, *out, mode, rng, beta, w, f)) break;
    }
  }
  return f / float(L.samples);
}

float layered_pdf(const Layer& L, Vec3 wo, Vec3 wi, TransportMode mode) {
  if (wo.z < 0) {
    wo = -wo;
    wi = -wi;
  }
  if (L.walk_table) {
    // layered_sample's mixture, exactly.
    if (wo.z == 0 || wi.z <= 0) return 0;
    const float q = walks_share(L, wo.z);
    const float coat = L.coat ? (1 - q) * dielectric_pdf(L.top, wo, wi, kReflection) : 0;
    return coat + q * cosine_hemisphere_pdf_solid_angle(wi.z);
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

// With a walk table (wo above the material; `flip`: the caller's wo was below): a mixture of the
// two lobes, the walks' (the table's f) with probability q, cosine-distributed, else the coat's
// reflection, drawn as the coat draws it. Every weight is exact for the table's f.
std::optional<BsdfSample> table_sample(const Layer& L, Vec3 wo, float uc, Vec2 u,
                                       TransportMode mode, bool flip) {
  const float q = walks_share(L, wo.z);
  if (uc < q) {
    Vec3 wi = sample_cosine_hemisphere(u);
    if (wi.z <= 0) return std::nullopt;
    const Spectrum f = L.walk_table->f(std::get<DiffuseMaterial>(L.base.m).reflectance, wo.z, wi.z);
    const float pdf = q * cosine_hemisphere_pdf_solid_angle(wi.z);
    if (flip) wi = -wi;
    return BsdfSample{f, wi, pdf, kReflection | kGlossy, 1};
  }
  if (!L.coat) return std::nullopt;
  auto bs = dielectric_sample(L.top, wo, (uc - q) / (1 - q), u, mode, kReflection);
  if (!usable(bs)) return std::nullopt;
  bs->pdf_solid_angle *= 1 - q;
  if (flip) bs->wi = -bs->wi;
  if (L.top.roughness.traced()) bs->flags |= kTraced;
  return bs;
}

std::optional<BsdfSample> layered_sample(const Layer& L, Vec3 wo, float uc, Vec2 u,
                                         TransportMode mode) {
  const bool flip = wo.z < 0;
  if (flip) wo = -wo;
  const DielectricMaterial& top = L.top;
  if (L.walk_table) return table_sample(L, wo, uc, u, mode, flip);
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
  float z = L.thickness;  // the coat at the thickness, the base at 0
  bool specular_path = bs->is_specular();
  for (int depth = 0; depth < L.max_depth; ++depth) {
    float rr = f.max_component() / pdf;
    if (depth > 3 && rr < 0.25f) {
      float q = std::fmax(0.0f, 1 - rr);
      if (rng.uniform() < q) return std::nullopt;
      pdf *= 1 - q;
    }
    if (w.z == 0) return std::nullopt;
    const float zp = next_height(L, z, w, rng, f);
    if (zp > 0 && zp < L.thickness) {
      // Scattered by the medium: the phase function, drawn exactly.
      const Vec3 wn = sample_henyey_greenstein(w, L.g, {rng.uniform(), rng.uniform()});
      if (wn.z == 0) return std::nullopt;
      const float phase = henyey_greenstein(dot(w, wn), L.g);
      f *= L.albedo * phase;
      pdf *= phase;
      specular_path = false;
      w = wn, z = zp;
      continue;
    }
    z = zp;
    std::optional<BsdfSample> t;
    if (z == 0) {
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
  if (auto* d = std::get_if<CoatedDiffuseMaterial>(&m)) {
    Layer l(d->layer, DiffuseMaterial{d->reflectance}, part);
    if (d->walk_table && d->walk_table->made_for(d->layer)) l.walk_table = d->walk_table;
    return l;
  }
  const auto& c = std::get<CoatedConductorMaterial>(m);
  return Layer(c.layer, c.conductor, part);
}

// Point (i, j) of a k x k grid over the unit square, crowded toward x = 1 (x = 1 - (1 - s)^2 for
// cell middles s), and its weight in an integral over the square (the mean of the weights is 1).
// The coat's sampling (microfacet normals by visible area) reaches its steep slopes there.
Vec2 grid_point(int i, int j, int k, float* weight) {
  const float s = (float(i) + 0.5f) / float(k);
  *weight = 2 * (1 - s);
  return {1 - (1 - s) * (1 - s), (float(j) + 0.5f) / float(k)};
}

}  // namespace

Spectrum CoatWalkTable::f(const Spectrum& reflectance, float cos_o, float cos_i) const {
  const float ab = lookup(a, std::fabs(cos_o)) * lookup(b, std::fabs(cos_i));
  Spectrum out;
  for (int c = 0; c < Spectrum::kChannels; ++c) {
    const float r = reflectance[c], x = r * rho;
    float visits_sum = 0;  // 1 + x + ... + x^(visits - 1)
    if (visits > 16 && x < 0.99f) {
      visits_sum = (1 - std::pow(x, float(visits))) / (1 - x);
    } else {
      for (int v = 0; v < visits; ++v) visits_sum = 1 + x * visits_sum;
    }
    out[c] = ab * r * visits_sum;
  }
  return out;
}

namespace {

// The coat a table is made for, as its integrals see it.
struct Coat {
  const DielectricMaterial& top;
  const CoatLayer& layer;
  float d;  // the layer's thickness
  bool smooth;
  TransportMode mode;
};

// One node's sums over the grid: A (a, enter) and B (b) of CoatWalkTable.
struct NodeSums {
  double in = 0, nee = 0, exit = 0, out_usable = 0, enter = 0;
};

// A: into the layer from w, across it to the base (the walk's first steps).
void add_way_in(const Coat& c, const TrowbridgeReitz& distribution, Vec3 w, Vec2 u, float g,
                NodeSums& sums) {
  auto in = dielectric_sample(c.top, w, 0.5f, u, c.mode, kTransmission);
  if (usable(in)) {
    sums.in +=
        g * in->f[0] * std::fabs(in->wi.z) / in->pdf_solid_angle * layer_transmittance(c.d, in->wi);
    // The coat's sample of both lobes takes this way in with probability 1 - Fresnel.
    const float cos_m = c.smooth ? w.z : dot(w, distribution.sample_wm(w, u));
    sums.enter += g * (1 - fresnel_dielectric(cos_m, c.layer.eta));
  }
}

// B, exits by base sampling: a cosine direction up from the base (weight R, outside), through the
// layer and the coat toward w. Its integrand peaks where the coat's refraction does (alpha 0.01:
// a cone of about 0.01 rad), so it is integrated over both the cosine grid and the coat's own
// samples, combined by the balance heuristic (either way the term is p_base g / (p_base +
// p_coat)).
inline double exit_term(const Coat& c, Vec3 w, Vec3 up, float p_coat) {
  const float f_exit = dielectric_f(c.top, -up, w, c.mode)[0];
  if (!(f_exit > 0)) return 0.0;
  const float p_base = up.z * float(kInvPi);
  const float wt = power_heuristic(p_base, dielectric_pdf(c.top, w, -up, kTransmission));
  return double(p_base) * f_exit * layer_transmittance(c.d, up) * wt / (double(p_base) + p_coat);
}

// B: out of the layer toward w, by next-event estimation and (unless the coat is smooth) by exits
// of base sampling.
void add_way_out(const Coat& c, Vec3 w, Vec2 u, float g, NodeSums& sums) {
  // B, next-event estimation: the way out toward w presampled from w (adjoint), the base's
  // f (R / pi, R outside) and the layer on the way; weighted against exits by base sampling
  // unless the coat is smooth.
  auto out = dielectric_sample(c.top, w, 0.5f, u, adjoint(c.mode), kTransmission);
  if (usable(out)) {
    sums.out_usable += g;
    const float cos_b = std::fabs(out->wi.z);
    const float wt = c.smooth ? 1 : power_heuristic(out->pdf_solid_angle, cos_b * float(kInvPi));
    sums.nee += g * kInvPi * cos_b * wt * layer_transmittance(c.d, out->wi) / out->pdf_solid_angle *
                out->f[0];
  }
  if (c.smooth) return;
  const Vec3 up = sample_cosine_hemisphere(u);
  sums.exit += g * exit_term(c, w, up, dielectric_pdf(c.top, w, -up, kTransmission));
  if (usable(out) && out->wi.z < 0)
    sums.exit += g * exit_term(c, w, -out->wi, out->pdf_solid_angle);
}

// Node j of the table (a, enter, b) from a k x k grid of points.
void fill_node(const Coat& c, int k, int j, CoatWalkTable* t) {
  const float cos_w = std::max(node_cos(j), 1e-6f);  // node 0 just above grazing
  const Vec3 w(std::sqrt(std::fmax(0.0f, 1 - cos_w * cos_w)), 0, cos_w);
  NodeSums sums;
  const TrowbridgeReitz distribution(c.top.roughness.alpha_x, c.top.roughness.alpha_y);
  for (int iy = 0; iy < k; ++iy)
    for (int ix = 0; ix < k; ++ix) {
      float g;
      const Vec2 u = grid_point(ix, iy, k, &g);
      add_way_in(c, distribution, w, u, g, sums);
      add_way_out(c, w, u, g, sums);
    }
  const double n = double(k) * k;
  t->a[j] = float(sums.in / n);
  t->enter[j] = float(sums.enter / n);
  // The walk skips a sample whose way out cannot be drawn, exits included.
  t->b[j] = float(sums.nee / n + sums.out_usable / n * sums.exit / n);
}

// rho: from a cosine direction up from the base, across the layer, reflected by the coat from
// inside, back across the layer. Four dimensions (the direction up, the coat's sample): the
// points of the R4 sequence (Kronecker steps by powers of 1 / phi_4, phi_4^5 = phi_4 + 1),
// summed in fixed chunks so that the sum does not depend on the threads.
float coat_rho(const Coat& c) {
  constexpr int kChunks = 64, kChunk = 4096;
  constexpr double kPhi4 = 1.1673039782614187;
  const double step[4] = {1 / kPhi4, 1 / (kPhi4 * kPhi4), 1 / (kPhi4 * kPhi4 * kPhi4),
                          1 / (kPhi4 * kPhi4 * kPhi4 * kPhi4)};
  std::array<double, kChunks> rho_sums{};
  tbb::parallel_for(0, kChunks, [&](int chunk) {
    for (int n = chunk * kChunk; n < (chunk + 1) * kChunk; ++n) {
      float x[4];
      for (int i = 0; i < 4; ++i) {
        double v = 0.5 + step[i] * n;
        x[i] = float(v - std::floor(v));
      }
      const Vec3 up = sample_cosine_hemisphere({x[0], x[1]});
      auto r = dielectric_sample(c.top, -up, 0.5f, {x[2], x[3]}, c.mode, kReflection);
      if (usable(r))
        rho_sums[chunk] += layer_transmittance(c.d, up) * r->f[0] * std::fabs(r->wi.z) /
                           r->pdf_solid_angle * layer_transmittance(c.d, r->wi);
    }
  });
  double rho_sum = 0;
  for (double s : rho_sums) rho_sum += s;
  return float(rho_sum / (double(kChunks) * kChunk));
}

}  // namespace

std::shared_ptr<const CoatWalkTable> make_coat_walk_table(const CoatLayer& layer) {
  if (layer.roughness.alpha_x != layer.roughness.alpha_y) return nullptr;
  auto t = std::make_shared<CoatWalkTable>();
  t->layer = layer;
  t->visits = std::max(0, (layer.max_depth + 1) / 2);
  const DielectricMaterial top{layer.eta, layer.roughness, nullptr, {}};
  const bool smooth = top.roughness.effectively_smooth();
  // Radiance transport. In importance transport the way in loses its 1 / eta^2 and the way out
  // gains it: the product, a reflection's f, is the same.
  const Coat coat{top, layer, layer.thickness, smooth, TransportMode::kRadiance};
  // A smooth coat refracts and reflects deterministically: one point is the integral.
  const int k = smooth ? 1 : kGrid;
  tbb::parallel_for(0, CoatWalkTable::kNodes, [&](int j) { fill_node(coat, k, j, t.get()); });
  t->rho = coat_rho(coat);
  for (int j = 0; j < CoatWalkTable::kNodes; ++j)
    if (!std::isfinite(t->a[j]) || !std::isfinite(t->b[j]) || !std::isfinite(t->enter[j]))
      return nullptr;
  if (!std::isfinite(t->rho)) return nullptr;
  return t;
}

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

float layered_gathered_probability(const Material& m, Vec3 wo, Vec3 wi, TransportMode) {
  const Layer L = layer_of(m, BsdfPart::kAll);
  if (!L.top.roughness.traced() || L.base.specular || L.base_traced()) return 1;  // no split
  if (!L.walk_table) return -1;
  if (wo.z < 0) {
    wo = -wo;
    wi = -wi;
  }
  if (wo.z == 0 || wi.z <= 0) return 0;
  // layered_pdf's mixture (with a walk table, layered_sample's exactly): the walks' share.
  const float q = walks_share(L, wo.z);
  const float walks = q * cosine_hemisphere_pdf_solid_angle(wi.z);
  const float coat = (1 - q) * dielectric_pdf(L.top, wo, wi, kReflection);
  return walks + coat > 0 ? walks / (walks + coat) : 0.0f;
}

}  // namespace bpm
