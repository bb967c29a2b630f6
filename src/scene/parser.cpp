// pbrt-v4 scene file parser: directives, typed parameters, the graphics state and its stack.
// Format reference: pbrt-v4's file format documentation and src/pbrt/parser.cpp.
#include <charconv>
#include <cmath>
#include <filesystem>
#include <functional>
#include <set>

#include "scene/parsed_scene.h"
#include "scene/tokenizer.h"

namespace bpm {
namespace {

namespace fs = std::filesystem;

struct GraphicsState {
  Transform ctm;
  bool reverse_orientation = false;
  MaterialRef material;
  std::optional<SceneEntity> area_light;
  bool in_object = false;
  MediumRef medium;
};

class Parser {
 public:
  explicit Parser(ParsedScene* scene) : scene_(scene) {}

  void run(std::unique_ptr<Tokenizer> top) {
    push_file(std::move(top));
    while (auto tok = next_token()) directive(*tok);
    if (object_name_)
      throw Error(object_loc_, "ObjectBegin \"" + *object_name_ + "\" without ObjectEnd");
    if (!stack_.empty())
      throw Error(stack_.back().loc, "AttributeBegin without a matching AttributeEnd");
    if (!world_begun_) throw Error(last_loc_, "the scene has no WorldBegin");
  }

 private:
  struct Saved {
    GraphicsState state;
    FileLoc loc;
    bool transform_only;
  };
  struct FileInput {
    std::unique_ptr<Tokenizer> tok;
  };

  ParsedScene* scene_;
  std::vector<FileInput> files_;
  // Tokens are views into their file's text, and a look-ahead may run past the end of an
  // included file: finished files stay alive until parsing ends.
  std::vector<std::unique_ptr<Tokenizer>> finished_;
  std::optional<Token> peeked_;
  GraphicsState gs_;
  std::vector<Saved> stack_;
  std::map<std::string, Transform> coord_systems_;
  std::map<std::string, std::vector<ShapeEntity>> objects_;
  std::optional<std::string> object_name_;
  FileLoc object_loc_;
  bool world_begun_ = false;
  bool active_start_ = true, active_end_ = true;
  FileLoc last_loc_;
  std::set<std::string> include_chain_;

  void push_file(std::unique_ptr<Tokenizer> t) { files_.push_back({std::move(t)}); }

  std::optional<Token> next_token() {
    if (peeked_) {
      auto t = peeked_;
      peeked_.reset();
      return t;
    }
    while (!files_.empty()) {
      if (auto t = files_.back().tok->next()) {
        last_loc_ = t->loc;
        return t;
      }
      include_chain_.erase(files_.back().tok->file_name());
      finished_.push_back(std::move(files_.back().tok));
      files_.pop_back();
    }
    return std::nullopt;
  }
  std::optional<Token> peek_token() {
    if (!peeked_) peeked_ = next_token();
    return peeked_;
  }
  Token expect_token(const FileLoc& after, const char* what) {
    auto t = next_token();
    if (!t) throw Error(after, std::string("unexpected end of file: expected ") + what);
    return *t;
  }
  std::string expect_string(const Token& directive, const char* what) {
    Token t = expect_token(directive.loc, what);
    if (!t.is_string())
      throw Error(t.loc, "expected " + std::string(what) + " (a quoted string) after " +
                             std::string(directive.text) + "; got '" + std::string(t.text) + "'");
    return t.unquoted();
  }
  static double to_number(const Token& t) {
    double v = 0;
    const char* b = t.text.data();
    const char* e = b + t.text.size();
    if (*b == '+') ++b;
    auto [ptr, ec] = std::from_chars(b, e, v);
    if (ec != std::errc() || ptr != e)
      throw Error(t.loc, "expected a number; got '" + std::string(t.text) + "'");
    return v;
  }
  double expect_number(const Token& directive) {
    return to_number(expect_token(directive.loc, "a number"));
  }
  std::vector<double> numbers(const Token& d, int n) {
    std::vector<double> v;
    bool bracket = false;
    if (auto p = peek_token(); p && p->is("[")) {
      next_token();
      bracket = true;
    }
    for (int i = 0; i < n; ++i) v.push_back(expect_number(d));
    if (bracket) {
      Token t = expect_token(d.loc, "]");
      if (!t.is("]"))
        throw Error(t.loc, std::string(d.text) + " takes " + std::to_string(n) + " numbers");
    }
    for (double x : v)
      if (!std::isfinite(x)) throw Error(d.loc, std::string(d.text) + " has a non-finite value");
    return v;
  }

  // The type name, place and parameters of a directive that creates something.
  void read_entity(const Token& d, const char* what, SceneEntity* e) {
    e->name = expect_string(d, what);
    e->loc = d.loc;
    e->params = params();
  }

  ParamSet params() {
    ParamSet ps;
    while (true) {
      auto t = peek_token();
      if (!t || !t->is_string()) break;
      next_token();
      std::string decl = t->unquoted();
      size_t sp = decl.find_first_of(" \t");
      if (sp == std::string::npos)
        throw Error(t->loc, "expected a parameter declaration \"type name\"; got \"" + decl + "\"");
      std::string type = decl.substr(0, sp);
      size_t ns = decl.find_first_not_of(" \t", sp);
      std::string name = ns == std::string::npos ? "" : decl.substr(ns);
      if (name.empty() || name.find_first_of(" \t") != std::string::npos)
        throw Error(t->loc, "malformed parameter declaration \"" + decl + "\"");
      Param p;
      p.type = canonical_param_type(type);
      if (p.type.empty()) throw Error(t->loc, "unknown parameter type \"" + type + "\"");
      p.name = name;
      p.loc = t->loc;
      std::vector<Token> values;
      Token v = expect_token(t->loc, "a parameter value");
      if (v.is("[")) {
        while (true) {
          Token x = expect_token(t->loc, "] closing the parameter values");
          if (x.is("]")) break;
          if (x.is("[")) throw Error(x.loc, "nested '[' in parameter values");
          values.push_back(x);
        }
      } else {
        values.push_back(v);
      }
      fill_values(&p, values);
      ps.add(std::move(p));
    }
    return ps;
  }

  void fill_values(Param* p, const std::vector<Token>& values) {
    if (values.empty()) throw Error(p->loc, "parameter \"" + p->name + "\" has no values");
    const std::string& ty = p->type;
    if (ty == "string" || ty == "texture") {
      for (const Token& v : values) {
        if (!v.is_string())
          throw Error(v.loc, "parameter \"" + p->name + "\" expects strings; got '" +
                                 std::string(v.text) + "'");
        p->strings.push_back(v.unquoted());
      }
    } else if (ty == "bool") {
      for (const Token& v : values) {
        std::string s = v.is_string() ? v.unquoted() : std::string(v.text);
        if (s != "true" && s != "false")
          throw Error(v.loc, "parameter \"" + p->name + "\" expects true or false; got '" +
                                 std::string(v.text) + "'");
        p->bools.push_back(s == "true");
      }
    } else if (ty == "spectrum" && values.size() == 1 && values[0].is_string()) {
      p->strings.push_back(values[0].unquoted());
    } else {
      for (const Token& v : values) {
        if (v.is_string())
          throw Error(v.loc, "parameter \"" + p->name + "\" expects numbers; got a string");
        p->numbers.push_back(to_number(v));
      }
      size_t n = p->numbers.size();
      auto need = [&](size_t k, const char* what) {
        if (n % k != 0)
          throw Error(p->loc, "parameter \"" + p->name + "\" of type " + ty + " needs " + what +
                                  "; got " + std::to_string(n) + " values");
      };
      if (ty == "integer") {
        for (double x : p->numbers)
          if (x != std::floor(x) || std::fabs(x) > 2147483647.0)
            throw Error(p->loc, "parameter \"" + p->name + "\" expects integers");
      } else if (ty == "rgb") {
        // One colour; an rgbgrid medium's lists of them are checked where they are read.
        if (n == 0 || n % 3 != 0)
          throw Error(p->loc, "parameter \"" + p->name + "\" of type rgb needs 3 values; got " +
                                  std::to_string(n));
      } else if (ty == "blackbody") {
        if (n != 1 && n != 2)
          throw Error(p->loc,
                      "parameter \"" + p->name + "\" of type blackbody needs a temperature");
      } else if (ty == "spectrum") {
        need(2, "wavelength/value pairs");
      } else if (ty == "point2" || ty == "vector2") {
        need(2, "a multiple of 2 values");
      } else if (ty == "point3" || ty == "vector3" || ty == "normal") {
        need(3, "a multiple of 3 values");
      }
    }
  }

  void apply_transform(const Transform& t, bool concat) {
    // Motion blur is not supported: only the start transform is kept.
    if (active_start_) gs_.ctm = concat ? gs_.ctm * t : t;
    if (active_end_ && !active_start_)
      warning(last_loc_, "transforms for the shutter's end time are ignored (no motion blur)");
  }

  void require_world(const Token& d, bool inside) {
    if (inside && !world_begun_)
      throw Error(d.loc, std::string(d.text) + " is only allowed after WorldBegin");
    if (!inside && world_begun_)
      throw Error(d.loc, std::string(d.text) + " is not allowed after WorldBegin");
  }

  // pbrt-v4 resolves every relative file name against the directory of the main scene file,
  // whichever file names it.
  std::string current_directory() const { return scene_->base_directory; }

  // Each group below returns false, having consumed nothing, when `d` is not one of its
  // directives, so directive() can try them in turn and still report an unknown keyword itself.
  void directive(const Token& d) {
    const std::string_view k = d.text;
    if (d.is_string() || k == "[" || k == "]")
      throw Error(d.loc, "expected a directive; got '" + std::string(k) + "'");
    if (transform_directive(d) || graphics_state_directive(d) || render_option_directive(d) ||
        entity_directive(d) || object_directive(d) || file_directive(d))
      return;
    throw Error(d.loc, "unknown directive '" + std::string(k) + "'");
  }

  // The current transformation matrix, the named coordinate systems and the orientation flag.
  bool transform_directive(const Token& d) {
    const std::string_view k = d.text;
    if (k == "Translate") {
      auto v = numbers(d, 3);
      apply_transform(Transform::translate(Vec3(v[0], v[1], v[2])), true);
    } else if (k == "Scale") {
      auto v = numbers(d, 3);
      if (v[0] == 0 || v[1] == 0 || v[2] == 0)
        throw Error(d.loc, "Scale by zero makes the transform singular");
      apply_transform(Transform::scale(Vec3(v[0], v[1], v[2])), true);
    } else if (k == "Rotate") {
      auto v = numbers(d, 4);
      if (v[1] == 0 && v[2] == 0 && v[3] == 0) throw Error(d.loc, "Rotate about a zero axis");
      apply_transform(Transform::rotate(v[0], Vec3(v[1], v[2], v[3])), true);
    } else if (k == "LookAt") {
      auto v = numbers(d, 9);
      auto t = Transform::look_at(Vec3(v[0], v[1], v[2]), Vec3(v[3], v[4], v[5]),
                                  Vec3(v[6], v[7], v[8]));
      if (!t)
        throw Error(d.loc,
                    "LookAt with coincident eye and target, or up parallel to the view direction");
      apply_transform(*t, true);
    } else if (k == "Transform" || k == "ConcatTransform") {
      auto v = numbers(d, 16);
      Matrix4 m;
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) m[i][j] = v[4 * i + j];
      // The file lists the matrix column by column.
      auto t = Transform::from_matrix(matrix_transpose(m));
      if (!t) throw Error(d.loc, std::string(k) + " matrix is singular");
      apply_transform(*t, k == "ConcatTransform");
    } else if (k == "Identity") {
      apply_transform(Transform(), false);
    } else if (k == "CoordinateSystem") {
      coord_systems_[expect_string(d, "a name")] = gs_.ctm;
    } else if (k == "CoordSysTransform") {
      std::string name = expect_string(d, "a name");
      auto it = coord_systems_.find(name);
      if (it == coord_systems_.end())
        throw Error(d.loc, "unknown coordinate system \"" + name + "\"");
      gs_.ctm = it->second;
    } else if (k == "ActiveTransform") {
      Token t = expect_token(d.loc, "StartTime, EndTime or All");
      if (t.is("StartTime"))
        active_start_ = true, active_end_ = false;
      else if (t.is("EndTime"))
        active_start_ = false, active_end_ = true;
      else if (t.is("All"))
        active_start_ = active_end_ = true;
      else
        throw Error(t.loc, "ActiveTransform takes StartTime, EndTime or All; got '" +
                               std::string(t.text) + "'");
    } else if (k == "TransformTimes") {
      numbers(d, 2);
    } else if (k == "ReverseOrientation") {
      gs_.reverse_orientation = !gs_.reverse_orientation;
    } else {
      return false;
    }
    return true;
  }

  // The attribute stack and the material and media that later shapes and lights pick up.
  bool graphics_state_directive(const Token& d) {
    const std::string_view k = d.text;
    if (k == "AttributeBegin" || k == "TransformBegin") {
      stack_.push_back({gs_, d.loc, k == "TransformBegin"});
    } else if (k == "AttributeEnd" || k == "TransformEnd") {
      if (stack_.empty()) throw Error(d.loc, std::string(k) + " without a matching begin");
      if (stack_.back().transform_only)
        gs_.ctm = stack_.back().state.ctm;
      else
        gs_ = stack_.back().state;
      stack_.pop_back();
    } else if (k == "Attribute") {
      std::string target = expect_string(d, "a target");
      ParamSet ps = params();
      for (const Param& p : ps.all())
        warning(p.loc, "Attribute \"" + target + "\" defaults are not supported; \"" + p.name +
                           "\" was ignored");
    } else if (k == "Material") {
      require_world(d, true);
      SceneEntity m{expect_string(d, "a material type"), {}, d.loc};
      m.params = params();
      scene_->materials.push_back(std::move(m));
      gs_.material = {int(scene_->materials.size()) - 1, "", d.loc};
    } else if (k == "MakeNamedMaterial") {
      require_world(d, true);
      std::string name = expect_string(d, "a material name");
      ParamSet ps = params();
      const Param* type = ps.find("type", "string");
      if (!type) throw Error(d.loc, "MakeNamedMaterial \"" + name + "\" has no \"string type\"");
      if (scene_->named_materials.count(name))
        throw Error(d.loc, "named material \"" + name + "\" defined twice");
      scene_->named_materials[name] = SceneEntity{type->strings[0], std::move(ps), d.loc};
    } else if (k == "NamedMaterial") {
      require_world(d, true);
      gs_.material = {-1, expect_string(d, "a material name"), d.loc};
    } else if (k == "MakeNamedMedium") {
      std::string name = expect_string(d, "a medium name");
      ParamSet ps = params();
      const Param* type = ps.find("type", "string");
      if (!type || type->strings.size() != 1)
        throw Error(d.loc, "medium \"" + name + "\" has no \"string type\"");
      type->used = true;
      scene_->media[name] = MediumEntity{{type->strings[0], std::move(ps), d.loc}, gs_.ctm};
    } else if (k == "MediumInterface") {
      std::string inside = expect_string(d, "a medium name");
      std::string outside = inside;
      if (auto t = peek_token(); t && t->is_string()) outside = next_token()->unquoted();
      gs_.medium = MediumRef{inside, outside, d.loc};
    } else {
      return false;
    }
    return true;
  }

  // The camera, film, sampler and other whole-render settings, and WorldBegin that closes them.
  bool render_option_directive(const Token& d) {
    const std::string_view k = d.text;
    if (k == "Camera") {
      require_world(d, false);
      CameraEntity c;
      read_entity(d, "a camera type", &c);
      c.camera_from_world = gs_.ctm;
      c.medium = gs_.medium;
      coord_systems_["camera"] = gs_.ctm.inverse();
      scene_->camera = std::move(c);
    } else if (k == "Film" || k == "Sampler" || k == "PixelFilter" || k == "Integrator" ||
               k == "Accelerator") {
      require_world(d, false);
      SceneEntity e{expect_string(d, "a type name"), {}, d.loc};
      e.params = params();
      if (k == "Film")
        scene_->film = std::move(e);
      else if (k == "Sampler")
        scene_->sampler = std::move(e);
      else if (k == "PixelFilter")
        scene_->filter = std::move(e);
      else if (k == "Integrator")
        scene_->integrator = std::move(e), scene_->integrator_given = true;
      // Accelerator: Embree builds its own BVH, so the choice has no effect.
    } else if (k == "ColorSpace") {
      std::string cs = expect_string(d, "a color space");
      if (cs != "srgb")
        throw Error(d.loc, "color space \"" + cs + "\" is not supported (only srgb)");
    } else if (k == "Option") {
      ParamSet ps = params();
      for (const Param& p : ps.all())
        warning(p.loc, "Option \"" + p.name + "\" is not supported and was ignored");
    } else if (k == "WorldBegin") {
      require_world(d, false);
      world_begun_ = true;
      gs_.ctm = Transform();
      coord_systems_["world"] = gs_.ctm;
    } else if (k == "WorldEnd") {
      // pbrt-v3 syntax; nothing to do.
    } else {
      return false;
    }
    return true;
  }

  // Textures, lights and shapes, which take the graphics state as it stands now.
  bool entity_directive(const Token& d) {
    const std::string_view k = d.text;
    if (k == "Texture") {
      require_world(d, true);
      TextureEntity t;
      t.texture_name = expect_string(d, "a texture name");
      t.value_type = expect_string(d, "a texture type");
      if (t.value_type == "color") t.value_type = "spectrum";
      if (t.value_type != "float" && t.value_type != "spectrum")
        throw Error(d.loc,
                    "texture type must be \"float\" or \"spectrum\"; got \"" + t.value_type + "\"");
      read_entity(d, "a texture class", &t);
      t.world_from_texture = gs_.ctm;
      scene_->textures.push_back(std::move(t));
    } else if (k == "LightSource") {
      require_world(d, true);
      LightEntity l;
      read_entity(d, "a light type", &l);
      l.world_from_light = gs_.ctm;
      l.medium = gs_.medium;
      scene_->lights.push_back(std::move(l));
    } else if (k == "AreaLightSource") {
      require_world(d, true);
      SceneEntity a{expect_string(d, "an area light type"), {}, d.loc};
      a.params = params();
      gs_.area_light = std::move(a);
    } else if (k == "Shape") {
      require_world(d, true);
      ShapeEntity s;
      read_entity(d, "a shape type", &s);
      s.world_from_object = gs_.ctm;
      s.reverse_orientation = gs_.reverse_orientation;
      s.material = gs_.material;
      s.area_light = gs_.area_light;
      s.directory = current_directory();
      s.medium = gs_.medium;
      if (object_name_)
        objects_[*object_name_].push_back(std::move(s));
      else
        scene_->shapes.push_back(std::move(s));
    } else {
      return false;
    }
    return true;
  }

  // Object definitions collect shapes; each instance copies them into the scene under the
  // transform in effect where it is placed.
  bool object_directive(const Token& d) {
    const std::string_view k = d.text;
    if (k == "ObjectBegin") {
      require_world(d, true);
      if (object_name_) throw Error(d.loc, "ObjectBegin inside another ObjectBegin");
      object_name_ = expect_string(d, "an object name");
      object_loc_ = d.loc;
      if (objects_.count(*object_name_))
        throw Error(d.loc, "object \"" + *object_name_ + "\" defined twice");
      objects_[*object_name_];
      stack_.push_back({gs_, d.loc, false});
    } else if (k == "ObjectEnd") {
      if (!object_name_) throw Error(d.loc, "ObjectEnd without ObjectBegin");
      object_name_.reset();
      if (stack_.empty()) throw Error(d.loc, "ObjectEnd without ObjectBegin");
      gs_ = stack_.back().state;
      stack_.pop_back();
    } else if (k == "ObjectInstance") {
      require_world(d, true);
      std::string name = expect_string(d, "an object name");
      auto it = objects_.find(name);
      if (it == objects_.end()) throw Error(d.loc, "unknown object \"" + name + "\"");
      if (object_name_) throw Error(d.loc, "ObjectInstance inside ObjectBegin");
      for (const ShapeEntity& s : it->second) {
        ShapeEntity copy = s;
        copy.world_from_object = gs_.ctm * s.world_from_object;
        scene_->shapes.push_back(std::move(copy));
      }
    } else {
      return false;
    }
    return true;
  }

  // Include and Import are read alike: the named file's directives are parsed in place.
  bool file_directive(const Token& d) {
    const std::string_view k = d.text;
    if (k != "Include" && k != "Import") return false;
    std::string file = expect_string(d, "a file name");
    fs::path p =
        fs::path(file).is_absolute() ? fs::path(file) : fs::path(current_directory()) / file;
    std::string ps = p.lexically_normal().string();
    if (include_chain_.count(ps)) throw Error(d.loc, "file \"" + file + "\" includes itself");
    if (peeked_) throw Error(d.loc, "internal: include with pending token");
    include_chain_.insert(ps);
    push_file(Tokenizer::from_file(ps, d.loc));
    scene_->files.push_back(ps);
    return true;
  }
};

}  // namespace

ParsedScene parse_scene_file(const std::string& path) {
  ParsedScene scene;
  scene.base_directory = fs::path(path).parent_path().string();
  if (scene.base_directory.empty()) scene.base_directory = ".";
  scene.files.push_back(path);
  Parser parser(&scene);
  parser.run(Tokenizer::from_file(path, FileLoc{path, 0, 0}));
  return scene;
}

ParsedScene parse_scene_string(const std::string& text, const std::string& directory) {
  ParsedScene scene;
  scene.base_directory = directory;
  Parser parser(&scene);
  parser.run(Tokenizer::from_string(text));
  return scene;
}

}  // namespace bpm
