// Texture nodes: pbrt-v4's "constant", "imagemap", "checkerboard", "scale" and "mix" textures and
// their mappings, each built once and shared by everything that uses it.
#include <exception>
#include <filesystem>
#include <string>
#include <tuple>

#include "scene/flatten_internal.h"
#include "scene/spectra.h"

namespace bpm::flatten_internal {

namespace fs = std::filesystem;

const TextureEntity& Flattener::texture_entity(const Param& ref) {
  ref.used = true;
  if (ref.strings.size() != 1) throw Error(ref.loc, "a texture parameter names one texture");
  auto it = textures_.find(ref.strings[0]);
  if (it == textures_.end()) throw Error(ref.loc, "unknown texture \"" + ref.strings[0] + "\"");
  return *it->second;
}

// The node of a texture, built on first use. Spectrum textures are built once per kind (how
// their image texels are read); float textures once.
int Flattener::texture_node(const TextureEntity& t, bool as_float, SpectrumKind kind) {
  auto key = std::make_tuple(t.texture_name, as_float, as_float ? 0 : int(kind));
  if (auto it = texture_nodes_.find(key); it != texture_nodes_.end()) return it->second;
  if (!building_.insert(t.texture_name).second)
    throw Error(t.loc, "texture \"" + t.texture_name + "\" refers to itself");
  int node = build_texture(t, as_float, kind);
  building_.erase(t.texture_name);
  texture_nodes_[key] = node;
  return node;
}

// A texture's parameter that may itself be a texture: its node, or a constant node.
int Flattener::spectrum_node(const ParamSet& ps, const std::string& name, SpectrumKind kind,
                             float def) {
  const Param* p = ps.find_any(name);
  if (p && p->type == "texture") return texture_node(texture_entity(*p), false, kind);
  if (p && p->type == "float")
    return scene().textures.add(ConstantTexture{SpectrumCurve(ps.get_float(name, def)), 0});
  auto v = spectrum_curve(ps, name, kind);
  return scene().textures.add(ConstantTexture{v.value_or(SpectrumCurve(def)), 0});
}
int Flattener::float_node(const ParamSet& ps, const std::string& name, float def) {
  const Param* p = ps.find_any(name);
  if (p && p->type == "texture")
    return texture_node(texture_entity(*p), true, SpectrumKind::kAlbedo);
  return scene().textures.add(ConstantTexture{SpectrumCurve(), ps.get_float(name, def)});
}

TexMapping Flattener::texture_mapping(const TextureEntity& t) {
  const ParamSet& ps = t.params;
  TexMapping m;
  std::string kind = ps.get_string("mapping", "uv");
  m.texture_from_world = t.world_from_texture.inverse();
  if (kind == "uv") {
    m.kind = TexMapping::Kind::kUV;
    m.su = ps.get_float("uscale", 1);
    m.sv = ps.get_float("vscale", 1);
    m.du = ps.get_float("udelta", 0);
    m.dv = ps.get_float("vdelta", 0);
  } else if (kind == "spherical") {
    m.kind = TexMapping::Kind::kSpherical;
  } else if (kind == "cylindrical") {
    m.kind = TexMapping::Kind::kCylindrical;
  } else if (kind == "planar") {
    m.kind = TexMapping::Kind::kPlanar;
    auto v1 = ps.get_vector3s("v1"), v2 = ps.get_vector3s("v2");
    if (!v1.empty()) m.vs = v1[0];
    if (!v2.empty()) m.vt = v2[0];
    m.ds = ps.get_float("udelta", 0);
    m.dt = ps.get_float("vdelta", 0);
  } else {
    throw Error(ps.find_any("mapping")->loc,
                "texture mapping \"" + kind + "\" is unknown (uv, spherical, cylindrical, planar)");
  }
  return m;
}

int Flattener::build_texture(const TextureEntity& t, bool as_float, SpectrumKind kind) {
  const ParamSet& ps = t.params;
  if (as_float != (t.value_type == "float"))
    throw Error(t.loc, "texture \"" + t.texture_name + "\" is a " + t.value_type + " texture; a " +
                           (as_float ? "float" : "spectrum") + " texture is needed here");
  TextureNode node;
  if (t.name == "constant") {
    ConstantTexture c;
    if (as_float)
      c.value = ps.get_float("value", 1);
    else
      c.spectrum = spectrum_curve(ps, "value", kind).value_or(SpectrumCurve(1.0f));
    node = c;
  } else if (t.name == "imagemap") {
    node = image_texture(t, kind);
  } else if (t.name == "checkerboard") {
    CheckerboardTexture c;
    c.dimension = ps.get_int("dimension", 2);
    if (c.dimension != 2 && c.dimension != 3)
      throw Error(ps.find_any("dimension")->loc, "checkerboard dimension must be 2 or 3");
    ps.get_string("aamode", "closedform");
    if (c.dimension == 2) c.mapping = texture_mapping(t);
    c.texture_from_world = t.world_from_texture.inverse();
    c.tex1 = as_float ? float_node(ps, "tex1", 1) : spectrum_node(ps, "tex1", kind, 1);
    c.tex2 = as_float ? float_node(ps, "tex2", 0) : spectrum_node(ps, "tex2", kind, 0);
    node = c;
  } else if (t.name == "scale") {
    ScaleTexture sc;
    sc.tex = as_float ? float_node(ps, "tex", 1) : spectrum_node(ps, "tex", kind, 1);
    sc.scale = float_node(ps, "scale", 1);
    node = sc;
  } else if (t.name == "mix") {
    MixTexture m;
    m.tex1 = as_float ? float_node(ps, "tex1", 0) : spectrum_node(ps, "tex1", kind, 0);
    m.tex2 = as_float ? float_node(ps, "tex2", 1) : spectrum_node(ps, "tex2", kind, 1);
    m.amount = float_node(ps, "amount", 0.5f);
    node = m;
  } else {
    throw Error(t.loc, "texture class \"" + t.name +
                           "\" is not supported (constant, imagemap, checkerboard, scale, mix)");
  }
  ps.warn_unused("texture \"" + t.texture_name + "\"");
  return scene().textures.add(std::move(node));
}

// An "imagemap" texture: its image, decoded as "encoding" says, and how it is filtered, wrapped
// and mapped.
ImageTexture Flattener::image_texture(const TextureEntity& t, SpectrumKind kind) {
  const ParamSet& ps = t.params;
  ImageTexture im;
  std::string file = ps.get_string("filename", "");
  if (file.empty())
    throw Error(t.loc, "imagemap texture \"" + t.texture_name + "\" has no \"string filename\"");
  fs::path path =
      fs::path(file).is_absolute() ? fs::path(file) : fs::path(parsed_.base_directory) / file;
  read_data_file(path.string());
  TexEncoding enc;
  std::string encoding = ps.get_string("encoding", "sRGB");
  if (encoding == "sRGB") {
    enc.kind = TexEncoding::Kind::kSrgb;
  } else if (encoding == "linear") {
    enc.kind = TexEncoding::Kind::kLinear;
  } else if (encoding.rfind("gamma ", 0) == 0) {
    enc.kind = TexEncoding::Kind::kGamma;
    try {
      enc.gamma = std::stof(encoding.substr(6));
    } catch (const std::exception&) {
      enc.gamma = -1;
    }
    if (!(enc.gamma > 0))
      throw Error(ps.find_any("encoding")->loc, "bad gamma in encoding \"" + encoding + "\"");
  } else {
    throw Error(ps.find_any("encoding")->loc,
                "encoding \"" + encoding + "\" is unknown (sRGB, linear, \"gamma g\")");
  }
  try {
    im.image = load_texture_image(path.string(), enc);
  } catch (const Error& e) {
    throw Error(ps.find_any("filename")->loc, e.what());
  }
  std::string filter = ps.get_string("filter", "bilinear");
  if (filter == "point") {
    im.filter = TexFilter::kPoint;
  } else if (filter == "bilinear" || filter == "trilinear" || filter == "ewa" || filter == "EWA") {
    im.filter = TexFilter::kBilinear;  // without ray differentials, the finest level (texture.h)
  } else {
    throw Error(ps.find_any("filter")->loc,
                "texture filter \"" + filter + "\" is unknown (point, bilinear, trilinear, ewa)");
  }
  ps.get_float("maxanisotropy", 8);
  std::string wrap = ps.get_string("wrap", "repeat");
  if (wrap == "repeat")
    im.wrap = TexWrap::kRepeat;
  else if (wrap == "clamp")
    im.wrap = TexWrap::kClamp;
  else if (wrap == "black")
    im.wrap = TexWrap::kBlack;
  else if (wrap == "octahedralsphere")
    im.wrap = TexWrap::kOctahedralSphere;
  else
    throw Error(ps.find_any("wrap")->loc,
                "wrap mode \"" + wrap + "\" is unknown (repeat, clamp, black, octahedralsphere)");
  im.scale = ps.get_float("scale", 1);
  im.invert = ps.get_bool("invert", false);
  im.kind = kind;
  im.mapping = texture_mapping(t);
  return im;
}

}  // namespace bpm::flatten_internal
