// Materials (pbrt-v4's, plus bpm's "phong") with their spectral and float parameters.
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>

#include "materials/layered.h"
#include "scene/flatten_internal.h"
#include "scene/spectra.h"

namespace bpm::flatten_internal {

namespace fs = std::filesystem;

// A spectral material parameter: a constant (a constant texture included) or a texture node.
std::optional<SpectrumParam> Flattener::spectrum_param(const ParamSet& ps, const std::string& name,
                                                       SpectrumKind kind) {
  const Param* p = ps.find_any(name);
  if (p && p->type == "texture") {
    const TextureEntity& t = texture_entity(*p);
    if (t.name == "constant" && t.value_type == "float") {
      float v = t.params.get_float("value", 1);
      if (v < 0 || (kind == SpectrumKind::kAlbedo && v > 1))
        throw Error(t.loc, "constant texture \"" + t.texture_name +
                               "\" used as a reflectance must lie in [0, 1]");
      return SpectrumParam(SpectrumCurve(v));
    }
    if (t.name == "constant") {
      auto v = spectrum_curve(t.params, "value", kind);
      return SpectrumParam(v ? *v : SpectrumCurve(1.0f));
    }
    SpectrumParam sp;
    sp.texture = texture_node(t, false, kind);
    return sp;
  }
  if (auto c = spectrum_curve(ps, name, kind)) return SpectrumParam(*c);
  return std::nullopt;
}
// A float material parameter that must not vary over the surface (a constant texture is fine).
float Flattener::float_param(const ParamSet& ps, const std::string& name, float def) {
  const Param* p = ps.find_any(name);
  if (p && p->type == "texture") {
    const TextureEntity& t = texture_entity(*p);
    if (t.name != "constant" || t.value_type != "float")
      throw Error(p->loc, "\"" + name + "\" must be a float or a constant float texture; \"" +
                              p->strings[0] + "\" is not");
    return t.params.get_float("value", 1);
  }
  return ps.get_float(name, def);
}
// A float parameter that may vary: its constant, or the node of a non-constant float texture.
FloatParam Flattener::float_or_texture(const ParamSet& ps, const std::string& name, float def) {
  const Param* p = ps.find_any(name);
  if (p && p->type == "texture") {
    const TextureEntity& t = texture_entity(*p);
    if (!(t.name == "constant" && t.value_type == "float"))
      return FloatParam{0, texture_node(t, true, SpectrumKind::kAlbedo)};
  }
  return FloatParam{float_param(ps, name, def), -1};
}

// prefix: "" for most materials, "interface." or "conductor." for coatedconductor's two layers.
// Textured roughness goes to tex; a material that takes none passes null.
Roughness Flattener::roughness(const ParamSet& ps, const FileLoc& loc, const std::string& prefix,
                               RoughnessTextures* tex) {
  FloatParam r = float_or_texture(ps, prefix + "roughness", 0);
  FloatParam u =
      ps.find_any(prefix + "uroughness") ? float_or_texture(ps, prefix + "uroughness", 0) : r;
  FloatParam v =
      ps.find_any(prefix + "vroughness") ? float_or_texture(ps, prefix + "vroughness", 0) : r;
  bool remap = ps.get_bool("remaproughness", true);
  if (u.textured() || v.textured()) {
    if (!tex) throw Error(loc, "textured roughness is not supported for this material");
    tex->u = u.texture;
    tex->v = v.texture;
    tex->remap = remap;
  }
  if (u.value < 0 || v.value < 0) throw Error(loc, "roughness must not be negative");
  if (remap) {
    u.value = std::sqrt(u.value);  // pbrt-v4 TrowbridgeReitzDistribution::RoughnessToAlpha
    v.value = std::sqrt(v.value);
  }
  return Roughness{u.value, v.value};
}

// A dielectric's index of refraction: a float, or a spectrum reduced to its value at 550 nm.
Flattener::DielectricEta Flattener::dielectric_eta(const ParamSet& ps, const FileLoc& loc,
                                                   const std::string& name) {
  DielectricEta out;
  const Param* p = ps.find_any(name);
  if (p && p->type == "texture")
    throw Error(p->loc, "\"" + name +
                            "\" takes a value or a spectrum, not a texture (as in pbrt-v4, whose "
                            "dielectrics and coats have no textured index)");
  if (p && p->type == "float") {
    out.eta = ps.get_float(name, 1.5f);
  } else if (p) {
    SpectrumParam sp = *spectrum_param(ps, name, SpectrumKind::kUnbounded);
    const SpectrumCurve& s = sp.curve;
    // The index at the d line (587.56 nm) stands for the glass where one index is needed.
    out.eta = s.value(587.56f);
    if (s.max_value() - s.min_value() > 1e-4f) {
      if (!(s.min_value() > 0)) throw Error(p->loc, "eta must be positive at every wavelength");
      out.spectrum = std::make_shared<const SpectrumCurve>(s);
    }
  }
  if (!(out.eta > 0)) throw Error(p ? p->loc : loc, "eta must be positive");
  return out;
}

// A conductor from eta and k (copper by default) or from a reflectance; prefix names the
// parameters ("conductor." inside coatedconductor).
ConductorDesc Flattener::conductor_desc(const ParamSet& ps, const FileLoc& loc,
                                        const std::string& prefix) {
  ConductorDesc c;
  // pbrt-v4's coatedconductor calls the base's reflectance plain "reflectance".
  if (auto r = spectrum_param(ps, "reflectance", SpectrumKind::kAlbedo)) {
    c.reflectance = *r;
    if (ps.find_any(prefix + "eta") || ps.find_any(prefix + "k"))
      throw Error(loc, "conductor has both reflectance and eta/k");
  } else {
    c.eta = spectrum_param(ps, prefix + "eta", SpectrumKind::kUnbounded)
                .value_or(SpectrumParam(*named_spectrum("metal-Cu-eta", SpectrumKind::kUnbounded)));
    c.k = spectrum_param(ps, prefix + "k", SpectrumKind::kUnbounded)
              .value_or(SpectrumParam(*named_spectrum("metal-Cu-k", SpectrumKind::kUnbounded)));
  }
  c.roughness = roughness(ps, loc, prefix, &c.roughness_tex);
  return c;
}

// The coat of pbrt-v4's coated materials; prefix names the coat's roughness and eta
// ("interface." in coatedconductor). A scattering medium inside the layer (albedo > 0) is not
// modelled.
std::shared_ptr<const CoatWalkTable> Flattener::coat_walk_table(const CoatLayer& layer) {
  for (const auto& t : coat_walk_tables_)
    if (t->made_for(layer)) return t;
  auto t = make_coat_walk_table(layer);
  if (t) coat_walk_tables_.push_back(t);
  return t;
}

CoatLayer Flattener::coat_layer(const ParamSet& ps, const SceneEntity& e, const std::string& prefix,
                                SpectrumParam* albedo, RoughnessTextures* tex) {
  CoatLayer c;
  c.roughness = roughness(ps, e.loc, prefix, tex);
  DielectricEta eta = dielectric_eta(ps, e.loc, prefix + "eta");
  if (eta.spectrum)
    warning(
        ps.find_any(prefix + "eta")->loc,
        "a coat's wavelength-dependent eta is reduced to its value at 587.56 nm (no dispersion)");
  c.eta = eta.eta;
  c.thickness = float_param(ps, "thickness", 0.01f);
  if (!(c.thickness > 0) || !std::isfinite(c.thickness))
    throw Error(ps.find_any("thickness")->loc, "thickness must be positive");
  auto count = [&](const char* name, int def) {
    int v = ps.get_int(name, def);
    if (v < 1 || v > 1000)
      throw Error(ps.find_any(name)->loc, std::string(name) + " must be in [1, 1000]");
    return v;
  };
  c.max_depth = count("maxdepth", 10);
  c.samples = count("nsamples", 1);
  // The medium between coat and base: its albedo (a spectrum or texture) and phase asymmetry.
  if (auto a = spectrum_param(ps, "albedo", SpectrumKind::kAlbedo)) *albedo = *a;
  c.g = float_param(ps, "g", 0);
  if (!(std::fabs(c.g) < 1)) throw Error(ps.find_any("g")->loc, "g must lie in (-1, 1)");
  return c;
}

// A material's bump ("displacement", a float texture) or normal map ("normalmap", an image read
// with linear encoding, as pbrt-v4 reads it).
Bump Flattener::make_bump(const SceneEntity& e) {
  const ParamSet& ps = e.params;
  Bump b;
  if (ps.find_any("displacement")) b.displacement = float_or_texture(ps, "displacement", 0);
  if (const Param* p = ps.find_any("normalmap")) {
    const std::string file = ps.get_string("normalmap", "");
    if (file.empty()) throw Error(p->loc, "\"normalmap\" must name an image file");
    const fs::path path =
        fs::path(file).is_absolute() ? fs::path(file) : fs::path(parsed_.base_directory) / file;
    read_data_file(path.string());
    TexEncoding linear;
    linear.kind = TexEncoding::Kind::kLinear;
    try {
      b.normal_map = load_texture_image(path.string(), linear, false);  // directions, not colours
    } catch (const Error& err) {
      throw Error(p->loc, std::string("normalmap: ") + err.what());
    }
    if (b.normal_map->channels < 3)
      throw Error(p->loc, "normalmap \"" + file + "\" has " +
                              std::to_string(b.normal_map->channels) +
                              " channel; a normal map needs R, G and B");
  }
  return b;
}

// Adds a material and its bump to the render scene; returns its index.
int Flattener::add_material(const SceneEntity& e) {
  Bump bump = make_bump(e);  // first: make_material warns of the parameters nothing read
  MaterialDesc made = make_material(e);
  if (auto* mix = std::get_if<MixDesc>(&made))
    for (int part : mix->materials)
      if (size_t(part) < scene().bumps.size() && scene().bumps[size_t(part)].active())
        throw Error(e.loc, "a bump or normal map on a material inside a mix is not supported");
  scene().materials.push_back(std::move(made));
  const size_t index = scene().materials.size() - 1;
  if (bump.active()) {
    scene().bumps.resize(index + 1);
    scene().bumps[index] = std::move(bump);
  }
  return int(index);
}

MaterialDesc Flattener::make_material(const SceneEntity& e) {
  const ParamSet& ps = e.params;
  MaterialDesc m;
  if (e.name == "diffuse") {
    DiffuseDesc d;
    if (auto r = spectrum_param(ps, "reflectance", SpectrumKind::kAlbedo)) d.reflectance = *r;
    m = d;
  } else if (e.name == "conductor") {
    m = conductor_desc(ps, e.loc, "");
  } else if (e.name == "dielectric" || e.name == "thindielectric") {
    DielectricEta eta = dielectric_eta(ps, e.loc);
    if (e.name == "dielectric") {
      DielectricMaterial d{eta.eta, {}, eta.spectrum, {}};
      d.roughness = roughness(ps, e.loc, "", &d.roughness_tex);
      m = d;
    } else {
      m = ThinDielectricMaterial{eta.eta, eta.spectrum};
    }
  } else if (e.name == "diffusetransmission") {
    DiffuseTransmissionDesc d;
    if (auto r = spectrum_param(ps, "reflectance", SpectrumKind::kAlbedo)) d.reflectance = *r;
    if (auto t = spectrum_param(ps, "transmittance", SpectrumKind::kAlbedo)) d.transmittance = *t;
    float s = ps.get_float("scale", 1);
    if (d.reflectance.textured() || d.transmittance.textured()) {
      if (s != 1)
        throw Error(ps.find_any("scale")->loc,
                    "diffusetransmission scale with textures is not supported");
    } else {
      d.reflectance.curve = d.reflectance.curve.scaled(s);
      d.transmittance.curve = d.transmittance.curve.scaled(s);
      if ((d.reflectance.curve.rgb() + d.transmittance.curve.rgb()).max_component() > 1.0001f)
        throw Error(e.loc, "diffusetransmission reflectance + transmittance exceeds 1");
    }
    m = d;
  } else if (e.name == "coateddiffuse") {
    CoatedDiffuseDesc c;
    if (auto r = spectrum_param(ps, "reflectance", SpectrumKind::kAlbedo)) c.reflectance = *r;
    c.layer = coat_layer(ps, e, "", &c.albedo, &c.roughness_tex);
    // The walks' table is for a constant coat over no medium.
    if (!c.roughness_tex.any() && !c.albedo.textured() && c.albedo.curve.is_black())
      c.walk_table = coat_walk_table(c.layer);
    m = c;
  } else if (e.name == "coatedconductor") {
    CoatedConductorDesc c;
    c.layer = coat_layer(ps, e, "interface.", &c.albedo, &c.roughness_tex);
    c.conductor = conductor_desc(ps, e.loc, "conductor.");
    m = c;
  } else if (e.name == "phong") {
    // bpm's own non-reciprocal glossy lobe (material.h); pbrt-v4 does not know it.
    PhongDesc ph;
    if (auto r = spectrum_param(ps, "reflectance", SpectrumKind::kAlbedo)) ph.reflectance = *r;
    if (const Param* p = ps.find_any("exponent")) {
      ph.exponent = ps.get_float("exponent", 20);
      if (!(ph.exponent >= 0 && ph.exponent <= 1e5f))
        throw Error(p->loc, "phong exponent must be in [0, 1e5]");
    }
    m = ph;
  } else if (e.name == "mix") {
    MixDesc mix;
    const Param* names = ps.find("materials", "string");
    if (!names || names->strings.size() != 2)
      throw Error(names ? names->loc : e.loc,
                  "mix needs \"string materials\" with two named materials");
    names->used = true;
    for (int i = 0; i < 2; ++i)
      mix.materials[i] = material_id(MaterialRef{-1, names->strings[size_t(i)], names->loc});
    mix.amount = float_or_texture(ps, "amount", 0.5f);
    m = mix;
  } else if (e.name == "interface" || e.name == "" || e.name == "none") {
    m = InterfaceMaterial{};
  } else {
    throw Error(e.loc, "material \"" + e.name + "\" is not supported");
  }
  if (const Param* type = ps.find_any("type")) type->used = true;  // MakeNamedMaterial's own
  ps.warn_unused("material \"" + e.name + "\"");
  return m;
}

// The index of a material in the render scene, made on first use; 0 (the default material) when
// the shape names none.
int Flattener::material_id(const MaterialRef& ref) {
  if (!ref.named.empty()) {
    auto it = named_material_ids_.find(ref.named);
    if (it != named_material_ids_.end()) return it->second;
    auto e = parsed_.named_materials.find(ref.named);
    if (e == parsed_.named_materials.end())
      throw Error(ref.loc, "unknown named material \"" + ref.named + "\"");
    if (!building_materials_.insert(ref.named).second)
      throw Error(ref.loc, "named material \"" + ref.named + "\" contains itself (through mix)");
    const int id = add_material(e->second);
    building_materials_.erase(ref.named);
    return named_material_ids_[ref.named] = id;
  }
  if (ref.index < 0) return 0;
  auto it = anonymous_material_ids_.find(ref.index);
  if (it != anonymous_material_ids_.end()) return it->second;
  return anonymous_material_ids_[ref.index] = add_material(parsed_.materials[ref.index]);
}

}  // namespace bpm::flatten_internal
