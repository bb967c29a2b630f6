// The class behind flatten_scene (flatten.h), private to the files that define it:
//   flatten.cpp            the order of the steps
//   flatten_settings.cpp   camera, film, pixel filter, sampler and integrator settings
//   flatten_lens.cpp       the realistic camera's lens
//   flatten_textures.cpp   texture nodes
//   flatten_materials.cpp  spectral and float parameters, materials, media
//   flatten_shapes.cpp     shapes and the area lights attached to them
//   flatten_lights.cpp     the other lights
#pragma once
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "scene/flatten.h"
#include "scene/ply.h"

namespace bpm::flatten_internal {

inline float radians(float deg) { return deg * kPi / 180; }

// pbrt-v4's "cloud" density at point p of the medium's space (media.h, CloudMedium::Density):
// five octaves of Perlin noise at `frequency`, p first pushed along the noise's slope where
// `wispiness` > 0, thinning with height (y) and solid below y = 0.5; in [0, 1].
float cloud_density(Vec3 p, float density, float wispiness, float frequency);

class Flattener {
 public:
  explicit Flattener(const ParsedScene& p);
  LoadedScene run();

 private:
  const ParsedScene& parsed_;
  // Textures by name, and the nodes built from them, keyed by (name, as float, SpectrumKind);
  // building_ holds the textures under construction, to report one that refers to itself.
  std::map<std::string, const TextureEntity*> textures_;
  std::map<std::tuple<std::string, bool, int>, int> texture_nodes_;
  std::set<std::string> building_;
  // Indices in the render scene of the materials and media made so far; building_materials_
  // holds the named materials under construction, to report one that contains itself.
  std::map<int, int> anonymous_material_ids_;
  std::map<std::string, int> named_material_ids_;
  std::map<std::string, int> medium_ids_;
  std::set<std::string> building_materials_;
  // The coateddiffuse walk tables made so far: materials with the same coat share one.
  std::vector<std::shared_ptr<const CoatWalkTable>> coat_walk_tables_;
  std::shared_ptr<const CoatWalkTable> coat_walk_table(const CoatLayer& layer);
  // The data files read so far (LoadedScene::data_files), and the same as a set.
  std::vector<std::string> data_files_;
  std::set<std::string> data_file_set_;
  void read_data_file(const std::string& path);
  // get_spectrum with the scene's directory, noting a spectrum file it reads.
  std::optional<SpectrumCurve> spectrum_curve(const ParamSet& ps, const std::string& name,
                                              SpectrumKind kind);
  // The render scene being filled (set by read_camera, the first step).
  RenderScene* scene_ = nullptr;
  RenderScene& scene() { return *scene_; }

  // Camera, film, filter, sampler and integrator settings (flatten_settings.cpp).
  void read_camera(LoadedScene* out);
  void read_film(LoadedScene* out);
  void read_filter(LoadedScene* out);
  void read_sampler_and_integrator(LoadedScene* out);
  // The realistic camera's lens (flatten_lens.cpp): read with the camera, built once the film's
  // resolution is known.
  void read_lens(const CameraEntity& c);
  void build_lens(LoadedScene* out);
  std::optional<LensSettings> lens_;
  FileLoc lens_loc_;

  // Texture nodes (flatten_textures.cpp).
  const TextureEntity& texture_entity(const Param& ref);
  int texture_node(const TextureEntity& t, bool as_float, SpectrumKind kind);
  int spectrum_node(const ParamSet& ps, const std::string& name, SpectrumKind kind, float def);
  int float_node(const ParamSet& ps, const std::string& name, float def);
  static TexMapping texture_mapping(const TextureEntity& t);
  int build_texture(const TextureEntity& t, bool as_float, SpectrumKind kind);
  ImageTexture image_texture(const TextureEntity& t, SpectrumKind kind);

  // Material parameters, materials and media (flatten_materials.cpp).
  std::optional<SpectrumParam> spectrum_param(const ParamSet& ps, const std::string& name,
                                              SpectrumKind kind);
  float float_param(const ParamSet& ps, const std::string& name, float def);
  FloatParam float_or_texture(const ParamSet& ps, const std::string& name, float def);
  Roughness roughness(const ParamSet& ps, const FileLoc& loc, const std::string& prefix = "",
                      RoughnessTextures* tex = nullptr);
  // A dielectric's index: its value at 587.56 nm, and the curve when it depends on the wavelength.
  struct DielectricEta {
    float eta = 1.5f;
    EtaSpectrum spectrum;
  };
  DielectricEta dielectric_eta(const ParamSet& ps, const FileLoc& loc,
                               const std::string& name = "eta");
  ConductorDesc conductor_desc(const ParamSet& ps, const FileLoc& loc, const std::string& prefix);
  CoatLayer coat_layer(const ParamSet& ps, const SceneEntity& e, const std::string& prefix,
                       SpectrumParam* albedo, RoughnessTextures* tex);
  MaterialDesc make_material(const SceneEntity& e);
  Bump make_bump(const SceneEntity& e);
  int add_material(const SceneEntity& e);
  int material_id(const MaterialRef& ref);

  // The media shapes, lights and the camera refer to (flatten_media.cpp).
  int medium_id(const std::string& name, const FileLoc& loc);
  std::shared_ptr<const DensityGrid> density_grid(const MediumEntity& m);
  std::shared_ptr<const DensityGrid> cloud_grid(const MediumEntity& m);
  std::shared_ptr<const DensityGrid> le_scale_grid(const MediumEntity& m);
  void read_temperature(const MediumEntity& m, Medium* medium);
  std::shared_ptr<const RgbGrid> rgb_grid(const MediumEntity& m, float scale);

  // Shapes and their area lights (flatten_shapes.cpp).
  static void check_indices(const std::vector<int>& idx, size_t n, const FileLoc& loc);
  TriangleMesh mesh_from(const Transform& xf, bool flip, std::vector<Vec3> P, std::vector<Vec3> N,
                         std::vector<Vec2> uv, const std::vector<int>& idx);
  void add_shape(const ShapeEntity& s, RenderScene* rs);
  TriangleMesh mesh_shape(const ShapeEntity& s, bool flip);
  TriangleMesh loopsubdiv_shape(const ShapeEntity& s, bool flip);
  TriangleMesh plymesh_shape(const ShapeEntity& s, bool flip);
  void displace_ply(const ParamSet& ps, const Param& displacement, float edge_length,
                    const ShapeEntity& s, PlyMesh* ply);
  static Sphere sphere_shape(const ShapeEntity& s, bool flip);
  static Disk disk_shape(const ShapeEntity& s, bool flip);
  static Cylinder cylinder_shape(const ShapeEntity& s, bool flip);
  static Curves curve_shape(const ShapeEntity& s, bool flip);
  // A bilinear mesh's patches as triangles (indices p00 p10 p01 p11 per patch): two for a planar
  // patch, else a grid fine enough to follow the patch, whose vertices are appended.
  static std::vector<int> bilinear_to_triangles(std::vector<Vec3>& P, std::vector<Vec3>& N,
                                                std::vector<Vec2>& uv, const std::vector<int>& idx);
  void add_area_light(const SceneEntity& a, Object* obj, int id, RenderScene* rs);

  // Light sources other than area lights (flatten_lights.cpp). The add_*_light helpers take the
  // light's "scale" and apply their kind's "power" or "illuminance" to it.
  SpectrumCurve light_spectrum(const ParamSet& ps, const std::string& name);
  std::shared_ptr<const TexImage> light_image(const ParamSet& ps, const std::string& light);
  std::shared_ptr<const TexImage> luminaire_image(const ParamSet& ps);
  ImageInfiniteLight image_light(const LightEntity& e, const Param& file_param, float* scale);
  void add_light(const LightEntity& e, RenderScene* rs);
  void add_point_light(const LightEntity& e, float* scale, RenderScene* rs);
  void add_goniometric_light(const LightEntity& e, float* scale, RenderScene* rs);
  void add_projection_light(const LightEntity& e, float* scale, RenderScene* rs);
  void add_spot_light(const LightEntity& e, float* scale, RenderScene* rs);
  void add_distant_light(const LightEntity& e, float* scale, RenderScene* rs);
  void add_infinite_light(const LightEntity& e, float* scale, RenderScene* rs);
};

}  // namespace bpm::flatten_internal
