// The scene as the file states it: directives with their parameters and transforms, before any
// interpretation. flatten.cpp and its flatten_*.cpp parts turn it into the
// render scene.
#pragma once
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "base/transform.h"
#include "scene/params.h"

namespace bpm {

struct SceneEntity {
  std::string name;  // the type: "perspective", "diffuse", "sphere", ...
  ParamSet params;
  FileLoc loc;
};

// The media on the two sides of a surface (pbrt-v4's MediumInterface; "" is vacuum), or the
// medium a camera or light sits in (outside).
struct MediumRef {
  std::string inside, outside;
  FileLoc loc;  // of the MediumInterface directive
  bool any() const { return !inside.empty() || !outside.empty(); }
};

struct CameraEntity : SceneEntity {
  Transform camera_from_world;
  MediumRef medium;
};

struct MaterialRef {
  int index = -1;     // into ParsedScene::materials, or -1
  std::string named;  // or a NamedMaterial name
  FileLoc loc;
};

struct ShapeEntity : SceneEntity {
  Transform world_from_object;
  bool reverse_orientation = false;
  MaterialRef material;
  std::optional<SceneEntity> area_light;
  std::string directory;  // of the file that named the shape, for relative paths
  MediumRef medium;
};

struct MediumEntity : SceneEntity {
  Transform world_from_medium;  // the transform in effect at MakeNamedMedium (grids' space)
};

struct LightEntity : SceneEntity {
  Transform world_from_light;
  MediumRef medium;
};

struct TextureEntity : SceneEntity {
  std::string texture_name;
  std::string value_type;  // "float" or "spectrum"
  Transform world_from_texture;
};

struct ParsedScene {
  std::optional<CameraEntity> camera;
  SceneEntity film{"rgb", {}, {}};
  SceneEntity sampler{"zsobol", {}, {}};
  SceneEntity filter{"gaussian", {}, {}};
  SceneEntity integrator{"volpath", {}, {}};
  bool integrator_given = false;
  std::vector<SceneEntity> materials;                  // anonymous Material directives
  std::map<std::string, SceneEntity> named_materials;  // MakeNamedMaterial
  std::vector<TextureEntity> textures;
  std::map<std::string, MediumEntity> media;  // MakeNamedMedium; name is the "type" parameter
  std::vector<ShapeEntity> shapes;
  std::vector<LightEntity> lights;
  std::string base_directory;      // of the main scene file
  std::vector<std::string> files;  // the scene files read: the main one, then each Include/Import
};

// Parses a scene file (following Include and Import). Throws Error with file:line:column.
ParsedScene parse_scene_file(const std::string& path);
// Parses scene text held in memory; relative file names resolve against directory.
ParsedScene parse_scene_string(const std::string& text, const std::string& directory = ".");

}  // namespace bpm
