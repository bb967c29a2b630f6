#include "scene/flatten.h"
#include "scene/loop_subdivision.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <tuple>

#include "scene/ply.h"
#include "scene/spectra.h"

namespace bpm {
namespace {

namespace fs = std::filesystem;

float radians(float deg) { return deg * kPi / 180; }

class Flattener {
 public:
  explicit Flattener(const ParsedScene& p) : parsed_(p) {
    for (const TextureEntity& t : p.textures) textures_[t.texture_name] = &t;
  }

  LoadedScene run() {
    LoadedScene out;
    read_camera(&out);
    read_film(&out);
    read_filter(&out);
    read_sampler_and_integrator(&out);
    // Default material (pbrt-v4: diffuse, reflectance 0.5) is material 0.
    scene().materials.push_back(DiffuseDesc{});
    for (const ShapeEntity& s : parsed_.shapes) add_shape(s, &out.scene);
    for (const LightEntity& l : parsed_.lights) add_light(l, &out.scene);
    out.scene.commit();
    // Distant and infinite lights needed the scene bounds; nothing more to do after commit.
    return out;
  }

 private:
  const ParsedScene& parsed_;
  std::map<std::string, const TextureEntity*> textures_;
  std::map<std::tuple<std::string, bool, int>, int> texture_nodes_;
  std::set<std::string> building_;
  std::map<int, int> anonymous_material_ids_;
  std::map<std::string, int> named_material_ids_;
  std::map<std::string, int> medium_ids_;
  std::set<std::string> building_materials_;
  RenderScene* scene_ = nullptr;
  RenderScene& scene() { return *scene_; }

  // ---- camera, film, filter, sampler, integrator ----
  void read_camera(LoadedScene* out) {
    scene_ = &out->scene;
    if (!parsed_.camera) {
      out->camera.world_from_camera = Transform();
      return;
    }
    const CameraEntity& c = *parsed_.camera;
    if (!c.medium.outside.empty())
      throw Error(c.medium.loc, "a camera inside a medium (\"" + c.medium.outside + "\") is not supported");
    if (c.name != "perspective")
      throw Error(c.loc, "camera \"" + c.name + "\" is not supported (only perspective)");
    out->camera.world_from_camera = c.camera_from_world.inverse();
    out->camera.fov_degrees = c.params.get_float("fov", 90);
    if (!(out->camera.fov_degrees > 0 && out->camera.fov_degrees < 180))
      throw Error(c.loc, "fov must lie in (0, 180) degrees");
    out->camera.lens_radius = c.params.get_float("lensradius", 0);
    out->camera.focal_distance = c.params.get_float("focaldistance", 1e6f);
    if (out->camera.lens_radius < 0) throw Error(c.loc, "lensradius must not be negative");
    if (!(out->camera.focal_distance > 0)) throw Error(c.loc, "focaldistance must be positive");
    auto sw = c.params.get_floats("screenwindow");
    if (!sw.empty()) {
      if (sw.size() != 4) throw Error(c.params.find_any("screenwindow")->loc, "screenwindow needs 4 values");
      for (int i = 0; i < 4; ++i) out->camera.screen_window[i] = sw[i];
    }
    float open = c.params.get_float("shutteropen", 0), close = c.params.get_float("shutterclose", 1);
    if (close < open) throw Error(c.loc, "shutterclose is before shutteropen");
    out->film.imaging_ratio = close - open;
    c.params.warn_unused("camera");
  }

  void read_film(LoadedScene* out) {
    const SceneEntity& f = parsed_.film;
    if (f.name != "rgb") throw Error(f.loc, "film \"" + f.name + "\" is not supported (only rgb)");
    out->film.width = f.params.get_int("xresolution", 1280);
    out->film.height = f.params.get_int("yresolution", 720);
    if (out->film.width <= 0 || out->film.height <= 0 || out->film.width > 65536 || out->film.height > 65536)
      throw Error(f.loc, "film resolution must be between 1 and 65536 pixels per axis");
    out->film.filename = f.params.get_string("filename", "pbrt.exr");
    float iso = f.params.get_float("iso", 100);
    if (!(iso > 0)) throw Error(f.loc, "iso must be positive");
    out->film.imaging_ratio *= iso / 100;
    std::string sensor = f.params.get_string("sensor", "cie1931");
    if (sensor != "cie1931") throw Error(f.params.find_any("sensor")->loc, "sensor \"" + sensor + "\" is not supported (only cie1931)");
    if (f.params.get_float("whitebalance", 0) != 0)
      throw Error(f.params.find_any("whitebalance")->loc, "white balancing is not supported");
    out->film.max_component_value = f.params.get_float("maxcomponentvalue", kInf);
    if (auto* cw = f.params.find_any("cropwindow")) throw Error(cw->loc, "cropwindow is not supported");
    if (auto* pb = f.params.find_any("pixelbounds")) throw Error(pb->loc, "pixelbounds is not supported");
    f.params.get_bool("savefp16", true);  // bpm always writes 32-bit float EXR
    f.params.warn_unused("film");
  }

  void read_filter(LoadedScene* out) {
    const SceneEntity& f = parsed_.filter;
    FilterSettings& s = out->filter;
    float def = 0.5f;
    if (f.name == "box") s.type = FilterType::kBox, def = 0.5f;
    else if (f.name == "triangle") s.type = FilterType::kTriangle, def = 2;
    else if (f.name == "gaussian") s.type = FilterType::kGaussian, def = 1.5f;
    else if (f.name == "mitchell") s.type = FilterType::kMitchell, def = 2;
    else if (f.name == "sinc") s.type = FilterType::kLanczos, def = 4;
    else throw Error(f.loc, "pixel filter \"" + f.name + "\" is unknown");
    s.radius = {f.params.get_float("xradius", def), f.params.get_float("yradius", def)};
    if (!(s.radius.x > 0 && s.radius.y > 0)) throw Error(f.loc, "filter radius must be positive");
    s.sigma = f.params.get_float("sigma", 0.5f);
    s.b = f.params.get_float("B", 1.0f / 3);
    s.c = f.params.get_float("C", 1.0f / 3);
    s.tau = f.params.get_float("tau", 3);
    f.params.warn_unused("pixel filter");
  }

  void read_sampler_and_integrator(LoadedScene* out) {
    const SceneEntity& s = parsed_.sampler;
    static const char* samplers[] = {"zsobol", "sobol", "paddedsobol", "halton", "independent", "pmj02bn", "stratified"};
    bool known = false;
    for (const char* n : samplers) known = known || s.name == n;
    if (!known) throw Error(s.loc, "sampler \"" + s.name + "\" is unknown");
    out->render.spp = s.params.get_int("pixelsamples", 16);
    if (s.name == "stratified")
      out->render.spp = s.params.get_int("xsamples", 4) * s.params.get_int("ysamples", 4);
    if (out->render.spp <= 0) throw Error(s.loc, "pixelsamples must be positive");
    out->render.seed = s.params.get_int("seed", 0);
    s.params.get_bool("jitter", true);
    s.params.get_string("randomization", "");
    s.params.warn_unused("sampler");

    const SceneEntity& in = parsed_.integrator;
    out->render.integrator_as_written = in.name;
    out->render.max_depth = in.params.get_int("maxdepth", 5);
    if (out->render.max_depth < 0) throw Error(in.loc, "maxdepth must not be negative");
    if (in.name == "path" || in.name == "bpm" || in.name == "fpm") {
      out->render.integrator = in.name;
    } else if (in.name == "volpath" || in.name == "bdpt" || in.name == "mlt" || in.name == "sppm" ||
               in.name == "simplepath" || in.name == "lightpath" || in.name == "randomwalk" ||
               in.name == "simplevolpath") {
      // These estimate the same image for scenes without media; bpm's reference for them is path.
      out->render.integrator = "path";
      if (parsed_.integrator_given)
        warning(in.loc, "integrator \"" + in.name + "\" is rendered with bpm's \"path\" integrator (same image for surfaces)");
    } else {
      throw Error(in.loc, "integrator \"" + in.name + "\" is not supported");
    }
    if (in.name == "bpm" || in.name == "fpm") read_bpm_settings(in, &out->render.bpm);
    if (in.name == "fpm") {
      out->render.fpm.final_gather = in.params.get_bool("finalgather", false);
      out->render.fpm.knn = in.params.get_int("knn", 0);
      if (out->render.fpm.knn < 0) {
        const Param* p = in.params.find_any("knn");
        throw Error(p ? p->loc : in.loc, "knn must not be negative");
      }
    }
    for (const Param& p : in.params.all()) p.used = true;  // other integrators' knobs are advisory
  }

  // bpm's own parameters on its Integrator line; the command line may override each.
  static void read_bpm_settings(const SceneEntity& in, BpmSettings* b) {
    const ParamSet& ps = in.params;
    auto check = [&](const char* name, bool ok, const char* what) {
      if (!ok) throw Error(ps.find_any(name) ? ps.find_any(name)->loc : in.loc, std::string(name) + " " + what);
    };
    b->diffuse_depth = ps.get_int("diffusedepth", b->diffuse_depth);
    check("diffusedepth", b->diffuse_depth >= 0 && b->diffuse_depth <= 3, "must be in 0..3");
    b->k0 = ps.get_float("k0", b->k0);
    check("k0", b->k0 > 0 && b->k0 < 1e4f, "must be positive");
    b->k1 = ps.get_float("k1", b->k1);
    check("k1", b->k1 > 0 && b->k1 < 1e4f, "must be positive");
    std::string policy = ps.get_string("radiuspolicy", to_string(b->radius_policy));
    check("radiuspolicy", policy == "fixed" || policy == "progressive", "must be \"fixed\" or \"progressive\"");
    b->radius_policy = policy == "fixed" ? RadiusPolicy::kFixed : RadiusPolicy::kProgressive;
    b->alpha = ps.get_float("alpha", b->alpha);
    check("alpha", b->alpha > 0 && b->alpha < 1, "must be in (0, 1)");
    b->photons_per_batch = ps.get_int("photonsperbatch", b->photons_per_batch);
    check("photonsperbatch", b->photons_per_batch > 0, "must be positive");
    b->coverage = ps.get_float("coverage", b->coverage);
    check("coverage", b->coverage >= 0 && b->coverage <= 1, "must be in [0, 1]");
    b->max_batches = ps.get_int("maxbatches", b->max_batches);
    check("maxbatches", b->max_batches > 0, "must be positive");
    b->centre_tree = ps.get_string("tree", "spheres") == "centres";
    check("tree", b->centre_tree || ps.get_string("tree", "spheres") == "spheres", "must be \"spheres\" or \"centres\"");
  }

  // ---- textures ----
  const TextureEntity& texture_entity(const Param& ref) {
    ref.used = true;
    if (ref.strings.size() != 1) throw Error(ref.loc, "a texture parameter names one texture");
    auto it = textures_.find(ref.strings[0]);
    if (it == textures_.end()) throw Error(ref.loc, "unknown texture \"" + ref.strings[0] + "\"");
    return *it->second;
  }

  // The node of a texture, built on first use. Spectrum textures are built once per kind (how
  // their image texels are read); float textures once.
  int texture_node(const TextureEntity& t, bool as_float, SpectrumKind kind) {
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
  int spectrum_node(const ParamSet& ps, const std::string& name, SpectrumKind kind, float def) {
    const Param* p = ps.find_any(name);
    if (p && p->type == "texture") return texture_node(texture_entity(*p), false, kind);
    if (p && p->type == "float") return scene().textures.add(ConstantTexture{SpectrumCurve(ps.get_float(name, def)), 0});
    auto v = get_spectrum(ps, name, kind, parsed_.base_directory);
    return scene().textures.add(ConstantTexture{v.value_or(SpectrumCurve(def)), 0});
  }
  int float_node(const ParamSet& ps, const std::string& name, float def) {
    const Param* p = ps.find_any(name);
    if (p && p->type == "texture") return texture_node(texture_entity(*p), true, SpectrumKind::kAlbedo);
    return scene().textures.add(ConstantTexture{SpectrumCurve(), ps.get_float(name, def)});
  }

  static TexMapping texture_mapping(const TextureEntity& t) {
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
      throw Error(ps.find_any("mapping")->loc, "texture mapping \"" + kind + "\" is unknown (uv, spherical, cylindrical, planar)");
    }
    return m;
  }

  int build_texture(const TextureEntity& t, bool as_float, SpectrumKind kind) {
    const ParamSet& ps = t.params;
    if (as_float != (t.value_type == "float"))
      throw Error(t.loc, "texture \"" + t.texture_name + "\" is a " + t.value_type + " texture; a " +
                             (as_float ? "float" : "spectrum") + " texture is needed here");
    TextureNode node;
    if (t.name == "constant") {
      ConstantTexture c;
      if (as_float) c.value = ps.get_float("value", 1);
      else c.spectrum = get_spectrum(ps, "value", kind, parsed_.base_directory).value_or(SpectrumCurve(1.0f));
      node = c;
    } else if (t.name == "imagemap") {
      ImageTexture im;
      std::string file = ps.get_string("filename", "");
      if (file.empty()) throw Error(t.loc, "imagemap texture \"" + t.texture_name + "\" has no \"string filename\"");
      fs::path path = fs::path(file).is_absolute() ? fs::path(file) : fs::path(parsed_.base_directory) / file;
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
        if (!(enc.gamma > 0)) throw Error(ps.find_any("encoding")->loc, "bad gamma in encoding \"" + encoding + "\"");
      } else {
        throw Error(ps.find_any("encoding")->loc, "encoding \"" + encoding + "\" is unknown (sRGB, linear, \"gamma g\")");
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
        throw Error(ps.find_any("filter")->loc, "texture filter \"" + filter + "\" is unknown (point, bilinear, trilinear, ewa)");
      }
      ps.get_float("maxanisotropy", 8);
      std::string wrap = ps.get_string("wrap", "repeat");
      if (wrap == "repeat") im.wrap = TexWrap::kRepeat;
      else if (wrap == "clamp") im.wrap = TexWrap::kClamp;
      else if (wrap == "black") im.wrap = TexWrap::kBlack;
      else if (wrap == "octahedralsphere") im.wrap = TexWrap::kOctahedralSphere;
      else throw Error(ps.find_any("wrap")->loc, "wrap mode \"" + wrap + "\" is unknown (repeat, clamp, black, octahedralsphere)");
      im.scale = ps.get_float("scale", 1);
      im.invert = ps.get_bool("invert", false);
      im.kind = kind;
      im.mapping = texture_mapping(t);
      node = im;
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
      throw Error(t.loc, "texture class \"" + t.name + "\" is not supported (constant, imagemap, checkerboard, scale, mix)");
    }
    ps.warn_unused("texture \"" + t.texture_name + "\"");
    return scene().textures.add(std::move(node));
  }

  // ---- materials ----
  // A spectral material parameter: a constant (a constant texture included) or a texture node.
  std::optional<SpectrumParam> spectrum_param(const ParamSet& ps, const std::string& name, SpectrumKind kind) {
    const Param* p = ps.find_any(name);
    if (p && p->type == "texture") {
      const TextureEntity& t = texture_entity(*p);
      if (t.name == "constant" && t.value_type == "float") {
        float v = t.params.get_float("value", 1);
        if (v < 0 || (kind == SpectrumKind::kAlbedo && v > 1))
          throw Error(t.loc, "constant texture \"" + t.texture_name + "\" used as a reflectance must lie in [0, 1]");
        return SpectrumParam(SpectrumCurve(v));
      }
      if (t.name == "constant") {
        auto v = get_spectrum(t.params, "value", kind, parsed_.base_directory);
        return SpectrumParam(v ? *v : SpectrumCurve(1.0f));
      }
      SpectrumParam sp;
      sp.texture = texture_node(t, false, kind);
      return sp;
    }
    if (auto c = get_spectrum(ps, name, kind, parsed_.base_directory)) return SpectrumParam(*c);
    return std::nullopt;
  }
  // A float material parameter that must not vary over the surface (a constant texture is fine).
  float float_param(const ParamSet& ps, const std::string& name, float def) {
    const Param* p = ps.find_any(name);
    if (p && p->type == "texture") {
      const TextureEntity& t = texture_entity(*p);
      if (t.name != "constant" || t.value_type != "float")
        throw Error(p->loc, "\"" + name + "\" must be a float or a constant float texture; \"" + p->strings[0] + "\" is not");
      return t.params.get_float("value", 1);
    }
    return ps.get_float(name, def);
  }
  // A float parameter that may vary: its constant, or the node of a non-constant float texture.
  FloatParam float_or_texture(const ParamSet& ps, const std::string& name, float def) {
    const Param* p = ps.find_any(name);
    if (p && p->type == "texture") {
      const TextureEntity& t = texture_entity(*p);
      if (!(t.name == "constant" && t.value_type == "float")) return FloatParam{0, texture_node(t, true, SpectrumKind::kAlbedo)};
    }
    return FloatParam{float_param(ps, name, def), -1};
  }

  // prefix: "" for most materials, "interface." or "conductor." for coatedconductor's two layers.
  // Textured roughness goes to tex; a material that takes none passes null.
  Roughness roughness(const ParamSet& ps, const FileLoc& loc, const std::string& prefix = "",
                      RoughnessTextures* tex = nullptr) {
    FloatParam r = float_or_texture(ps, prefix + "roughness", 0);
    FloatParam u = ps.find_any(prefix + "uroughness") ? float_or_texture(ps, prefix + "uroughness", 0) : r;
    FloatParam v = ps.find_any(prefix + "vroughness") ? float_or_texture(ps, prefix + "vroughness", 0) : r;
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
  float dielectric_eta(const ParamSet& ps, const FileLoc& loc, const std::string& name = "eta") {
    float eta = 1.5f;
    const Param* p = ps.find_any(name);
    if (p && p->type == "float") {
      eta = ps.get_float(name, 1.5f);
    } else if (p) {
      SpectrumParam sp = *spectrum_param(ps, name, SpectrumKind::kUnbounded);
      if (sp.textured()) throw Error(p->loc, "a textured eta is not supported");
      const SpectrumCurve& s = sp.curve;
      if (s.max_value() - s.min_value() > 1e-4f)
        warning(p->loc, "a wavelength-dependent eta is reduced to its value at 550 nm (no dispersion)");
      eta = s.value(550);
    }
    if (!(eta > 0)) throw Error(p ? p->loc : loc, "eta must be positive");
    return eta;
  }

  // A conductor from eta and k (copper by default) or from a reflectance; prefix names the
  // parameters ("conductor." inside coatedconductor).
  ConductorDesc conductor_desc(const ParamSet& ps, const FileLoc& loc, const std::string& prefix) {
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
  CoatLayer coat_layer(const ParamSet& ps, const SceneEntity& e, const std::string& prefix, RoughnessTextures* tex) {
    CoatLayer c;
    c.roughness = roughness(ps, e.loc, prefix, tex);
    c.eta = dielectric_eta(ps, e.loc, prefix + "eta");
    c.thickness = float_param(ps, "thickness", 0.01f);
    if (!(c.thickness > 0) || !std::isfinite(c.thickness))
      throw Error(ps.find_any("thickness")->loc, "thickness must be positive");
    auto count = [&](const char* name, int def) {
      int v = ps.get_int(name, def);
      if (v < 1 || v > 1000) throw Error(ps.find_any(name)->loc, std::string(name) + " must be in [1, 1000]");
      return v;
    };
    c.max_depth = count("maxdepth", 10);
    c.samples = count("nsamples", 1);
    if (auto a = spectrum_param(ps, "albedo", SpectrumKind::kAlbedo); a && (a->textured() || !a->curve.is_black()))
      throw Error(ps.find_any("albedo")->loc, e.name + " with a scattering layer (albedo > 0) is not supported");
    if (ps.find_any("g")) float_param(ps, "g", 0);  // that medium's phase function: irrelevant without it
    return c;
  }

  MaterialDesc make_material(const SceneEntity& e) {
    const ParamSet& ps = e.params;
    for (const char* unsupported : {"displacement", "normalmap"})
      if (auto* p = ps.find_any(unsupported)) throw Error(p->loc, std::string(unsupported) + " is not supported");
    MaterialDesc m;
    if (e.name == "diffuse") {
      DiffuseDesc d;
      if (auto r = spectrum_param(ps, "reflectance", SpectrumKind::kAlbedo)) d.reflectance = *r;
      m = d;
    } else if (e.name == "conductor") {
      m = conductor_desc(ps, e.loc, "");
    } else if (e.name == "dielectric" || e.name == "thindielectric") {
      float eta = dielectric_eta(ps, e.loc);
      if (e.name == "dielectric") m = DielectricMaterial{eta, roughness(ps, e.loc)};
      else m = ThinDielectricMaterial{eta};
    } else if (e.name == "diffusetransmission") {
      DiffuseTransmissionDesc d;
      if (auto r = spectrum_param(ps, "reflectance", SpectrumKind::kAlbedo)) d.reflectance = *r;
      if (auto t = spectrum_param(ps, "transmittance", SpectrumKind::kAlbedo)) d.transmittance = *t;
      float s = ps.get_float("scale", 1);
      if (d.reflectance.textured() || d.transmittance.textured()) {
        if (s != 1) throw Error(ps.find_any("scale")->loc, "diffusetransmission scale with textures is not supported");
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
      c.layer = coat_layer(ps, e, "", &c.roughness_tex);
      m = c;
    } else if (e.name == "coatedconductor") {
      CoatedConductorDesc c;
      c.layer = coat_layer(ps, e, "interface.", &c.roughness_tex);
      c.conductor = conductor_desc(ps, e.loc, "conductor.");
      m = c;
    } else if (e.name == "phong") {
      // bpm's own non-reciprocal glossy lobe (material.h); pbrt-v4 does not know it.
      PhongDesc ph;
      if (auto r = spectrum_param(ps, "reflectance", SpectrumKind::kAlbedo)) ph.reflectance = *r;
      if (const Param* p = ps.find_any("exponent")) {
        ph.exponent = ps.get_float("exponent", 20);
        if (!(ph.exponent >= 0 && ph.exponent <= 1e5f)) throw Error(p->loc, "phong exponent must be in [0, 1e5]");
      }
      m = ph;
    } else if (e.name == "mix") {
      MixDesc mix;
      const Param* names = ps.find("materials", "string");
      if (!names || names->strings.size() != 2)
        throw Error(names ? names->loc : e.loc, "mix needs \"string materials\" with two named materials");
      names->used = true;
      for (int i = 0; i < 2; ++i) mix.materials[i] = material_id(MaterialRef{-1, names->strings[size_t(i)], names->loc});
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

  // ---- media ----
  // The index of a named medium, -1 for "" (vacuum). Only media that absorb without scattering
  // or emitting are supported (pbrt-v4 "homogeneous" with sigma_s = 0 and no Le).
  int medium_id(const std::string& name, const FileLoc& loc) {
    if (name.empty()) return -1;
    if (auto it = medium_ids_.find(name); it != medium_ids_.end()) return it->second;
    auto e = parsed_.media.find(name);
    if (e == parsed_.media.end()) throw Error(loc, "unknown medium \"" + name + "\"");
    const SceneEntity& m = e->second;
    const ParamSet& ps = m.params;
    auto unsupported = [&](const std::string& why) {
      return Error(loc, "participating media are not supported (medium \"" + name + "\" defined at " + m.loc.str() +
                            ": " + why + "); only absorbing homogeneous media (sigma_s = 0) are");
    };
    if (m.name != "homogeneous") throw unsupported("type \"" + m.name + "\"");
    if (const Param* p = ps.find_any("preset")) {
      p->used = true;
      throw unsupported("preset \"" + (p->strings.empty() ? std::string() : p->strings[0]) + "\" scatters");
    }
    float scale = ps.get_float("scale", 1);
    if (!(scale >= 0) || !std::isfinite(scale)) throw Error(m.loc, "medium scale must be a non-negative number");
    // pbrt-v4's defaults scatter: sigma_s must be stated, and zero.
    auto sigma_s = get_spectrum(ps, "sigma_s", SpectrumKind::kUnbounded, parsed_.base_directory);
    if (!sigma_s || sigma_s->max_value() * scale > 0) throw unsupported("it scatters (sigma_s > 0)");
    auto Le = get_spectrum(ps, "Le", SpectrumKind::kIlluminant, parsed_.base_directory);
    float le_scale = ps.get_float("Lescale", 1);
    if (Le && !Le->is_black() && le_scale != 0) throw unsupported("it emits (Le)");
    ps.get_float("g", 0);
    auto sigma_a = get_spectrum(ps, "sigma_a", SpectrumKind::kUnbounded, parsed_.base_directory)
                       .value_or(SpectrumCurve::from_rgb(Rgb(0.0011f, 0.0024f, 0.014f), SpectrumKind::kUnbounded));
    if (!(sigma_a.min_value() >= 0)) throw Error(m.loc, "sigma_a must not be negative");
    ps.warn_unused("medium \"" + name + "\"");
    scene().media.push_back(AbsorbingMedium{name, sigma_a.scaled(scale)});
    return medium_ids_[name] = int(scene().media.size()) - 1;
  }

  int material_id(const MaterialRef& ref) {
    if (!ref.named.empty()) {
      auto it = named_material_ids_.find(ref.named);
      if (it != named_material_ids_.end()) return it->second;
      auto e = parsed_.named_materials.find(ref.named);
      if (e == parsed_.named_materials.end()) throw Error(ref.loc, "unknown named material \"" + ref.named + "\"");
      if (!building_materials_.insert(ref.named).second)
        throw Error(ref.loc, "named material \"" + ref.named + "\" contains itself (through mix)");
      MaterialDesc made = make_material(e->second);
      building_materials_.erase(ref.named);
      scene().materials.push_back(std::move(made));
      return named_material_ids_[ref.named] = int(scene().materials.size()) - 1;
    }
    if (ref.index < 0) return 0;
    auto it = anonymous_material_ids_.find(ref.index);
    if (it != anonymous_material_ids_.end()) return it->second;
    scene().materials.push_back(make_material(parsed_.materials[ref.index]));
    return anonymous_material_ids_[ref.index] = int(scene().materials.size()) - 1;
  }

  // ---- shapes ----
  static void check_indices(const std::vector<int>& idx, size_t n, const FileLoc& loc) {
    for (int i : idx)
      if (i < 0 || size_t(i) >= n)
        throw Error(loc, "vertex index " + std::to_string(i) + " out of range (" + std::to_string(n) + " vertices)");
  }

  TriangleMesh mesh_from(const Transform& xf, bool flip, std::vector<Vec3> P, std::vector<Vec3> N,
                         std::vector<Vec2> uv, const std::vector<int>& idx) {
    TriangleMesh m;
    m.positions.reserve(P.size() + 2);  // Embree reads vertex buffers in 16-byte chunks
    for (Vec3 p : P) m.positions.push_back(xf.point(p));
    for (Vec3 n : N) m.normals.push_back(normalize(xf.normal(n)));
    m.uvs = std::move(uv);
    m.indices.assign(idx.begin(), idx.end());
    m.flip_normal = flip;
    return m;
  }

  void add_shape(const ShapeEntity& s, RenderScene* rs) {
    const ParamSet& ps = s.params;
    bool flip = s.reverse_orientation != s.world_from_object.swaps_handedness();
    for (const char* ignored : {"emission", "faceIndices"})
      if (auto* p = ps.find_any(ignored)) p->used = true;
    Object obj;
    obj.source = s.loc.str();
    if (const Param* a = ps.find_any("alpha")) {
      obj.alpha = float_or_texture(ps, "alpha", 1);
      if (!obj.alpha.textured() && !(obj.alpha.value >= 0 && obj.alpha.value <= 1))
        throw Error(a->loc, "alpha must be in [0, 1]");
      if (obj.has_alpha() && s.area_light)
        throw Error(a->loc, "alpha on an emitting shape is not supported (the area light at " + s.area_light->loc.str() + ")");
    }
    if (s.name == "trianglemesh" || s.name == "bilinearmesh") {
      bool bilinear = s.name == "bilinearmesh";
      auto P = ps.get_point3s("P");
      if (P.empty()) throw Error(s.loc, s.name + " has no \"point3 P\"");
      auto idx = ps.get_ints("indices");
      size_t per = bilinear ? 4 : 3;
      if (idx.empty()) {
        if (P.size() != per) throw Error(s.loc, s.name + " has no \"integer indices\"");
        for (size_t i = 0; i < per; ++i) idx.push_back(int(i));
      }
      const FileLoc& iloc = ps.find_any("indices") ? ps.find_any("indices")->loc : s.loc;
      if (idx.size() % per != 0)
        throw Error(iloc, "\"indices\" has " + std::to_string(idx.size()) + " values, not a multiple of " + std::to_string(per));
      check_indices(idx, P.size(), iloc);
      auto N = ps.get_normals("N");
      auto uv = ps.get_point2s("uv");
      if (uv.empty()) uv = ps.get_point2s("st");
      if (!N.empty() && N.size() != P.size())
        throw Error(ps.find_any("N")->loc, "\"N\" has " + std::to_string(N.size()) + " normals for " + std::to_string(P.size()) + " vertices");
      if (!uv.empty() && uv.size() != P.size())
        throw Error(ps.find_any("uv") ? ps.find_any("uv")->loc : s.loc, "\"uv\" count differs from the vertex count");
      if (auto* S = ps.find_any("S")) {
        S->used = true;
        warning(S->loc, "per-vertex tangents \"S\" are ignored");
      }
      if (bilinear) idx = bilinear_to_triangles(P, idx, s.loc);
      obj.shape = mesh_from(s.world_from_object, flip, P, N, uv, idx);
    } else if (s.name == "loopsubdiv") {
      auto P = ps.get_point3s("P");
      auto idx = ps.get_ints("indices");
      if (P.empty() || idx.empty()) throw Error(s.loc, "loopsubdiv needs \"point3 P\" and \"integer indices\"");
      const FileLoc& iloc = ps.find_any("indices")->loc;
      if (idx.size() % 3 != 0)
        throw Error(iloc, "\"indices\" has " + std::to_string(idx.size()) + " values, not a multiple of 3");
      check_indices(idx, P.size(), iloc);
      int levels = ps.get_int("levels", 3);
      if (levels < 0 || levels > 8) throw Error(ps.find_any("levels")->loc, "loopsubdiv levels must be in [0, 8]");
      SubdividedMesh sub;
      try {
        sub = loop_subdivide(P, idx, levels);
      } catch (const std::invalid_argument& e) {
        throw Error(s.loc, std::string("loopsubdiv: ") + e.what());
      }
      obj.shape = mesh_from(s.world_from_object, flip, std::move(sub.positions), std::move(sub.normals), {}, sub.indices);
    } else if (s.name == "plymesh") {
      std::string file = ps.get_string("filename", "");
      if (file.empty()) throw Error(s.loc, "plymesh has no \"string filename\"");
      if (auto* d = ps.find_any("displacement")) throw Error(d->loc, "displacement is not supported");
      ps.get_float("edgelength", 1);
      fs::path path = fs::path(file).is_absolute() ? fs::path(file) : fs::path(s.directory) / file;
      PlyMesh ply = read_ply(path.string(), ps.find_any("filename")->loc);
      obj.shape = mesh_from(s.world_from_object, flip, ply.positions, ply.normals, ply.uvs, ply.indices);
    } else if (s.name == "sphere") {
      Sphere sp;
      sp.world_from_object = s.world_from_object;
      sp.radius = ps.get_float("radius", 1);
      if (!(sp.radius > 0)) throw Error(s.loc, "sphere radius must be positive");
      sp.z_min = std::clamp(ps.get_float("zmin", -sp.radius), -sp.radius, sp.radius);
      sp.z_max = std::clamp(ps.get_float("zmax", sp.radius), -sp.radius, sp.radius);
      if (sp.z_min > sp.z_max) std::swap(sp.z_min, sp.z_max);
      sp.phi_max = radians(std::clamp(ps.get_float("phimax", 360), 0.0f, 360.0f));
      sp.flip_normal = flip;
      obj.shape = sp;
    } else if (s.name == "disk") {
      Disk d;
      d.world_from_object = s.world_from_object;
      d.height = ps.get_float("height", 0);
      d.radius = ps.get_float("radius", 1);
      d.inner_radius = ps.get_float("innerradius", 0);
      if (!(d.radius > 0) || d.inner_radius < 0 || d.inner_radius >= d.radius)
        throw Error(s.loc, "disk needs 0 <= innerradius < radius");
      d.phi_max = radians(std::clamp(ps.get_float("phimax", 360), 0.0f, 360.0f));
      d.flip_normal = flip;
      obj.shape = d;
    } else if (s.name == "cylinder") {
      Cylinder c;
      c.world_from_object = s.world_from_object;
      c.radius = ps.get_float("radius", 1);
      if (!(c.radius > 0)) throw Error(s.loc, "cylinder radius must be positive");
      float z0 = ps.get_float("zmin", -1), z1 = ps.get_float("zmax", 1);
      c.z_min = std::fmin(z0, z1);
      c.z_max = std::fmax(z0, z1);
      if (!(c.z_max > c.z_min)) throw Error(s.loc, "cylinder needs zmin != zmax");
      c.phi_max = radians(std::clamp(ps.get_float("phimax", 360), 0.0f, 360.0f));
      if (!(c.phi_max > 0)) throw Error(s.loc, "cylinder phimax must be positive");
      c.flip_normal = flip;
      obj.shape = c;
    } else {
      throw Error(s.loc, "shape \"" + s.name + "\" is not supported");
    }
    ps.warn_unused("shape \"" + s.name + "\"");
    obj.material = material_id(s.material);
    obj.medium_inside = medium_id(s.medium.inside, s.medium.loc);
    obj.medium_outside = medium_id(s.medium.outside, s.medium.loc);
    int id = int(rs->objects.size());
    if (s.area_light) add_area_light(*s.area_light, &obj, id, rs);
    rs->objects.push_back(std::move(obj));
  }

  static std::vector<int> bilinear_to_triangles(const std::vector<Vec3>& P, const std::vector<int>& idx, const FileLoc& loc) {
    std::vector<int> tris;
    for (size_t i = 0; i < idx.size(); i += 4) {
      int a = idx[i], b = idx[i + 1], c = idx[i + 2], d = idx[i + 3];  // p00 p10 p01 p11
      Vec3 n = cross(P[b] - P[a], P[c] - P[a]);
      float size = std::fmax(length(P[b] - P[a]), length(P[c] - P[a]));
      float ln = length(n);
      if (ln > 0 && std::fabs(dot(P[d] - P[a], n / ln)) > 1e-4f * size)
        throw Error(loc, "non-planar bilinear patches are not supported (patch " + std::to_string(i / 4) + ")");
      int t[6] = {a, b, d, a, d, c};
      tris.insert(tris.end(), t, t + 6);
    }
    return tris;
  }

  void add_area_light(const SceneEntity& a, Object* obj, int id, RenderScene* rs) {
    if (a.name != "diffuse") throw Error(a.loc, "area light \"" + a.name + "\" is not supported");
    const ParamSet& ps = a.params;
    std::shared_ptr<const TexImage> image;
    Rgb image_mean(0.0f);
    if (ps.find_any("filename")) {
      if (const Param* l = ps.find_any("L")) throw Error(l->loc, "an area light takes \"L\" or \"filename\", not both");
      image = light_image(ps, "an image area");
      for (int y = 0; y < image->height; ++y)
        for (int x = 0; x < image->width; ++x) {
          image_mean += image->texel(x, y, TexWrap::kClamp).clamped_zero();
        }
      image_mean = image_mean / float(image->width * image->height);
    }
    SpectrumCurve L = image ? SpectrumCurve(0.0f) : light_spectrum(ps, "L");
    float scale = ps.get_float("scale", 1);
    if (scale < 0) throw Error(ps.find_any("scale")->loc, "area light scale must not be negative");
    bool two_sided = ps.get_bool("twosided", false);
    float power = ps.get_float("power", -1);
    if (image && power > 0) {
      // pbrt-v4 normalises by the image's mean luminance.
      if (!(image_mean.luminance() > 0)) throw Error(ps.find_any("power")->loc, "\"power\" is given but the image is black");
      scale /= image_mean.luminance();
    }
    ps.warn_unused("area light");
    if (std::holds_alternative<Sphere>(obj->shape) || std::holds_alternative<Disk>(obj->shape)) {
      const Transform& xf = std::holds_alternative<Sphere>(obj->shape) ? std::get<Sphere>(obj->shape).world_from_object
                                                                        : std::get<Disk>(obj->shape).world_from_object;
      bool full = std::holds_alternative<Sphere>(obj->shape) ? std::get<Sphere>(obj->shape).is_full()
                                                             : std::get<Disk>(obj->shape).is_full();
      if (!xf.is_similarity() || !full)
        throw Error(a.loc, "emitting spheres and disks must be whole and not non-uniformly scaled");
    }
    if (auto* c = std::get_if<Cylinder>(&obj->shape); c && !c->world_from_object.is_similarity())
      throw Error(a.loc, "emitting cylinders must not be non-uniformly scaled");
    obj->first_light = int(rs->lights.size());
    for (int p = 0; p < primitive_count(obj->shape); ++p) {
      AreaLight l;
      l.object = id;
      l.primitive = p;
      l.two_sided = two_sided;
      l.area = primitive_area(obj->shape, p);
      float s = scale;
      // pbrt-v4 applies "power" to each shape it creates, i.e. to each triangle of a mesh.
      if (power > 0 && l.area > 0) s *= power / (kPi * (two_sided ? 2 : 1) * l.area);
      l.radiance = L.scaled(s);
      l.image = image;
      l.image_scale = s;
      l.image_mean = image_mean;
      rs->lights.push_back(l);
    }
  }

  // ---- light sources ----
  // A light's spectrum; D65 at unit luminance when absent (pbrt-v4's colour-space illuminant).
  SpectrumCurve light_spectrum(const ParamSet& ps, const std::string& name) {
    return get_spectrum(ps, name, SpectrumKind::kIlluminant, parsed_.base_directory)
        .value_or(SpectrumCurve::from_rgb(Rgb(1.0f), SpectrumKind::kIlluminant));
  }

  // An environment image light; scale comes in with the light's "scale" and leaves with the
  // "illuminance" normalisation applied.
  // The image a light's "filename" names (8-bit images decoded as sRGB, as pbrt-v4 does); errors
  // name the parameter.
  std::shared_ptr<const TexImage> light_image(const ParamSet& ps, const std::string& light) {
    const Param* f = ps.find_any("filename");
    std::string file = ps.get_string("filename", "");
    if (!f || file.empty()) throw Error(f ? f->loc : FileLoc{}, light + " light needs \"string filename\"");
    fs::path path = fs::path(file).is_absolute() ? fs::path(file) : fs::path(parsed_.base_directory) / file;
    std::shared_ptr<const TexImage> image;
    try {
      image = load_texture_image(path.string(), TexEncoding{});
    } catch (const Error& err) {
      throw Error(f->loc, err.what());
    }
    for (float v : image->texels)
      if (!std::isfinite(v)) throw Error(f->loc, "\"" + file + "\" has infinite or not-a-number texels and cannot be a light");
    return image;
  }

  ImageInfiniteLight image_light(const LightEntity& e, const Param& file_param, float* scale) {
    const ParamSet& ps = e.params;
    std::string file = ps.get_string("filename", "");
    ImageInfiniteLight l;
    l.image = light_image(ps, "an infinite");
    const TexImage& im = *l.image;
    if (im.width == im.height) {
      l.equal_area = true;
    } else if (im.width == 2 * im.height) {
      l.equal_area = false;
      warning(file_param.loc, "\"" + file + "\" is " + std::to_string(im.width) + "x" + std::to_string(im.height) +
                                  ": read as a latitude-longitude map (pbrt-v3's layout); pbrt-v4 takes only square "
                                  "equal-area images");
    } else {
      throw Error(file_param.loc, "environment image \"" + file + "\" is " + std::to_string(im.width) + "x" +
                                      std::to_string(im.height) + ": it must be square (equal-area) or twice as wide as high (latitude-longitude)");
    }
    if (!e.world_from_light.is_similarity())
      throw Error(e.loc, "the transform of an environment light must be a rotation (no non-uniform scale)");
    l.world_from_light = e.world_from_light;
    float E = ps.get_float("illuminance", -1);
    if (E > 0) {
      double e_image = image_light_illuminance(l);
      if (!(e_image > 0))
        throw Error(ps.find_any("illuminance")->loc, "\"illuminance\" is given but the image sends no light to the upper hemisphere");
      *scale *= float(E / e_image);
    }
    l.scale = *scale;
    prepare_image_light(&l);
    return l;
  }

  void add_light(const LightEntity& e, RenderScene* rs) {
    const ParamSet& ps = e.params;
    if (!e.medium.outside.empty() && medium_id(e.medium.outside, e.medium.loc) >= 0)
      throw Error(e.loc, "light \"" + e.name + "\" inside a medium (\"" + e.medium.outside + "\") is not supported");
    const Transform& xf = e.world_from_light;
    float scale = ps.get_float("scale", 1);
    if (e.name == "point") {
      SpectrumCurve I = light_spectrum(ps, "I");
      float power = ps.get_float("power", -1);
      if (power > 0) scale *= power / (4 * kPi);
      rs->lights.push_back(PointLight{xf.point(ps.get_point3("from", Vec3(0, 0, 0))), I.scaled(scale)});
    } else if (e.name == "goniometric") {
      if (!ps.find_any("filename")) throw Error(e.loc, "goniometric light needs \"string filename\" (its intensity image)");
      GoniometricLight l;
      l.image = light_image(ps, "goniometric");
      if (l.image->width != l.image->height)
        throw Error(ps.find_any("filename")->loc, "goniometric image \"" + ps.get_string("filename", "") + "\" is " +
                                                      std::to_string(l.image->width) + "x" + std::to_string(l.image->height) +
                                                      ": it must be square (pbrt-v4's equal-area layout)");
      if (!xf.is_similarity()) throw Error(e.loc, "the transform of a goniometric light must not scale non-uniformly");
      l.world_from_light = xf;
      prepare_goniometric_light(&l);
      float power = ps.get_float("power", -1);
      if (power > 0) {
        if (!(l.mean_value > 0)) throw Error(ps.find_any("power")->loc, "\"power\" is given but the goniometric image is black");
        scale *= power / (4 * kPi * l.mean_value);
      }
      l.intensity = light_spectrum(ps, "I").scaled(scale);
      rs->lights.push_back(std::move(l));
    } else if (e.name == "projection") {
      if (!ps.find_any("filename")) throw Error(e.loc, "projection light needs \"string filename\" (the projected image)");
      ProjectionLight l;
      l.image = light_image(ps, "projection");
      float fov = ps.get_float("fov", 90);
      if (!(fov > 0 && fov < 180)) throw Error(ps.find_any("fov")->loc, "projection fov must be in (0, 180) degrees");
      l.tan_half_fov = std::tan(radians(fov) / 2);
      if (!xf.is_similarity()) throw Error(e.loc, "the transform of a projection light must not scale non-uniformly");
      l.world_from_light = xf;
      l.scale = 1;
      prepare_projection_light(&l);  // power_rgb at scale 1; the distribution does not depend on it
      float power = ps.get_float("power", -1);
      if (power > 0) {
        // pbrt-v4 normalises the luminance-weighted power of the image.
        float phi = l.power_rgb.luminance();
        if (!(phi > 0)) throw Error(ps.find_any("power")->loc, "\"power\" is given but the projected image is black");
        scale *= power / phi;
      }
      l.scale = scale;
      l.power_rgb *= scale;
      rs->lights.push_back(std::move(l));
    } else if (e.name == "spot") {
      SpectrumCurve I = light_spectrum(ps, "I");
      Vec3 from = ps.get_point3("from", Vec3(0, 0, 0)), to = ps.get_point3("to", Vec3(0, 0, 1));
      if (length(to - from) == 0) throw Error(e.loc, "spot light with from == to");
      float cone = ps.get_float("coneangle", 30), delta = ps.get_float("conedelta", 5);
      SpotLight l;
      l.position = xf.point(from);
      l.frame = Frame::from_z(normalize(xf.vector(to - from)));
      l.cos_falloff_end = std::cos(radians(cone));
      l.cos_falloff_start = std::cos(radians(cone - delta));
      float power = ps.get_float("power", -1);
      if (power > 0)
        scale *= power / (2 * kPi * ((1 - l.cos_falloff_start) + (l.cos_falloff_start - l.cos_falloff_end) / 2));
      l.intensity = I.scaled(scale);
      rs->lights.push_back(l);
    } else if (e.name == "distant") {
      SpectrumCurve L = light_spectrum(ps, "L");
      Vec3 from = ps.get_point3("from", Vec3(0, 0, 0)), to = ps.get_point3("to", Vec3(0, 0, 1));
      if (length(to - from) == 0) throw Error(e.loc, "distant light with from == to");
      float E = ps.get_float("illuminance", -1);
      if (E > 0) scale *= E;
      rs->lights.push_back(DistantLight{normalize(xf.vector(from - to)), L.scaled(scale)});
    } else if (e.name == "infinite") {
      if (auto* p = ps.find_any("portal")) throw Error(p->loc, "light portals are not supported");
      if (const Param* f = ps.find_any("filename")) {
        if (const Param* l = ps.find_any("L")) throw Error(l->loc, "an infinite light takes \"L\" or \"filename\", not both");
        rs->lights.push_back(image_light(e, *f, &scale));
        if (!(scale >= 0) || !std::isfinite(scale)) throw Error(e.loc, "light scale must be a non-negative number");
        ps.warn_unused("light \"" + e.name + "\"");
        return;
      }
      SpectrumCurve L = light_spectrum(ps, "L");
      float E = ps.get_float("illuminance", -1);
      if (E > 0) scale *= E / kPi;
      rs->lights.push_back(UniformInfiniteLight{L.scaled(scale)});
    } else {
      throw Error(e.loc, "light \"" + e.name + "\" is not supported");
    }
    if (!(scale >= 0) || !std::isfinite(scale)) throw Error(e.loc, "light scale must be a non-negative number");
    ps.warn_unused("light \"" + e.name + "\"");
  }
};

}  // namespace

LoadedScene flatten_scene(const ParsedScene& parsed) { return Flattener(parsed).run(); }

}  // namespace bpm
