// Tests of the pbrt-v4 scene parser (parser.cpp, tokenizer.cpp, params.cpp), of the checks that
// flatten.cpp applies while turning the parsed scene into the render scene, of spectrum parameters
// (spectra.cpp) and of the PLY reader (ply.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <variant>
#include <vector>

#include "base/error.h"
#include "base/rng.h"
#include "lights/light.h"
#include "materials/layered.h"
#include "scene/flatten.h"
#include "scene/parsed_scene.h"
#include "scene/ply.h"
#include "scene/spectra.h"

namespace bpm {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// Helpers

// The Error message that parsing and flattening scene_text produces, or "" when both succeed.
std::string error_of(const std::string& scene_text, const std::string& directory = ".") {
  try {
    ParsedScene parsed = parse_scene_string(scene_text, directory);
    (void)flatten_scene(parsed);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// The Error message of parsing alone, or "" when parsing succeeds.
std::string parse_error_of(const std::string& scene_text, const std::string& directory = ".") {
  try {
    (void)parse_scene_string(scene_text, directory);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// "<string>:LINE:COL", the location prefix of errors in in-memory scene text.
std::string at(int line, int column) {
  return "<string>:" + std::to_string(line) + ":" + std::to_string(column);
}

// 1-based column at which needle starts in line (-1 when absent, which makes the test fail).
int col(const std::string& line, const std::string& needle) {
  size_t p = line.find(needle);
  return p == std::string::npos ? -1 : int(p) + 1;
}

// The message starts with "WHERE: " and contains phrase.
::testing::AssertionResult IsError(const std::string& message, const std::string& where,
                                   const std::string& phrase) {
  if (message.empty())
    return ::testing::AssertionFailure()
           << "no error; expected \"" << where << ": ..." << phrase << "...\"";
  if (!message.starts_with(where + ": "))
    return ::testing::AssertionFailure()
           << "error \"" << message << "\" is not located at " << where;
  if (message.find(phrase) == std::string::npos)
    return ::testing::AssertionFailure()
           << "error \"" << message << "\" does not contain \"" << phrase << "\"";
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult Contains(const std::string& haystack, const std::string& needle) {
  if (haystack.find(needle) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "\"" << haystack << "\" does not contain \"" << needle << "\"";
}

void expect_vec_near(Vec3 a, Vec3 b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

// A spectral curve's colour against the colour the file gave (the sigmoid fit reproduces it).
void expect_spectrum_near(const SpectrumCurve& a, const Rgb& b, float eps = 1e-4f) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(a.rgb()[i], b[i], eps) << "channel " << i;
}
// Two curves, wavelength by wavelength.
void expect_spectrum_near(const SpectrumCurve& a, const SpectrumCurve& b, float eps = 1e-5f) {
  for (float l = kLambdaMin; l <= kLambdaMax; l += 10)
    EXPECT_NEAR(a.value(l), b.value(l), eps) << l << " nm";
}

// A material parameter that must be a constant curve.
void expect_spectrum_near(const SpectrumParam& a, const Rgb& b, float eps = 1e-4f) {
  EXPECT_FALSE(a.textured());
  expect_spectrum_near(a.curve, b, eps);
}
void expect_spectrum_near(const SpectrumParam& a, const SpectrumCurve& b, float eps = 1e-5f) {
  EXPECT_FALSE(a.textured());
  expect_spectrum_near(a.curve, b, eps);
}

Vec3 origin_of(const Transform& t) { return t.point(Vec3(0, 0, 0)); }

// A fresh folder under the system temp directory, removed with its contents at the end.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = "bpm_parser_test_";
    if (info) name += std::string(info->test_suite_name()) + "_" + info->name() + "_";
    name += std::to_string(std::random_device{}());
    path_ = fs::temp_directory_path() / name;
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const fs::path& path() const { return path_; }
  std::string str() const { return path_.string(); }
  fs::path write(const std::string& name, const std::string& content) const {
    fs::path p = path_ / name;
    fs::create_directories(p.parent_path());
    std::ofstream out(p, std::ios::binary);
    out << content;
    return p;
  }

 private:
  fs::path path_;
};

template <typename T>
void put_le(std::string* s, T v) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(b, b + sizeof(T));
  s->append(reinterpret_cast<const char*>(b), sizeof(T));
}

template <typename T>
void put_be(std::string* s, T v) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if constexpr (std::endian::native == std::endian::little) std::reverse(b, b + sizeof(T));
  s->append(reinterpret_cast<const char*>(b), sizeof(T));
}

const char* kTriangleP = R"("point3 P" [0 0 0  1 0 0  0 1 0])";

const std::string kAsciiQuadPly =
    "ply\n"
    "format ascii 1.0\n"
    "comment a unit quad\n"
    "element vertex 4\n"
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "element face 1\n"
    "property list uchar int vertex_indices\n"
    "end_header\n"
    "0 0 0\n"
    "1 0 0\n"
    "1 1 0\n"
    "0 1 0\n"
    "4 0 1 2 3\n";

// ---------------------------------------------------------------------------------------------
// Directives

TEST(SceneParse, MinimalSceneFlattens) {
  ParsedScene p = parse_scene_string("WorldBegin\n");
  EXPECT_FALSE(p.camera.has_value());
  EXPECT_TRUE(p.shapes.empty());
  EXPECT_EQ(p.film.name, "rgb");
  EXPECT_EQ(p.sampler.name, "zsobol");
  EXPECT_EQ(p.filter.name, "gaussian");
  EXPECT_EQ(p.integrator.name, "volpath");
  EXPECT_FALSE(p.integrator_given);
  LoadedScene ls = flatten_scene(p);
  EXPECT_TRUE(ls.scene.objects.empty());
  ASSERT_EQ(ls.scene.materials.size(), 1u);  // the default material
  ASSERT_TRUE(std::holds_alternative<DiffuseDesc>(ls.scene.materials[0]));
  expect_spectrum_near(std::get<DiffuseDesc>(ls.scene.materials[0]).reflectance, Rgb(0.5f));
  EXPECT_EQ(ls.render.integrator, "path");
  EXPECT_EQ(ls.film.width, 1280);
  EXPECT_EQ(ls.film.height, 720);
}

TEST(SceneParse, CommentsAndLocations) {
  ParsedScene p =
      parse_scene_string("# a comment\nWorldBegin # trailing\n\n   Shape \"sphere\" # x\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  EXPECT_EQ(p.shapes[0].loc.file, "<string>");
  EXPECT_EQ(p.shapes[0].loc.line, 4);
  EXPECT_EQ(p.shapes[0].loc.column, 4);
  EXPECT_EQ(p.shapes[0].name, "sphere");
}

TEST(SceneParse, TranslateMovesShape) {
  ParsedScene p = parse_scene_string("WorldBegin\nTranslate 1 2 3\nShape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  expect_vec_near(origin_of(p.shapes[0].world_from_object), Vec3(1, 2, 3));
  LoadedScene ls = flatten_scene(p);
  ASSERT_EQ(ls.scene.objects.size(), 1u);
  ASSERT_TRUE(std::holds_alternative<Sphere>(ls.scene.objects[0].shape));
  expect_vec_near(origin_of(std::get<Sphere>(ls.scene.objects[0].shape).world_from_object),
                  Vec3(1, 2, 3));
}

TEST(SceneParse, BracketedTranslate) {
  ParsedScene p = parse_scene_string("WorldBegin\nTranslate [ -1 +2 3.5e0 ]\nShape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  expect_vec_near(origin_of(p.shapes[0].world_from_object), Vec3(-1, 2, 3.5f));
}

TEST(SceneParse, TransformsConcatenateInOrder) {
  // Translate then Scale: the scale applies first to object points.
  ParsedScene p =
      parse_scene_string("WorldBegin\nTranslate 1 0 0\nScale 2 3 4\nShape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  expect_vec_near(p.shapes[0].world_from_object.point(Vec3(1, 1, 1)), Vec3(3, 3, 4));
}

TEST(SceneParse, Scale) {
  ParsedScene p = parse_scene_string("WorldBegin\nScale 2 3 4\nShape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  expect_vec_near(p.shapes[0].world_from_object.point(Vec3(1, 1, 1)), Vec3(2, 3, 4));
}

TEST(SceneParse, RotateDegreesAboutAxis) {
  ParsedScene p = parse_scene_string("WorldBegin\nRotate 90 0 0 1\nShape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  expect_vec_near(p.shapes[0].world_from_object.point(Vec3(1, 0, 0)), Vec3(0, 1, 0));
  expect_vec_near(p.shapes[0].world_from_object.point(Vec3(0, 1, 0)), Vec3(-1, 0, 0));
}

TEST(SceneParse, LookAtMapsEyeToCameraOrigin) {
  ParsedScene p = parse_scene_string(
      "LookAt 1 2 3  1 2 10  0 1 0\nCamera \"perspective\" \"float fov\" 45\nWorldBegin\n");
  ASSERT_TRUE(p.camera.has_value());
  EXPECT_EQ(p.camera->name, "perspective");
  const Transform& cfw = p.camera->camera_from_world;
  expect_vec_near(cfw.point(Vec3(1, 2, 3)), Vec3(0, 0, 0));
  expect_vec_near(cfw.point(Vec3(1, 2, 10)), Vec3(0, 0, 7));  // looks down +z
  expect_vec_near(cfw.point(Vec3(1, 3, 3)), Vec3(0, 1, 0));   // up is +y
  expect_vec_near(cfw.point(Vec3(2, 2, 3)), Vec3(1, 0, 0));
  LoadedScene ls = flatten_scene(p);
  expect_vec_near(origin_of(ls.camera.world_from_camera), Vec3(1, 2, 3));
  EXPECT_FLOAT_EQ(ls.camera.fov_degrees, 45);
}

TEST(SceneParse, TransformReadsColumnByColumn) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\nTranslate 100 0 0\nTransform [1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1]\nShape "
      "\"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  // Transform replaces the current transform (the Translate is gone).
  expect_vec_near(origin_of(p.shapes[0].world_from_object), Vec3(5, 6, 7));
}

TEST(SceneParse, TransformNonTranslationPart) {
  // Columns: x axis -> (0 1 0), y axis -> (-1 0 0), z axis -> (0 0 1).
  ParsedScene p = parse_scene_string(
      "WorldBegin\nTransform [0 1 0 0  -1 0 0 0  0 0 1 0  0 0 0 1]\nShape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  expect_vec_near(p.shapes[0].world_from_object.point(Vec3(1, 0, 0)), Vec3(0, 1, 0));
  expect_vec_near(p.shapes[0].world_from_object.point(Vec3(0, 1, 0)), Vec3(-1, 0, 0));
}

TEST(SceneParse, ConcatTransformMultiplies) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\nTranslate 1 0 0\nConcatTransform [1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1]\nShape "
      "\"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  expect_vec_near(origin_of(p.shapes[0].world_from_object), Vec3(6, 6, 7));
}

TEST(SceneParse, IdentityResets) {
  ParsedScene p = parse_scene_string("WorldBegin\nTranslate 1 2 3\nIdentity\nShape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  EXPECT_TRUE(p.shapes[0].world_from_object.is_identity());
}

TEST(SceneParse, WorldBeginResetsTransform) {
  ParsedScene p = parse_scene_string("Translate 1 2 3\nWorldBegin\nShape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  EXPECT_TRUE(p.shapes[0].world_from_object.is_identity());
}

TEST(SceneParse, CoordinateSystemAndCoordSysTransform) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\nTranslate 1 0 0\nCoordinateSystem \"a\"\nIdentity\nTranslate 0 5 0\n"
      "CoordSysTransform \"a\"\nShape \"sphere\"\nCoordSysTransform \"world\"\nShape \"disk\"\n");
  ASSERT_EQ(p.shapes.size(), 2u);
  expect_vec_near(origin_of(p.shapes[0].world_from_object), Vec3(1, 0, 0));
  EXPECT_TRUE(p.shapes[1].world_from_object.is_identity());
}

TEST(SceneParse, CameraCoordinateSystem) {
  ParsedScene p = parse_scene_string(
      "LookAt 1 2 3  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\nCoordSysTransform "
      "\"camera\"\n"
      "Shape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  expect_vec_near(origin_of(p.shapes[0].world_from_object), Vec3(1, 2, 3));
}

TEST(SceneParse, ReverseOrientationIsPartOfAttributes) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\nAttributeBegin\nReverseOrientation\nShape \"sphere\"\nAttributeEnd\nShape "
      "\"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 2u);
  EXPECT_TRUE(p.shapes[0].reverse_orientation);
  EXPECT_FALSE(p.shapes[1].reverse_orientation);
  LoadedScene ls = flatten_scene(p);
  ASSERT_EQ(ls.scene.objects.size(), 2u);
  EXPECT_TRUE(std::get<Sphere>(ls.scene.objects[0].shape).flip_normal);
  EXPECT_FALSE(std::get<Sphere>(ls.scene.objects[1].shape).flip_normal);
}

TEST(SceneParse, ReverseOrientationAndMirrorCancel) {
  ParsedScene p =
      parse_scene_string("WorldBegin\nScale -1 1 1\nReverseOrientation\nShape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  EXPECT_TRUE(p.shapes[0].world_from_object.swaps_handedness());
  LoadedScene ls = flatten_scene(p);
  EXPECT_FALSE(std::get<Sphere>(ls.scene.objects[0].shape).flip_normal);
}

TEST(SceneParse, AttributeBeginEndRestoresTransformAndMaterial) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\nAttributeBegin\nTranslate 1 0 0\nMaterial \"conductor\"\nShape \"sphere\"\n"
      "AttributeEnd\nShape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 2u);
  expect_vec_near(origin_of(p.shapes[0].world_from_object), Vec3(1, 0, 0));
  EXPECT_EQ(p.shapes[0].material.index, 0);
  EXPECT_TRUE(p.shapes[1].world_from_object.is_identity());
  EXPECT_EQ(p.shapes[1].material.index, -1);
  LoadedScene ls = flatten_scene(p);
  ASSERT_EQ(ls.scene.objects.size(), 2u);
  EXPECT_TRUE(
      std::holds_alternative<ConductorDesc>(ls.scene.materials[ls.scene.objects[0].material]));
  EXPECT_EQ(ls.scene.objects[1].material, 0);  // the default diffuse material
}

TEST(SceneParse, TransformBeginEndRestoresOnlyTransform) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\nTransformBegin\nTranslate 1 0 0\nMaterial \"conductor\"\nReverseOrientation\n"
      "TransformEnd\nShape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  EXPECT_TRUE(p.shapes[0].world_from_object.is_identity());
  EXPECT_EQ(p.shapes[0].material.index, 0);
  EXPECT_TRUE(p.shapes[0].reverse_orientation);
}

TEST(SceneParse, NestedAttributes) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\nAttributeBegin\nTranslate 1 0 0\nAttributeBegin\nTranslate 0 1 0\nShape "
      "\"sphere\"\n"
      "AttributeEnd\nShape \"sphere\"\nAttributeEnd\nShape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 3u);
  expect_vec_near(origin_of(p.shapes[0].world_from_object), Vec3(1, 1, 0));
  expect_vec_near(origin_of(p.shapes[1].world_from_object), Vec3(1, 0, 0));
  expect_vec_near(origin_of(p.shapes[2].world_from_object), Vec3(0, 0, 0));
}

TEST(SceneParse, CameraParameters) {
  ParsedScene p = parse_scene_string(
      "Camera \"perspective\" \"float fov\" 30 \"float lensradius\" 0.1 \"float focaldistance\" "
      "4\nWorldBegin\n");
  ASSERT_TRUE(p.camera.has_value());
  EXPECT_EQ(p.camera->loc.line, 1);
  LoadedScene ls = flatten_scene(p);
  EXPECT_FLOAT_EQ(ls.camera.fov_degrees, 30);
  EXPECT_FLOAT_EQ(ls.camera.lens_radius, 0.1f);
  EXPECT_FLOAT_EQ(ls.camera.focal_distance, 4);
  EXPECT_TRUE(ls.camera.world_from_camera.is_identity());
}

TEST(SceneParse, Film) {
  ParsedScene p = parse_scene_string(
      "Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" [32] \"string filename\" "
      "\"out.exr\"\n"
      "WorldBegin\n");
  EXPECT_EQ(p.film.name, "rgb");
  LoadedScene ls = flatten_scene(p);
  EXPECT_EQ(ls.film.width, 64);
  EXPECT_EQ(ls.film.height, 32);
  EXPECT_EQ(ls.film.filename, "out.exr");
}

TEST(SceneParse, Sampler) {
  LoadedScene ls = flatten_scene(parse_scene_string(
      "Sampler \"independent\" \"integer pixelsamples\" 4 \"integer seed\" 9\nWorldBegin\n"));
  EXPECT_EQ(ls.render.spp, 4);
  EXPECT_EQ(ls.render.seed, 9);
  LoadedScene st = flatten_scene(parse_scene_string(
      "Sampler \"stratified\" \"integer xsamples\" 2 \"integer ysamples\" 3\nWorldBegin\n"));
  EXPECT_EQ(st.render.spp, 6);
}

TEST(SceneParse, PixelFilter) {
  LoadedScene box = flatten_scene(parse_scene_string("PixelFilter \"box\"\nWorldBegin\n"));
  EXPECT_EQ(box.filter.type, FilterType::kBox);
  EXPECT_FLOAT_EQ(box.filter.radius.x, 0.5f);
  LoadedScene tri = flatten_scene(
      parse_scene_string("PixelFilter \"triangle\" \"float xradius\" 1\nWorldBegin\n"));
  EXPECT_EQ(tri.filter.type, FilterType::kTriangle);
  EXPECT_FLOAT_EQ(tri.filter.radius.x, 1);
  EXPECT_FLOAT_EQ(tri.filter.radius.y, 2);
  LoadedScene mit = flatten_scene(parse_scene_string(
      "PixelFilter \"mitchell\" \"float B\" 0.5 \"float C\" 0.25\nWorldBegin\n"));
  EXPECT_EQ(mit.filter.type, FilterType::kMitchell);
  EXPECT_FLOAT_EQ(mit.filter.b, 0.5f);
  EXPECT_FLOAT_EQ(mit.filter.c, 0.25f);
}

TEST(SceneParse, Integrator) {
  ParsedScene p = parse_scene_string("Integrator \"bpm\" \"integer maxdepth\" 7\nWorldBegin\n");
  EXPECT_TRUE(p.integrator_given);
  EXPECT_EQ(p.integrator.name, "bpm");
  LoadedScene ls = flatten_scene(p);
  EXPECT_EQ(ls.render.integrator, "bpm");
  EXPECT_EQ(ls.render.integrator_as_written, "bpm");
  EXPECT_EQ(ls.render.max_depth, 7);
}

TEST(SceneParse, VolpathIntegratorIsRenderedAsPathWithANote) {
  ParsedScene p = parse_scene_string("Integrator \"volpath\" \"integer maxdepth\" 3\nWorldBegin\n");
  int before = warning_count();
  LoadedScene ls = flatten_scene(p);
  EXPECT_EQ(warning_count() - before, 0);  // the program prints the note unless --integrator
  EXPECT_EQ(ls.render.integrator, "path");
  EXPECT_EQ(ls.render.integrator_as_written, "volpath");
  EXPECT_NE(ls.render.integrator_note.find("volpath"), std::string::npos);
  EXPECT_EQ(ls.render.max_depth, 3);
  // pbrt-v4's default (no Integrator line) is volpath: path, without a note.
  LoadedScene none = flatten_scene(parse_scene_string("WorldBegin\n"));
  EXPECT_EQ(none.render.integrator, "path");
  EXPECT_TRUE(none.render.integrator_note.empty());
}

// Integrators that carry light from the lights' side reach caustics a path tracer misses: bpm.
TEST(SceneParse, BidirectionalAndPhotonIntegratorsAreRenderedWithBpm) {
  for (const char* name : {"bdpt", "mlt", "lightpath", "sppm"}) {
    LoadedScene ls =
        flatten_scene(parse_scene_string(std::string("Integrator \"") + name + "\"\nWorldBegin\n"));
    EXPECT_EQ(ls.render.integrator, "bpm") << name;
    EXPECT_NE(ls.render.integrator_note.find(name), std::string::npos) << name;
  }
}

// ... but a glowing medium is path's alone: such a scene renders with path, and the note says why.
TEST(SceneParse, GlowingMediaAreRenderedWithPath) {
  const LoadedScene ls = flatten_scene(
      parse_scene_string("Integrator \"bdpt\"\nMakeNamedMedium \"m\" \"string type\" "
                         "\"homogeneous\" \"rgb Le\" [1 1 1]\n"
                         "WorldBegin\nMediumInterface \"m\" \"\"\nShape \"sphere\"\n"));
  EXPECT_EQ(ls.render.integrator, "path");
  EXPECT_NE(ls.render.integrator_note.find("glows"), std::string::npos);
}

TEST(SceneParse, AcceleratorIsAcceptedAndIgnored) {
  int before = warning_count();
  ParsedScene p =
      parse_scene_string("Accelerator \"bvh\" \"integer maxnodeprims\" 4\nWorldBegin\n");
  (void)flatten_scene(p);
  EXPECT_EQ(warning_count(), before);
  EXPECT_EQ(p.film.name, "rgb");
  EXPECT_EQ(p.integrator.name, "volpath");
  EXPECT_TRUE(IsError(parse_error_of("WorldBegin\nAccelerator \"bvh\"\n"), at(2, 1),
                      "Accelerator is not allowed after WorldBegin"));
}

TEST(SceneParse, ColorSpaceSrgbAccepted) {
  ParsedScene p = parse_scene_string("ColorSpace \"srgb\"\nWorldBegin\nShape \"sphere\"\n");
  EXPECT_EQ(p.shapes.size(), 1u);
}

TEST(SceneParse, OptionWarns) {
  int before = warning_count();
  ParsedScene p =
      parse_scene_string("Option \"bool disablepixeljitter\" true\nWorldBegin\nShape \"sphere\"\n");
  EXPECT_EQ(warning_count() - before, 1);
  EXPECT_EQ(p.shapes.size(), 1u);
}

TEST(SceneParse, WorldEndAccepted) {
  ParsedScene p = parse_scene_string("WorldBegin\nShape \"sphere\"\nWorldEnd\n");
  EXPECT_EQ(p.shapes.size(), 1u);
}

TEST(SceneParse, AttributeDirectiveWarnsAndIsIgnored) {
  int before = warning_count();
  ParsedScene p = parse_scene_string(
      "WorldBegin\nAttribute \"shape\" \"float radius\" 2 \"float zmin\" 0\nShape \"sphere\"\n");
  EXPECT_EQ(warning_count() - before, 2);
  LoadedScene ls = flatten_scene(p);
  ASSERT_EQ(ls.scene.objects.size(), 1u);
  EXPECT_FLOAT_EQ(std::get<Sphere>(ls.scene.objects[0].shape).radius, 1);
}

TEST(SceneParse, MaterialAppliesToFollowingShapes) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\nMaterial \"diffuse\" \"rgb reflectance\" [0.1 0.2 0.3]\nShape \"sphere\"\nShape "
      "\"disk\"\n"
      "Material \"dielectric\" \"float eta\" 1.33\nShape \"sphere\"\n");
  ASSERT_EQ(p.materials.size(), 2u);
  EXPECT_EQ(p.materials[0].name, "diffuse");
  EXPECT_EQ(p.materials[1].name, "dielectric");
  ASSERT_EQ(p.shapes.size(), 3u);
  EXPECT_EQ(p.shapes[0].material.index, 0);
  EXPECT_EQ(p.shapes[1].material.index, 0);
  EXPECT_EQ(p.shapes[2].material.index, 1);
  LoadedScene ls = flatten_scene(p);
  ASSERT_EQ(ls.scene.objects.size(), 3u);
  EXPECT_EQ(ls.scene.objects[0].material, ls.scene.objects[1].material);  // shared, not duplicated
  const MaterialDesc& m0 = ls.scene.materials[ls.scene.objects[0].material];
  ASSERT_TRUE(std::holds_alternative<DiffuseDesc>(m0));
  expect_spectrum_near(std::get<DiffuseDesc>(m0).reflectance, Rgb(0.1f, 0.2f, 0.3f));
  const MaterialDesc& m2 = ls.scene.materials[ls.scene.objects[2].material];
  ASSERT_TRUE(std::holds_alternative<DielectricMaterial>(m2));
  EXPECT_FLOAT_EQ(std::get<DielectricMaterial>(m2).eta, 1.33f);
}

TEST(SceneParse, NamedMaterialResolvesAtFlatten) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\nMakeNamedMaterial \"gold\" \"string type\" \"conductor\" \"spectrum eta\" "
      "\"metal-Au-eta\" "
      "\"spectrum k\" \"metal-Au-k\" \"float roughness\" 0.04\n"
      "NamedMaterial \"gold\"\nShape \"sphere\"\nShape \"disk\"\n");
  ASSERT_EQ(p.named_materials.count("gold"), 1u);
  EXPECT_EQ(p.named_materials.at("gold").name, "conductor");
  ASSERT_EQ(p.shapes.size(), 2u);
  EXPECT_EQ(p.shapes[0].material.named, "gold");
  EXPECT_EQ(p.shapes[0].material.index, -1);
  LoadedScene ls = flatten_scene(p);
  ASSERT_EQ(ls.scene.objects.size(), 2u);
  EXPECT_EQ(ls.scene.objects[0].material, ls.scene.objects[1].material);
  const MaterialDesc& m = ls.scene.materials[ls.scene.objects[0].material];
  ASSERT_TRUE(std::holds_alternative<ConductorDesc>(m));
  const ConductorDesc& c = std::get<ConductorDesc>(m);
  expect_spectrum_near(c.eta, *named_spectrum("metal-Au-eta", SpectrumKind::kUnbounded));
  expect_spectrum_near(c.k, *named_spectrum("metal-Au-k", SpectrumKind::kUnbounded));
  EXPECT_NEAR(c.roughness.alpha_x, 0.2f, 1e-6f);  // remapped: sqrt(0.04)
  EXPECT_NEAR(c.roughness.alpha_y, 0.2f, 1e-6f);
}

TEST(SceneParse, NamedMaterialMayBeDefinedAfterUse) {
  LoadedScene ls =
      flatten_scene(parse_scene_string("WorldBegin\nNamedMaterial \"glass\"\nShape \"sphere\"\n"
                                       "MakeNamedMaterial \"glass\" \"string type\" \"dielectric\" "
                                       "\"spectrum eta\" \"glass-BK7\"\n"));
  ASSERT_EQ(ls.scene.objects.size(), 1u);
  const MaterialDesc& m = ls.scene.materials[ls.scene.objects[0].material];
  ASSERT_TRUE(std::holds_alternative<DielectricMaterial>(m));
  EXPECT_NEAR(std::get<DielectricMaterial>(m).eta, 1.5168f, 1e-5f);
}

TEST(SceneParse, ConductorDefaultsToCopper) {
  LoadedScene ls =
      flatten_scene(parse_scene_string("WorldBegin\nMaterial \"conductor\"\nShape \"sphere\"\n"));
  const MaterialDesc& m = ls.scene.materials[ls.scene.objects[0].material];
  ASSERT_TRUE(std::holds_alternative<ConductorDesc>(m));
  expect_spectrum_near(std::get<ConductorDesc>(m).eta,
                       *named_spectrum("metal-Cu-eta", SpectrumKind::kUnbounded));
  expect_spectrum_near(std::get<ConductorDesc>(m).k,
                       *named_spectrum("metal-Cu-k", SpectrumKind::kUnbounded));
}

TEST(SceneParse, ConstantTextures) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\n"
      "Texture \"tex\" \"spectrum\" \"constant\" \"rgb value\" [0.2 0.3 0.4]\n"
      "Texture \"grey\" \"float\" \"constant\" \"float value\" 0.7\n"
      "Texture \"rough\" \"float\" \"constant\" \"float value\" 0.25\n"
      "Texture \"old\" \"color\" \"constant\" \"rgb value\" [0.5 0.5 0.5]\n"
      "Material \"diffuse\" \"texture reflectance\" \"tex\"\nShape \"sphere\"\n"
      "Material \"diffuse\" \"texture reflectance\" \"grey\"\nShape \"sphere\"\n"
      "Material \"conductor\" \"texture roughness\" \"rough\" \"bool remaproughness\" false\nShape "
      "\"sphere\"\n");
  ASSERT_EQ(p.textures.size(), 4u);
  EXPECT_EQ(p.textures[0].texture_name, "tex");
  EXPECT_EQ(p.textures[0].value_type, "spectrum");
  EXPECT_EQ(p.textures[0].name, "constant");
  EXPECT_EQ(p.textures[1].value_type, "float");
  EXPECT_EQ(p.textures[3].value_type, "spectrum");  // "color" is the old name
  LoadedScene ls = flatten_scene(p);
  ASSERT_EQ(ls.scene.objects.size(), 3u);
  const MaterialDesc& m0 = ls.scene.materials[ls.scene.objects[0].material];
  ASSERT_TRUE(std::holds_alternative<DiffuseDesc>(m0));
  expect_spectrum_near(std::get<DiffuseDesc>(m0).reflectance, Rgb(0.2f, 0.3f, 0.4f));
  const MaterialDesc& m1 = ls.scene.materials[ls.scene.objects[1].material];
  ASSERT_TRUE(std::holds_alternative<DiffuseDesc>(m1));
  expect_spectrum_near(std::get<DiffuseDesc>(m1).reflectance, Rgb(0.7f));
  const MaterialDesc& m2 = ls.scene.materials[ls.scene.objects[2].material];
  ASSERT_TRUE(std::holds_alternative<ConductorDesc>(m2));
  EXPECT_FLOAT_EQ(std::get<ConductorDesc>(m2).roughness.alpha_x, 0.25f);
  EXPECT_FLOAT_EQ(std::get<ConductorDesc>(m2).roughness.alpha_y, 0.25f);
}

TEST(SceneParse, PointLight) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\nTranslate 1 0 0\nLightSource \"point\" \"rgb I\" [1 2 3] \"point3 from\" [1 2 "
      "3]\n");
  ASSERT_EQ(p.lights.size(), 1u);
  EXPECT_EQ(p.lights[0].name, "point");
  expect_vec_near(origin_of(p.lights[0].world_from_light), Vec3(1, 0, 0));
  LoadedScene ls = flatten_scene(p);
  ASSERT_EQ(ls.scene.lights.size(), 1u);
  ASSERT_TRUE(std::holds_alternative<PointLight>(ls.scene.lights[0]));
  const PointLight& l = std::get<PointLight>(ls.scene.lights[0]);
  expect_vec_near(l.position, Vec3(2, 2, 3));
  expect_spectrum_near(l.intensity, Rgb(1, 2, 3));
}

TEST(SceneParse, DistantAndInfiniteLights) {
  LoadedScene ls = flatten_scene(
      parse_scene_string("WorldBegin\nLightSource \"distant\" \"point3 from\" [0 10 0] \"point3 "
                         "to\" [0 0 0] \"rgb L\" [1 1 1]\n"
                         "LightSource \"infinite\" \"rgb L\" [0.1 0.2 0.3] \"float scale\" 2\n"));
  ASSERT_EQ(ls.scene.lights.size(), 2u);
  ASSERT_TRUE(std::holds_alternative<DistantLight>(ls.scene.lights[0]));
  expect_vec_near(std::get<DistantLight>(ls.scene.lights[0]).direction_to_light, Vec3(0, 1, 0));
  ASSERT_TRUE(std::holds_alternative<UniformInfiniteLight>(ls.scene.lights[1]));
  expect_spectrum_near(std::get<UniformInfiniteLight>(ls.scene.lights[1]).radiance,
                       Rgb(0.2f, 0.4f, 0.6f));
  ASSERT_EQ(ls.scene.infinite_lights.size(), 1u);
  EXPECT_EQ(ls.scene.infinite_lights[0], 1);
}

TEST(SceneParse, SpotLight) {
  LoadedScene ls =
      flatten_scene(parse_scene_string("WorldBegin\nLightSource \"spot\" \"point3 from\" [0 0 5] "
                                       "\"point3 to\" [0 0 0] \"float coneangle\" 60 "
                                       "\"float conedeltaangle\" 10\n"));
  ASSERT_EQ(ls.scene.lights.size(), 1u);
  ASSERT_TRUE(std::holds_alternative<SpotLight>(ls.scene.lights[0]));
  const SpotLight& s = std::get<SpotLight>(ls.scene.lights[0]);
  expect_vec_near(s.position, Vec3(0, 0, 5));
  expect_vec_near(s.frame.n, Vec3(0, 0, -1));
  EXPECT_NEAR(s.cos_falloff_end, 0.5f, 1e-5f);
  EXPECT_NEAR(s.cos_falloff_start, std::cos(50 * kPi / 180), 1e-5f);
}

TEST(SceneParse, AreaLightOnMesh) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 2 3] \"bool twosided\" "
      "true\n"
      "Shape \"trianglemesh\" \"point3 P\" [0 0 0  1 0 0  1 1 0  0 1 0] \"integer indices\" [0 1 2 "
      " 0 2 3]\n"
      "AttributeEnd\nShape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 2u);
  ASSERT_TRUE(p.shapes[0].area_light.has_value());
  EXPECT_EQ(p.shapes[0].area_light->name, "diffuse");
  EXPECT_FALSE(p.shapes[1].area_light.has_value());
  LoadedScene ls = flatten_scene(p);
  ASSERT_EQ(ls.scene.objects.size(), 2u);
  EXPECT_EQ(ls.scene.objects[0].first_light, 0);
  EXPECT_EQ(ls.scene.objects[1].first_light, -1);
  ASSERT_EQ(ls.scene.lights.size(), 2u);  // one per triangle
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(std::holds_alternative<AreaLight>(ls.scene.lights[i]));
    const AreaLight& a = std::get<AreaLight>(ls.scene.lights[i]);
    EXPECT_EQ(a.object, 0);
    EXPECT_EQ(a.primitive, i);
    EXPECT_TRUE(a.two_sided);
    EXPECT_NEAR(a.area, 0.5f, 1e-6f);
    expect_spectrum_near(a.radiance, Rgb(1, 2, 3));
  }
}

TEST(SceneParse, AreaLightOnWholeSphere) {
  LoadedScene ls = flatten_scene(
      parse_scene_string("WorldBegin\nAreaLightSource \"diffuse\" \"rgb L\" [4 4 4] \"float "
                         "scale\" 0.5\nShape \"sphere\" \"float radius\" 2\n"));
  ASSERT_EQ(ls.scene.lights.size(), 1u);
  ASSERT_TRUE(std::holds_alternative<AreaLight>(ls.scene.lights[0]));
  const AreaLight& a = std::get<AreaLight>(ls.scene.lights[0]);
  expect_spectrum_near(a.radiance, Rgb(2.0f));
  EXPECT_FALSE(a.two_sided);
  EXPECT_NEAR(a.area, 4 * kPi * 4, 1e-3f);
}

TEST(SceneParse, Shapes) {
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\n"
      "Shape \"sphere\" \"float radius\" 2 \"float zmin\" -1 \"float zmax\" 1.5 \"float phimax\" "
      "180\n"
      "Shape \"disk\" \"float radius\" 3 \"float innerradius\" 1 \"float height\" 0.5\n"
      "Shape \"trianglemesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0] \"point2 uv\" [0 0 1 0 0 1]\n"
      "Shape \"bilinearmesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0  1 1 0]\n"
      "Shape \"cylinder\" \"float radius\" 0.5 \"float zmin\" 2 \"float zmax\" -1 \"float phimax\" "
      "90\n"
      "ReverseOrientation\nShape \"cylinder\"\n"));
  ASSERT_EQ(ls.scene.objects.size(), 6u);
  const Sphere& s = std::get<Sphere>(ls.scene.objects[0].shape);
  EXPECT_FLOAT_EQ(s.radius, 2);
  EXPECT_FLOAT_EQ(s.z_min, -1);
  EXPECT_FLOAT_EQ(s.z_max, 1.5f);
  EXPECT_NEAR(s.phi_max, kPi, 1e-6f);
  EXPECT_FALSE(s.is_full());
  const Disk& d = std::get<Disk>(ls.scene.objects[1].shape);
  EXPECT_FLOAT_EQ(d.radius, 3);
  EXPECT_FLOAT_EQ(d.inner_radius, 1);
  EXPECT_FLOAT_EQ(d.height, 0.5f);
  const TriangleMesh& t = std::get<TriangleMesh>(ls.scene.objects[2].shape);
  EXPECT_EQ(t.positions.size(), 3u);
  EXPECT_EQ(t.indices, (std::vector<uint32_t>{0, 1, 2}));  // implied for a single triangle
  ASSERT_EQ(t.uvs.size(), 3u);
  EXPECT_FLOAT_EQ(t.uvs[1].x, 1);
  EXPECT_FLOAT_EQ(t.uvs[2].y, 1);
  const TriangleMesh& b = std::get<TriangleMesh>(ls.scene.objects[3].shape);
  EXPECT_EQ(b.triangle_count(), 2);
  const Cylinder& c = std::get<Cylinder>(ls.scene.objects[4].shape);
  EXPECT_FLOAT_EQ(c.radius, 0.5f);
  EXPECT_FLOAT_EQ(c.z_min, -1);  // pbrt-v4 orders zmin and zmax
  EXPECT_FLOAT_EQ(c.z_max, 2);
  EXPECT_NEAR(c.phi_max, kPi / 2, 1e-6f);
  EXPECT_FALSE(c.flip_normal);
  const Cylinder& c2 = std::get<Cylinder>(ls.scene.objects[5].shape);
  EXPECT_FLOAT_EQ(c2.radius, 1);  // pbrt-v4's defaults
  EXPECT_FLOAT_EQ(c2.z_min, -1);
  EXPECT_FLOAT_EQ(c2.z_max, 1);
  EXPECT_NEAR(c2.phi_max, 2 * kPi, 1e-6f);
  EXPECT_TRUE(c2.flip_normal);
}

TEST(SceneParse, TriangleMeshTransformsPositionsAndNormals) {
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nTranslate 0 0 5\nRotate 90 0 0 1\n"
      "Shape \"trianglemesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0] \"integer indices\" [0 1 2] "
      "\"normal N\" [1 0 0  1 0 0  2 0 0]\n"));
  ASSERT_EQ(ls.scene.objects.size(), 1u);
  const TriangleMesh& m = std::get<TriangleMesh>(ls.scene.objects[0].shape);
  ASSERT_EQ(m.positions.size(), 3u);
  expect_vec_near(m.positions[0], Vec3(0, 0, 5));
  expect_vec_near(m.positions[1], Vec3(0, 1, 5));
  ASSERT_EQ(m.normals.size(), 3u);
  for (Vec3 n : m.normals) expect_vec_near(n, Vec3(0, 1, 0));  // rotated and normalised
}

TEST(SceneParse, ObjectInstancesCopyShapesWithInstanceTransform) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\n"
      "ObjectBegin \"thing\"\nTranslate 1 0 0\nShape \"sphere\"\nShape \"disk\"\nObjectEnd\n"
      "Translate 0 10 0\nObjectInstance \"thing\"\n"
      "Translate 0 0 100\nObjectInstance \"thing\"\n");
  // The definition itself adds nothing; each instance adds both shapes.
  ASSERT_EQ(p.shapes.size(), 4u);
  EXPECT_EQ(p.shapes[0].name, "sphere");
  EXPECT_EQ(p.shapes[1].name, "disk");
  expect_vec_near(origin_of(p.shapes[0].world_from_object), Vec3(1, 10, 0));
  expect_vec_near(origin_of(p.shapes[1].world_from_object), Vec3(1, 10, 0));
  expect_vec_near(origin_of(p.shapes[2].world_from_object), Vec3(1, 10, 100));
  expect_vec_near(origin_of(p.shapes[3].world_from_object), Vec3(1, 10, 100));
  LoadedScene ls = flatten_scene(p);
  ASSERT_EQ(ls.scene.objects.size(), 4u);
  expect_vec_near(origin_of(std::get<Sphere>(ls.scene.objects[2].shape).world_from_object),
                  Vec3(1, 10, 100));
}

TEST(SceneParse, IncludeAndImport) {
  TempDir dir;
  dir.write("inc.pbrt", "# included\nShape \"sphere\" \"float radius\" 3\n");
  dir.write("imp.pbrt", "Shape \"disk\"\n");
  ParsedScene p = parse_scene_string(
      "WorldBegin\nTranslate 1 0 0\nInclude \"inc.pbrt\"\nImport \"imp.pbrt\"\nShape \"sphere\"\n",
      dir.str());
  ASSERT_EQ(p.shapes.size(), 3u);
  EXPECT_EQ(p.shapes[0].name, "sphere");
  EXPECT_TRUE(Contains(p.shapes[0].loc.file, "inc.pbrt"));
  EXPECT_EQ(p.shapes[0].loc.line, 2);
  EXPECT_TRUE(fs::equivalent(p.shapes[0].directory, dir.path()));
  expect_vec_near(origin_of(p.shapes[0].world_from_object), Vec3(1, 0, 0));
  EXPECT_EQ(p.shapes[1].name, "disk");
  EXPECT_TRUE(Contains(p.shapes[1].loc.file, "imp.pbrt"));
  EXPECT_EQ(p.shapes[2].loc.file, "<string>");
  EXPECT_EQ(p.shapes[2].loc.line, 5);
  LoadedScene ls = flatten_scene(p);
  EXPECT_FLOAT_EQ(std::get<Sphere>(ls.scene.objects[0].shape).radius, 3);
}

TEST(SceneParse, IncludedFileMayChangeGraphicsState) {
  TempDir dir;
  dir.write("state.pbrt", "Translate 0 2 0\nMaterial \"conductor\"\n");
  ParsedScene p =
      parse_scene_string("WorldBegin\nInclude \"state.pbrt\"\nShape \"sphere\"\n", dir.str());
  ASSERT_EQ(p.shapes.size(), 1u);
  expect_vec_near(origin_of(p.shapes[0].world_from_object), Vec3(0, 2, 0));
  EXPECT_EQ(p.shapes[0].material.index, 0);
}

// The last directive of an included file has no parameters, so looking for them reads past the
// end of that file. Under a sanitizer build this also checks that nothing of the finished file is
// used afterwards.
TEST(SceneParse, IncludedFileEndingWithParameterlessDirectives) {
  TempDir dir;
  dir.write("settings.pbrt",
            "# render settings kept apart from the geometry of the scene\n"
            "Film \"rgb\" \"integer xresolution\" 40 \"integer yresolution\" 30\n"
            "Sampler \"halton\"\n");
  dir.write("geometry.pbrt", "# geometry\nShape \"sphere\"\n");
  ParsedScene p = parse_scene_string(
      "Include \"settings.pbrt\"\nWorldBegin\nInclude \"geometry.pbrt\"\nShape \"disk\"\n",
      dir.str());
  EXPECT_EQ(p.sampler.name, "halton");
  EXPECT_EQ(p.film.name, "rgb");
  ASSERT_EQ(p.shapes.size(), 2u);
  EXPECT_EQ(p.shapes[0].name, "sphere");
  EXPECT_EQ(p.shapes[1].name, "disk");
  LoadedScene ls = flatten_scene(p);
  EXPECT_EQ(ls.film.width, 40);
  EXPECT_EQ(ls.film.height, 30);
}

// As in pbrt-v4, relative file names resolve against the main scene file's directory, whichever
// file names them, and whether or not the shape is the last directive of an included file.
TEST(SceneParse, ShapesOfAnIncludedFileResolveAgainstTheMainDirectory) {
  TempDir dir;
  dir.write("sub/quad.ply", kAsciiQuadPly);
  dir.write("sub/geometry.pbrt",
            "Shape \"plymesh\" \"string filename\" \"sub/quad.ply\"\n"
            "Shape \"plymesh\" \"string filename\" \"sub/quad.ply\"\n");
  ParsedScene p = parse_scene_string("WorldBegin\nInclude \"sub/geometry.pbrt\"\n", dir.str());
  ASSERT_EQ(p.shapes.size(), 2u);
  EXPECT_TRUE(fs::equivalent(p.shapes[0].directory, dir.path())) << p.shapes[0].directory;
  EXPECT_TRUE(fs::equivalent(p.shapes[1].directory, dir.path())) << p.shapes[1].directory;
  LoadedScene ls = flatten_scene(p);
  EXPECT_EQ(ls.scene.objects.size(), 2u);
}

TEST(SceneParse, SameFileIncludedTwiceIsNotACycle) {
  TempDir dir;
  dir.write("one.pbrt", "Shape \"sphere\"\n");
  ParsedScene p =
      parse_scene_string("WorldBegin\nInclude \"one.pbrt\"\nInclude \"one.pbrt\"\n", dir.str());
  EXPECT_EQ(p.shapes.size(), 2u);
}

TEST(SceneParse, ParseSceneFileResolvesRelativeToItsDirectory) {
  TempDir dir;
  dir.write("quad.ply", kAsciiQuadPly);
  fs::path main = dir.write(
      "main.pbrt",
      "WorldBegin\nTranslate 0 0 2\nShape \"plymesh\" \"string filename\" \"quad.ply\"\n");
  ParsedScene p = parse_scene_file(main.string());
  EXPECT_TRUE(fs::equivalent(p.base_directory, dir.path()));
  ASSERT_EQ(p.shapes.size(), 1u);
  EXPECT_TRUE(Contains(p.shapes[0].loc.file, "main.pbrt"));
  LoadedScene ls = flatten_scene(p);
  ASSERT_EQ(ls.scene.objects.size(), 1u);
  const TriangleMesh& m = std::get<TriangleMesh>(ls.scene.objects[0].shape);
  EXPECT_EQ(m.triangle_count(), 2);
  ASSERT_EQ(m.positions.size(), 4u);
  expect_vec_near(m.positions[2], Vec3(1, 1, 2));
}

TEST(SceneParse, MediaAreReadAndAbsorbingOnesAttachToShapes) {
  int before = warning_count();
  ParsedScene p = parse_scene_string(
      "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_s\" [1 1 1]\n"
      "MakeNamedMedium \"ink\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.5 0.2 0.4]\n"
      "  \"rgb sigma_s\" [0 0 0] \"float scale\" 2\nWorldBegin\n"
      "AttributeBegin\nMediumInterface \"ink\" \"\"\nShape \"sphere\"\nAttributeEnd\n"
      "MediumInterface \"\" \"ink\"\nShape \"sphere\"\nMediumInterface \"ink\"\nShape "
      "\"sphere\"\n");
  ASSERT_EQ(p.media.size(), 2u);
  EXPECT_EQ(p.media.at("fog").name, "homogeneous");
  ASSERT_EQ(p.shapes.size(), 3u);
  EXPECT_EQ(p.shapes[0].medium.inside, "ink");
  EXPECT_EQ(p.shapes[0].medium.outside, "");
  EXPECT_EQ(p.shapes[2].medium.outside, "ink");  // one name: both sides
  // The unused scattering medium is no error; the used one is absorbing, scaled.
  LoadedScene ls = flatten_scene(p);
  EXPECT_EQ(warning_count(), before);
  ASSERT_EQ(ls.scene.media.size(), 1u);
  expect_spectrum_near(ls.scene.media[0].sigma_a, Rgb(1.0f, 0.4f, 0.8f), 2e-3f);
  EXPECT_EQ(ls.scene.objects[0].medium_inside, 0);
  EXPECT_EQ(ls.scene.objects[0].medium_outside, -1);
  EXPECT_EQ(ls.scene.objects[1].medium_inside, -1);
  EXPECT_EQ(ls.scene.objects[1].medium_outside, 0);
  EXPECT_EQ(ls.scene.objects[2].medium_inside, 0);
  EXPECT_EQ(ls.scene.objects[2].medium_outside, 0);
}

TEST(SceneParse, EmptyMediumInterfaceIsAccepted) {
  ParsedScene p = parse_scene_string("WorldBegin\nMediumInterface \"\" \"\"\nShape \"sphere\"\n");
  EXPECT_EQ(p.shapes.size(), 1u);
}

TEST(SceneParse, ActiveTransformEndTimeIsIgnored) {
  int before = warning_count();
  ParsedScene p = parse_scene_string(
      "WorldBegin\nActiveTransform EndTime\nTranslate 5 0 0\nActiveTransform All\nTranslate 0 1 0\n"
      "ActiveTransform StartTime\nTranslate 0 0 2\nActiveTransform All\nShape \"sphere\"\n");
  EXPECT_EQ(warning_count() - before, 1);  // the EndTime Translate
  ASSERT_EQ(p.shapes.size(), 1u);
  expect_vec_near(origin_of(p.shapes[0].world_from_object), Vec3(0, 1, 2));
}

TEST(SceneParse, TransformTimesAccepted) {
  ParsedScene p =
      parse_scene_string("TransformTimes 0 1\nWorldBegin\nTranslate 1 0 0\nShape \"sphere\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  expect_vec_near(origin_of(p.shapes[0].world_from_object), Vec3(1, 0, 0));
}

// ---------------------------------------------------------------------------------------------
// Typed parameters

TEST(SceneParams, AllTypes) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\nShape \"anything\"\n"
      "  \"float f\" 1.5  \"float fs\" [1 2 3]  \"integer i\" [1 -2 3]  \"integer one\" 7\n"
      "  \"bool b1\" \"true\"  \"bool b2\" false  \"bool b3\" true  \"bool bs\" [\"false\" true]\n"
      "  \"string s\" \"hello world\"  \"string esc\" \"a\\\"b\"\n"
      "  \"rgb c\" [0.1 0.2 0.3]  \"color col\" [0.4 0.5 0.6]\n"
      "  \"spectrum named\" \"metal-Cu-eta\"  \"spectrum pairs\" [400 0.5 700 0.25]\n"
      "  \"blackbody bb\" 6500  \"blackbody bb2\" [3000 2]\n"
      "  \"point2 p2\" [1 2 3 4]  \"vector2 v2\" [5 6]\n"
      "  \"point3 p3\" [1 2 3]  \"point pt\" [4 5 6]\n"
      "  \"vector3 v3\" [0 0 1]  \"vector vv\" [7 8 9]\n"
      "  \"normal n\" [0 1 0]  \"normal3 n3\" [1 0 0]\n"
      "  \"texture tx\" \"mytex\"\n");
  ASSERT_EQ(p.shapes.size(), 1u);
  const ParamSet& ps = p.shapes[0].params;
  EXPECT_EQ(ps.all().size(), 25u);

  EXPECT_FLOAT_EQ(ps.get_float("f", 0), 1.5f);
  EXPECT_FLOAT_EQ(ps.get_float("absent", 4.5f), 4.5f);
  EXPECT_EQ(ps.get_floats("fs"), (std::vector<float>{1, 2, 3}));
  EXPECT_EQ(ps.get_ints("i"), (std::vector<int>{1, -2, 3}));
  EXPECT_EQ(ps.get_int("one", 0), 7);

  EXPECT_TRUE(ps.get_bool("b1", false));
  EXPECT_FALSE(ps.get_bool("b2", true));
  EXPECT_TRUE(ps.get_bool("b3", false));
  ASSERT_NE(ps.find("bs", "bool"), nullptr);
  EXPECT_EQ(ps.find("bs", "bool")->bools, (std::vector<bool>{false, true}));

  EXPECT_EQ(ps.get_string("s", ""), "hello world");
  EXPECT_EQ(ps.get_string("esc", ""), "a\"b");

  ASSERT_NE(ps.find("c", "rgb"), nullptr);
  EXPECT_EQ(ps.find("c", "rgb")->numbers, (std::vector<double>{0.1, 0.2, 0.3}));
  ASSERT_NE(ps.find("col", "rgb"), nullptr);  // "color" is an alias of rgb
  EXPECT_EQ(ps.find("col", "rgb")->numbers, (std::vector<double>{0.4, 0.5, 0.6}));

  const Param* named = ps.find("named", "spectrum");
  ASSERT_NE(named, nullptr);
  EXPECT_EQ(named->strings, (std::vector<std::string>{"metal-Cu-eta"}));
  EXPECT_TRUE(named->numbers.empty());
  const Param* pairs = ps.find("pairs", "spectrum");
  ASSERT_NE(pairs, nullptr);
  EXPECT_EQ(pairs->numbers, (std::vector<double>{400, 0.5, 700, 0.25}));

  ASSERT_NE(ps.find("bb", "blackbody"), nullptr);
  EXPECT_EQ(ps.find("bb", "blackbody")->numbers, (std::vector<double>{6500}));
  EXPECT_EQ(ps.find("bb2", "blackbody")->numbers, (std::vector<double>{3000, 2}));

  auto p2 = ps.get_point2s("p2");
  ASSERT_EQ(p2.size(), 2u);
  EXPECT_FLOAT_EQ(p2[1].x, 3);
  EXPECT_FLOAT_EQ(p2[1].y, 4);
  ASSERT_NE(ps.find("v2", "vector2"), nullptr);
  EXPECT_EQ(ps.find("v2", "vector2")->numbers, (std::vector<double>{5, 6}));

  auto p3 = ps.get_point3s("p3");
  ASSERT_EQ(p3.size(), 1u);
  expect_vec_near(p3[0], Vec3(1, 2, 3));
  expect_vec_near(ps.get_point3("pt", Vec3(0, 0, 0)), Vec3(4, 5, 6));  // "point" is point3
  auto v3 = ps.get_vector3s("v3");
  ASSERT_EQ(v3.size(), 1u);
  expect_vec_near(v3[0], Vec3(0, 0, 1));
  auto vv = ps.get_vector3s("vv");  // "vector" is vector3
  ASSERT_EQ(vv.size(), 1u);
  expect_vec_near(vv[0], Vec3(7, 8, 9));
  auto n = ps.get_normals("n");
  ASSERT_EQ(n.size(), 1u);
  expect_vec_near(n[0], Vec3(0, 1, 0));
  auto n3 = ps.get_normals("n3");  // "normal3" is normal
  ASSERT_EQ(n3.size(), 1u);
  expect_vec_near(n3[0], Vec3(1, 0, 0));

  const Param* tx = ps.find("tx", "texture");
  ASSERT_NE(tx, nullptr);
  EXPECT_EQ(tx->strings, (std::vector<std::string>{"mytex"}));
  EXPECT_EQ(tx->loc.line, 13);
}

TEST(SceneParams, CanonicalTypeNames) {
  EXPECT_EQ(canonical_param_type("point"), "point3");
  EXPECT_EQ(canonical_param_type("vector"), "vector3");
  EXPECT_EQ(canonical_param_type("normal3"), "normal");
  EXPECT_EQ(canonical_param_type("color"), "rgb");
  EXPECT_EQ(canonical_param_type("float"), "float");
  EXPECT_EQ(canonical_param_type("texture"), "texture");
  EXPECT_EQ(canonical_param_type("double"), "");
}

TEST(SceneParams, GetterMarksUsed) {
  ParsedScene p =
      parse_scene_string("WorldBegin\nShape \"sphere\" \"float radius\" 2 \"float other\" 1\n");
  const ParamSet& ps = p.shapes[0].params;
  EXPECT_FALSE(ps.find_any("radius")->used);
  EXPECT_FLOAT_EQ(ps.get_float("radius", 1), 2);
  EXPECT_TRUE(ps.find_any("radius")->used);
  EXPECT_FALSE(ps.find_any("other")->used);
}

TEST(SceneParams, RgbReflectance) {
  LoadedScene ls =
      flatten_scene(parse_scene_string("WorldBegin\nMaterial \"diffuse\" \"color reflectance\" "
                                       "[0.25 0.5 0.75]\nShape \"sphere\"\n"));
  const MaterialDesc& m = ls.scene.materials[ls.scene.objects[0].material];
  ASSERT_TRUE(std::holds_alternative<DiffuseDesc>(m));
  expect_spectrum_near(std::get<DiffuseDesc>(m).reflectance, Rgb(0.25f, 0.5f, 0.75f));
}

TEST(SceneParams, InlineSpectrumReflectance) {
  // Constant over the whole visible range: a grey reflectance of that value.
  LoadedScene ls =
      flatten_scene(parse_scene_string("WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" "
                                       "[360 0.5 830 0.5]\nShape \"sphere\"\n"));
  const MaterialDesc& m = ls.scene.materials[ls.scene.objects[0].material];
  ASSERT_TRUE(std::holds_alternative<DiffuseDesc>(m));
  expect_spectrum_near(std::get<DiffuseDesc>(m).reflectance, Rgb(0.5f), 1e-4f);
}

TEST(SceneParams, SpectrumFile) {
  TempDir dir;
  dir.write("grey.spd", "# wavelength value\n360 0.25\n600 0.25 # middle\n830 0.25\n");
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" \"grey.spd\"\nShape \"sphere\"\n",
      dir.str()));
  const MaterialDesc& m = ls.scene.materials[ls.scene.objects[0].material];
  ASSERT_TRUE(std::holds_alternative<DiffuseDesc>(m));
  expect_spectrum_near(std::get<DiffuseDesc>(m).reflectance, Rgb(0.25f), 1e-4f);
}

TEST(SceneParams, NamedSpectrumEta) {
  LoadedScene ls =
      flatten_scene(parse_scene_string("WorldBegin\nMaterial \"conductor\" \"spectrum eta\" "
                                       "\"metal-Ag-eta\" \"spectrum k\" \"metal-Ag-k\"\n"
                                       "Shape \"sphere\"\n"));
  const MaterialDesc& m = ls.scene.materials[ls.scene.objects[0].material];
  ASSERT_TRUE(std::holds_alternative<ConductorDesc>(m));
  // Through the measured values at 650, 550 and 450 nm.
  const ConductorDesc& c = std::get<ConductorDesc>(m);
  EXPECT_NEAR(c.eta.curve.value(650), 0.155265f, 1e-5f);
  EXPECT_NEAR(c.eta.curve.value(550), 0.116723f, 1e-5f);
  EXPECT_NEAR(c.eta.curve.value(450), 0.138342f, 1e-5f);
  EXPECT_NEAR(c.k.curve.value(650), 4.828181f, 1e-5f);
  EXPECT_NEAR(c.k.curve.value(450), 2.146961f, 1e-5f);
  EXPECT_NEAR(c.eta.curve.value(600), 0.5f * (0.155265f + 0.116723f), 1e-5f);  // linear between
}

// A camera's sensitivity as a named spectrum (here an unbounded one: a conductor's k), zero
// beyond its measured range.
TEST(SceneParams, NamedCameraCurve) {
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nMaterial \"conductor\" \"spectrum k\" \"nikon_d850_g\"\nShape \"sphere\"\n"));
  const ConductorDesc& c =
      std::get<ConductorDesc>(ls.scene.materials[ls.scene.objects[0].material]);
  EXPECT_NEAR(c.k.curve.value(520), 1.0f, 1e-5f);  // the green's peak
  EXPECT_EQ(c.k.curve.value(370), 0.0f);
  EXPECT_EQ(c.k.curve.value(800), 0.0f);
}

TEST(SceneParams, BlackbodyLightHasUnitLuminance) {
  LoadedScene ls =
      flatten_scene(parse_scene_string("WorldBegin\nLightSource \"point\" \"blackbody I\" "
                                       "6500\nLightSource \"point\" \"blackbody I\" 3000 "
                                       "\"float scale\" 2\n"));
  ASSERT_EQ(ls.scene.lights.size(), 2u);
  const PointLight& a = std::get<PointLight>(ls.scene.lights[0]);
  SpectrumCurve bb = SpectrumCurve::blackbody(6500);
  expect_spectrum_near(a.intensity, bb.scaled(1 / bb.luminance()));
  EXPECT_NEAR(a.intensity.luminance(), 1.0f, 1e-4f);
  const PointLight& b = std::get<PointLight>(ls.scene.lights[1]);
  EXPECT_NEAR(b.intensity.luminance(), 2.0f, 2e-4f);
  EXPECT_GT(b.intensity.rgb()[0], b.intensity.rgb()[2]);  // 3000 K is reddish
}

// ---------------------------------------------------------------------------------------------
// Parse errors

TEST(SceneParseError, UnknownDirective) {
  EXPECT_TRUE(
      IsError(error_of("WorldBegin\n  Bogus 1 2\n"), at(2, 3), "unknown directive 'Bogus'"));
}

TEST(SceneParseError, StringWhereDirectiveExpected) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\n\"sphere\"\n"), at(2, 1), "expected a directive"));
}

TEST(SceneParseError, UnterminatedStringAtEndOfFile) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nShape \"sphere"), at(2, 7),
                      "unterminated string at end of file"));
}

TEST(SceneParseError, UnterminatedStringAtNewline) {
  EXPECT_TRUE(
      IsError(error_of("WorldBegin\nShape \"sph\nere\"\n"), at(2, 7), "unterminated string"));
}

TEST(SceneParseError, ParameterValueMissingAtEndOfFile) {
  const std::string l2 = R"(Shape "sphere" "float radius")";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2), at(2, col(l2, "\"float")),
                      "unexpected end of file: expected a parameter value"));
}

TEST(SceneParseError, UnclosedParameterBracket) {
  const std::string l2 = R"(Shape "sphere" "float radius" [ 1)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"float")),
                      "expected ] closing the parameter values"));
}

TEST(SceneParseError, NestedParameterBracket) {
  const std::string l2 = R"(Shape "sphere" "float radius" [ 1 [2] ])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "[2")), "nested '['"));
}

TEST(SceneParseError, UnknownParameterType) {
  const std::string l2 = R"(Shape "sphere" "floot radius" 1)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"floot")),
                      "unknown parameter type \"floot\""));
}

TEST(SceneParseError, DeclarationWithoutName) {
  const std::string l2 = R"(Shape "sphere" "float" 1)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"float\"")),
                      "expected a parameter declaration \"type name\"; got \"float\""));
}

TEST(SceneParseError, DeclarationWithExtraWords) {
  const std::string l2 = R"(Shape "sphere" "float radius extra" 1)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"float")),
                      "malformed parameter declaration \"float radius extra\""));
}

TEST(SceneParseError, StringWhereNumbersExpected) {
  const std::string l2 = R"(Shape "sphere" "float radius" "one")";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"one\"")),
                      "parameter \"radius\" expects numbers; got a string"));
}

TEST(SceneParseError, NumberWhereStringExpected) {
  const std::string l2 = R"(Shape "plymesh" "string filename" 5)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "5")),
                      "parameter \"filename\" expects strings; got '5'"));
}

TEST(SceneParseError, BadBool) {
  const std::string l2 = R"(Shape "sphere" "bool flag" "yes")";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"yes\"")),
                      "parameter \"flag\" expects true or false"));
}

TEST(SceneParseError, BadBareBool) {
  const std::string l2 = R"(Shape "sphere" "bool flag" [true 1])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "1]")),
                      "expects true or false; got '1'"));
}

TEST(SceneParseError, NonIntegerInteger) {
  const std::string l2 = R"(Shape "trianglemesh" "integer indices" [0 1 2.5])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"integer")),
                      "parameter \"indices\" expects integers"));
}

TEST(SceneParseError, RgbWithTwoValues) {
  const std::string l2 = R"(Material "diffuse" "rgb reflectance" [0.1 0.2])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"rgb")),
                      "parameter \"reflectance\" of type rgb needs 3 values; got 2"));
}

TEST(SceneParseError, Point3WithFourValues) {
  const std::string l2 = R"(Shape "trianglemesh" "point3 P" [0 0 0 1])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"point3")),
                      "parameter \"P\" of type point3 needs a multiple of 3 values; got 4 values"));
}

TEST(SceneParseError, SpectrumWithOddCount) {
  const std::string l2 = R"(Material "conductor" "spectrum eta" [400 1 700])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"spectrum")),
                      "needs wavelength/value pairs; got 3 values"));
}

TEST(SceneParseError, BlackbodyWithThreeValues) {
  const std::string l2 = R"(LightSource "point" "blackbody I" [6500 1 2])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"blackbody")),
                      "of type blackbody needs a temperature"));
}

TEST(SceneParseError, DuplicateParameter) {
  const std::string l2 = R"(Shape "sphere" "float radius" 1 "float radius" 2)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, int(l2.rfind("\"float")) + 1),
                      "parameter \"radius\" given twice"));
}

TEST(SceneParseError, DirectiveNumberMissing) {
  EXPECT_TRUE(IsError(error_of("Translate 1 2\nWorldBegin\n"), at(2, 1),
                      "expected a number; got 'WorldBegin'"));
}

TEST(SceneParseError, DirectiveNumbersAtEndOfFile) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nTranslate 1"), at(2, 1),
                      "unexpected end of file: expected a number"));
}

TEST(SceneParseError, BracketedDirectiveWithTooManyNumbers) {
  const std::string l2 = "Translate [1 2 3 4]";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "4")),
                      "Translate takes 3 numbers"));
}

TEST(SceneParseError, AttributeEndWithoutBegin) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nShape \"sphere\"\nAttributeEnd\n"), at(3, 1),
                      "AttributeEnd without a matching begin"));
}

TEST(SceneParseError, TransformEndWithoutBegin) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nTransformEnd\n"), at(2, 1),
                      "TransformEnd without a matching begin"));
}

TEST(SceneParseError, AttributeBeginWithoutEndReportedAtEnd) {
  EXPECT_TRUE(IsError(
      error_of("WorldBegin\nAttributeBegin\nAttributeBegin\nAttributeEnd\nShape \"sphere\"\n"),
      at(2, 1), "AttributeBegin without a matching AttributeEnd"));
}

TEST(SceneParseError, CameraAfterWorldBegin) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nCamera \"perspective\"\n"), at(2, 1),
                      "Camera is not allowed after WorldBegin"));
}

TEST(SceneParseError, WorldBeginTwice) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nWorldBegin\n"), at(2, 1),
                      "WorldBegin is not allowed after WorldBegin"));
}

TEST(SceneParseError, ShapeBeforeWorldBegin) {
  EXPECT_TRUE(IsError(error_of("Shape \"sphere\"\nWorldBegin\n"), at(1, 1),
                      "Shape is only allowed after WorldBegin"));
}

TEST(SceneParseError, MaterialBeforeWorldBegin) {
  EXPECT_TRUE(IsError(error_of("Material \"diffuse\"\nWorldBegin\n"), at(1, 1),
                      "Material is only allowed after WorldBegin"));
}

TEST(SceneParseError, NoWorldBegin) {
  // Reported at the last token read.
  EXPECT_TRUE(IsError(error_of("Camera \"perspective\"\nFilm \"rgb\"\n"), at(2, 6),
                      "the scene has no WorldBegin"));
}

TEST(SceneParseError, UnknownCoordinateSystem) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nCoordSysTransform \"nowhere\"\n"), at(2, 1),
                      "unknown coordinate system \"nowhere\""));
}

TEST(SceneParseError, UnknownObjectInstance) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nObjectInstance \"thing\"\n"), at(2, 1),
                      "unknown object \"thing\""));
}

TEST(SceneParseError, ObjectEndWithoutObjectBegin) {
  EXPECT_TRUE(
      IsError(error_of("WorldBegin\nObjectEnd\n"), at(2, 1), "ObjectEnd without ObjectBegin"));
}

TEST(SceneParseError, ObjectDefinedTwice) {
  EXPECT_TRUE(
      IsError(error_of("WorldBegin\nObjectBegin \"a\"\nObjectEnd\nObjectBegin \"a\"\nObjectEnd\n"),
              at(4, 1), "object \"a\" defined twice"));
}

TEST(SceneParseError, NestedObjectBegin) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nObjectBegin \"a\"\nObjectBegin \"b\"\n"), at(3, 1),
                      "ObjectBegin inside another ObjectBegin"));
}

TEST(SceneParseError, ObjectInstanceInsideObject) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nObjectBegin \"a\"\nObjectInstance \"a\"\nObjectEnd\n"),
                      at(3, 1), "ObjectInstance inside ObjectBegin"));
}

TEST(SceneParseError, ObjectBeginWithoutEnd) {
  EXPECT_TRUE(
      IsError(error_of("WorldBegin\nObjectBegin \"a\"\nShape \"sphere\"\n"), at(2, 1), "without"));
}

TEST(SceneParseError, IncludeMissingFile) {
  TempDir dir;
  std::string msg = error_of("WorldBegin\nInclude \"no_such_file.pbrt\"\n", dir.str());
  EXPECT_TRUE(IsError(msg, at(2, 1), "cannot open scene file"));
  EXPECT_TRUE(Contains(msg, "no_such_file.pbrt\""));
}

TEST(SceneParseError, IncludeCycle) {
  TempDir dir;
  dir.write("a.pbrt", "Include \"b.pbrt\"\n");
  dir.write("b.pbrt", "# b includes a\nInclude \"a.pbrt\"\n");
  std::string msg = error_of("Include \"a.pbrt\"\nWorldBegin\n", dir.str());
  std::string where = (fs::path(dir.str()) / "b.pbrt").lexically_normal().string() + ":2:1";
  EXPECT_TRUE(IsError(msg, where, "file \"a.pbrt\" includes itself"));
}

TEST(SceneParseError, ErrorInIncludedFileNamesThatFile) {
  TempDir dir;
  dir.write("bad.pbrt", "Shape \"sphere\"\n  Bogus\n");
  std::string msg = error_of("WorldBegin\nInclude \"bad.pbrt\"\n", dir.str());
  std::string where = (fs::path(dir.str()) / "bad.pbrt").lexically_normal().string() + ":2:3";
  EXPECT_TRUE(IsError(msg, where, "unknown directive 'Bogus'"));
}

TEST(SceneParseError, MissingSceneFile) {
  TempDir dir;
  std::string path = (dir.path() / "absent.pbrt").string();
  try {
    (void)parse_scene_file(path);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_TRUE(Contains(e.what(), "cannot open scene file \"" + path + "\""));
  }
}

TEST(SceneParseError, SingularTransform) {
  EXPECT_TRUE(IsError(error_of("Transform [1 0 0 0  0 1 0 0  0 0 0 0  0 0 0 1]\nWorldBegin\n"),
                      at(1, 1), "Transform matrix is singular"));
}

TEST(SceneParseError, SingularConcatTransform) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nConcatTransform [0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0]\n"),
                      at(2, 1), "ConcatTransform matrix is singular"));
}

TEST(SceneParseError, ScaleByZero) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nScale 1 0 1\n"), at(2, 1),
                      "Scale by zero makes the transform singular"));
}

TEST(SceneParseError, RotateAboutZeroAxis) {
  EXPECT_TRUE(
      IsError(error_of("WorldBegin\nRotate 30 0 0 0\n"), at(2, 1), "Rotate about a zero axis"));
}

TEST(SceneParseError, LookAtCoincidentEyeAndTarget) {
  EXPECT_TRUE(IsError(error_of("LookAt 1 1 1  1 1 1  0 1 0\nWorldBegin\n"), at(1, 1),
                      "LookAt with coincident eye and target"));
}

TEST(SceneParseError, LookAtUpParallelToViewDirection) {
  EXPECT_TRUE(IsError(error_of("LookAt 0 0 0  0 5 0  0 1 0\nWorldBegin\n"), at(1, 1),
                      "up parallel to the view direction"));
}

TEST(SceneParseError, ActiveTransformBadArgument) {
  const std::string l2 = "ActiveTransform Sometimes";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "Sometimes")),
                      "ActiveTransform takes StartTime, EndTime or All"));
}

TEST(SceneParseError, TextureBadValueType) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nTexture \"t\" \"vector\" \"constant\"\n"), at(2, 1),
                      "texture type must be \"float\" or \"spectrum\""));
}

TEST(SceneParseError, MakeNamedMaterialWithoutType) {
  EXPECT_TRUE(
      IsError(error_of("WorldBegin\nMakeNamedMaterial \"m\" \"rgb reflectance\" [0.5 0.5 0.5]\n"),
              at(2, 1), "MakeNamedMaterial \"m\" has no \"string type\""));
}

TEST(SceneParseError, NamedMaterialDefinedTwice) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nMakeNamedMaterial \"m\" \"string type\" \"diffuse\"\n"
                               "MakeNamedMaterial \"m\" \"string type\" \"conductor\"\n"),
                      at(3, 1), "named material \"m\" defined twice"));
}

// pbrt-v4's default absorption is 1 per unit distance.
TEST(SceneParse, MediumDefaultAbsorption) {
  const LoadedScene ls = flatten_scene(parse_scene_string(
      "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_s\" [0 0 0] "
      "\"float scale\" 0.5\nWorldBegin\nMediumInterface \"m\" \"\"\nShape \"sphere\"\n"));
  ASSERT_EQ(ls.scene.media.size(), 1u);
  EXPECT_NEAR(ls.scene.media[0].sigma_a.value(450), 0.5f, 1e-6f);
  EXPECT_NEAR(ls.scene.media[0].sigma_a.value(650), 0.5f, 1e-6f);
}

// A preset names measured coefficients in mm^-1 (pbrt-v4's table), which "scale" multiplies.
TEST(SceneParse, MediumPreset) {
  const LoadedScene ls = flatten_scene(parse_scene_string(
      "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"string preset\" \"Ketchup\" "
      "\"float scale\" 2\nWorldBegin\nMediumInterface \"m\" \"\"\nShape \"sphere\"\n"));
  ASSERT_EQ(ls.scene.media.size(), 1u);
  const Rgb s = ls.scene.media[0].sigma_s.rgb(), a = ls.scene.media[0].sigma_a.rgb();
  EXPECT_NEAR(s[0], 0.36f, 0.02f);
  EXPECT_NEAR(s[2], 0.06f, 0.01f);
  EXPECT_NEAR(a[1], 1.94f, 0.1f);
  EXPECT_FALSE(ls.scene.media[0].grid);
}

// A uniformgrid's density lies on its box in the medium's space, interpolated between voxel
// centres and zero past the outermost ones.
TEST(SceneParse, UniformGridMedium) {
  const LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nTranslate 10 0 0\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" "
      "\"integer nx\" 2 \"float density\" [1 3] \"point3 p0\" [0 0 0] \"point3 p1\" [2 1 1]\n"
      "MediumInterface \"m\" \"\"\nShape \"sphere\"\n"));
  ASSERT_EQ(ls.scene.media.size(), 1u);
  const Medium& m = ls.scene.media[0];
  ASSERT_TRUE(m.grid);
  EXPECT_NEAR(m.density({10.5f, 0.5f, 0.5f}), 1, 1e-5f);  // voxel centres
  EXPECT_NEAR(m.density({11.5f, 0.5f, 0.5f}), 3, 1e-5f);
  EXPECT_NEAR(m.density({11.0f, 0.5f, 0.5f}), 2, 1e-5f);
  EXPECT_NEAR(m.density({10.5f, 0.0f, 0.5f}), 0.5f, 1e-5f);  // half way to the zeros beyond
  EXPECT_EQ(m.density({0.5f, 0.5f, 0.5f}), 0);               // outside the box
}

TEST(SceneParseError, MediaThatAreUnknownOrUnsupportedAreErrors) {
  auto scene = [](const std::string& medium_params,
                  const std::string& interface = "MediumInterface \"m\" \"\"") {
    return "MakeNamedMedium \"m\" " + medium_params + "\nWorldBegin\n" + interface +
           "\nShape \"sphere\"\n";
  };
  EXPECT_TRUE(
      IsError(error_of(scene("\"string type\" \"homogeneous\"", "MediumInterface \"nope\" \"\"")),
              at(3, 1), "unknown medium \"nope\""));
  // A scattering homogeneous medium, pbrt-v4's defaults included, is read.
  EXPECT_EQ(error_of(scene("\"string type\" \"homogeneous\"")), "");
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"gas\"")), at(3, 1), "type \"gas\""));
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"rgbgrid\"")), at(1, 1),
                      "rgbgrid medium needs \"rgb sigma_a\" or \"rgb sigma_s\" values"));
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"rgbgrid\" \"integer nx\" 2 "
                                     "\"rgb sigma_s\" [1 1 1]")),
                      at(1, 60), "rgbgrid has 1 sigma_s colours; nx * ny * nz = 2"));
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"rgbgrid\" \"rgb sigma_a\" [1 -1 1]")),
                      at(1, 45), "sigma_a colours must be finite and not negative"));
  // An rgbgrid glows by colours of Le where sigma_a is given; a cloud does not glow.
  EXPECT_EQ(error_of(scene("\"string type\" \"rgbgrid\" \"rgb sigma_a\" [1 1 1] "
                           "\"rgb Le\" [1 1 1]")),
            "");
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"rgbgrid\" \"rgb sigma_s\" [1 1 1] "
                                     "\"rgb Le\" [1 1 1]")),
                      at(1, 67), "an rgbgrid that glows (\"rgb Le\") needs \"rgb sigma_a\""));
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"rgbgrid\" \"integer nx\" 2 "
                                     "\"rgb sigma_a\" [1 1 1  1 1 1] \"rgb Le\" [1 1 1]")),
                      at(1, 89), "rgbgrid has 1 Le colours; nx * ny * nz = 2"));
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"cloud\" \"rgb Le\" [1 1 1]")), at(3, 1),
                      "it emits (Le)"));
  EXPECT_EQ(error_of(scene("\"string type\" \"rgbgrid\" \"integer nx\" 2 "
                           "\"rgb sigma_s\" [1 1 1  0 0.5 2]")),
            "");
  // A list of colours where one is wanted.
  EXPECT_TRUE(
      IsError(error_of(scene("\"string type\" \"homogeneous\" \"rgb sigma_a\" [1 1 1 1 1 1]")),
              at(1, 49), "parameter \"sigma_a\" of type rgb needs 3 values; got 6"));
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"nanovdb\"")), at(3, 1), "NanoVDB"));
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"uniformgrid\" \"rgb sigma_s\" [0 0 0]")),
                      at(1, 1), "uniformgrid medium needs \"float density\""));
  const std::string short_grid =
      "\"string type\" \"uniformgrid\" \"integer nx\" 2 \"float density\" [1]";
  EXPECT_TRUE(IsError(error_of(scene(short_grid)), at(1, 20 + col(short_grid, "\"float density")),
                      "uniformgrid has 1 density values; nx * ny * nz = 2"));
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"uniformgrid\" \"float density\" [-1]")),
                      at(1, 49), "density values must not be negative"));
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"uniformgrid\" \"float density\" [1] "
                                     "\"point3 p1\" [1 0 1]")),
                      at(1, 69), "p1 must exceed p0"));
  EXPECT_EQ(
      error_of(scene("\"string type\" \"homogeneous\" \"rgb sigma_s\" [0 0 0] \"rgb Le\" [1 1 1]")),
      "");
  EXPECT_EQ(error_of(scene("\"string type\" \"homogeneous\" \"string preset\" \"Apple\"")), "");
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"homogeneous\" \"string preset\" \"Pear\"")),
                      at(1, 49), "unknown medium preset \"Pear\"; known: \"Apple\""));
  const std::string bad_g = "\"string type\" \"homogeneous\" \"float g\" 1";
  EXPECT_TRUE(IsError(error_of(scene(bad_g)), at(1, 20 + col(bad_g, "\"float g")),
                      "g must lie in (-1, 1)"));
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"homogeneous\" \"rgb sigma_s\" [-1 0 0]")),
                      at(1, 49), "sigma_s"));
  EXPECT_TRUE(IsError(error_of("MakeNamedMedium \"m\" \"float scale\" 1\nWorldBegin\n"), at(1, 1),
                      "medium \"m\" has no \"string type\""));
  // The camera inside a medium sits in it, and so does a light (its photons start there).
  const std::string absorbing =
      "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_s\" [0 0 0]\n";
  EXPECT_EQ(flatten_scene(parse_scene_string(absorbing + "MediumInterface \"\" \"m\"\n"
                                                         "Camera \"perspective\"\nWorldBegin\n"))
                .camera.medium,
            0);
  EXPECT_EQ(
      flatten_scene(parse_scene_string(
                        absorbing + "WorldBegin\nMediumInterface \"m\"\nLightSource \"point\"\n"))
          .scene.medium_of_light(0),
      0);
}

// pbrt-v4's cloud and a glowing uniformgrid (by Le or by temperature) are read; their parameters
// out of range are located errors.
TEST(SceneParseError, CloudAndGlowingGridParameters) {
  auto scene = [](const std::string& medium_params) {
    return "MakeNamedMedium \"m\" " + medium_params +
           "\nWorldBegin\nMediumInterface \"m\" \"\"\nShape \"sphere\"\n";
  };
  // pbrt-v4's cloud is read; its parameters out of range are located errors.
  EXPECT_EQ(error_of(scene("\"string type\" \"cloud\" \"float frequency\" 1")), "");
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"cloud\" \"float frequency\" 0")), at(1, 43),
                      "frequency"));
  EXPECT_TRUE(IsError(error_of(scene("\"string type\" \"cloud\" \"float density\" -1")), at(1, 43),
                      "density"));
  EXPECT_TRUE(
      IsError(error_of(scene("\"string type\" \"cloud\" \"point3 p1\" [1 0 1]")), at(1, 43), "p1"));
  // A uniformgrid glows, by a grid of Lescale values of its size (or one voxel of 1).
  EXPECT_EQ(error_of(scene("\"string type\" \"uniformgrid\" \"float density\" [1] "
                           "\"rgb Le\" [1 1 1]")),
            "");
  const std::string short_le =
      "\"string type\" \"uniformgrid\" \"integer nx\" 2 \"float density\" "
      "[1 1] \"rgb Le\" [1 1 1] \"float Lescale\" [1]";
  EXPECT_TRUE(IsError(error_of(scene(short_le)), at(1, 20 + col(short_le, "\"float Lescale")),
                      "uniformgrid has 1 Lescale values; nx * ny * nz = 2"));
  // Or by temperature, one value per voxel, never beside Le.
  EXPECT_EQ(error_of(scene("\"string type\" \"uniformgrid\" \"float density\" [1] "
                           "\"float temperature\" [900]")),
            "");
  const std::string two_temperatures =
      "\"string type\" \"uniformgrid\" \"float density\" [1] \"float temperature\" [900 800]";
  EXPECT_TRUE(IsError(error_of(scene(two_temperatures)),
                      at(1, 20 + col(two_temperatures, "\"float temperature")),
                      "uniformgrid has 2 temperature values; nx * ny * nz = 1"));
  const std::string both =
      "\"string type\" \"uniformgrid\" \"float density\" [1] "
      "\"float temperature\" [900] \"rgb Le\" [1 1 1]";
  EXPECT_TRUE(IsError(error_of(scene(both)), at(1, 20 + col(both, "\"rgb Le")),
                      "by \"Le\" or by \"temperature\", not both"));
  const std::string negative =
      "\"string type\" \"uniformgrid\" \"float density\" [1] "
      "\"float temperature\" [-900]";
  EXPECT_TRUE(IsError(error_of(scene(negative)), at(1, 20 + col(negative, "\"float temperature")),
                      "temperature values must be non-negative"));
}

TEST(SceneParseError, ColorSpaceOtherThanSrgb) {
  EXPECT_TRUE(IsError(error_of("ColorSpace \"aces2065-1\"\nWorldBegin\n"), at(1, 1),
                      "color space \"aces2065-1\" is not supported"));
}

TEST(SceneParseError, NanInDirective) {
  // std::from_chars reads "nan" as a number, so the error is the non-finite check.
  EXPECT_TRUE(IsError(error_of("WorldBegin\nTranslate nan 0 0\n"), at(2, 1),
                      "Translate has a non-finite value"));
}

TEST(SceneParseError, MalformedNumber) {
  const std::string l2 = R"(Shape "sphere" "float radius" 1.2.3)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "1.2.3")),
                      "expected a number; got '1.2.3'"));
}

// ---------------------------------------------------------------------------------------------
// Errors found while flattening

TEST(SceneFlattenError, UnknownNamedMaterial) {
  const std::string text = "WorldBegin\nNamedMaterial \"gold\"\nShape \"sphere\"\n";
  EXPECT_EQ(parse_error_of(text), "");
  EXPECT_TRUE(IsError(error_of(text), at(2, 1), "unknown named material \"gold\""));
}

TEST(SceneFlattenError, TriangleMeshWithoutP) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nShape \"trianglemesh\" \"integer indices\" [0 1 2]\n"),
                      at(2, 1), "trianglemesh has no \"point3 P\""));
}

TEST(SceneFlattenError, TriangleMeshWithoutIndices) {
  EXPECT_TRUE(IsError(
      error_of("WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0]\n"),
      at(2, 1), "trianglemesh has no \"integer indices\""));
}

TEST(SceneFlattenError, IndicesNotMultipleOfThree) {
  const std::string l2 =
      R"(Shape "trianglemesh" "integer indices" [0 1 2 3] "point3 P" [0 0 0 1 0 0 0 1 0 1 1 0])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"integer")),
                      "\"indices\" has 4 values, not a multiple of 3"));
}

TEST(SceneFlattenError, IndexOutOfRange) {
  const std::string l2 =
      std::string(R"(Shape "trianglemesh" "integer indices" [0 1 5] )") + kTriangleP;
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"integer")),
                      "vertex index 5 out of range (3 vertices)"));
}

TEST(SceneFlattenError, NegativeIndex) {
  const std::string l2 =
      std::string(R"(Shape "trianglemesh" "integer indices" [0 -1 2] )") + kTriangleP;
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"integer")),
                      "vertex index -1 out of range"));
}

TEST(SceneFlattenError, NormalCountMismatch) {
  const std::string l2 =
      std::string(R"(Shape "trianglemesh" )") + kTriangleP + R"( "normal N" [0 0 1 0 0 1])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"normal N")),
                      "\"N\" has 2 normals for 3 vertices"));
}

TEST(SceneFlattenError, UvCountMismatch) {
  const std::string l2 =
      std::string(R"(Shape "trianglemesh" )") + kTriangleP + R"( "point2 uv" [0 0 1 0])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"point2")),
                      "\"uv\" count differs from the vertex count"));
}

// A twisted bilinear patch (p(u, v) = (u, v, u v) over the unit square) becomes a grid of
// triangles on the patch: every vertex on the surface with the patch's normal, dp/du x dp/dv, and
// its (u, v); the triangles' area is the patch's to 1e-4.
TEST(SceneFlatten, NonPlanarBilinearPatchIsTessellated) {
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nShape \"bilinearmesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0  1 1 1]\n"));
  const TriangleMesh& m = std::get<TriangleMesh>(ls.scene.objects[0].shape);
  EXPECT_GT(m.triangle_count(), 100);
  double area = 0;
  for (int t = 0; t < m.triangle_count(); ++t) {
    const Vec3 a = m.positions[size_t(m.indices[3 * size_t(t)])],
               b = m.positions[size_t(m.indices[3 * size_t(t) + 1])],
               c = m.positions[size_t(m.indices[3 * size_t(t) + 2])];
    area += 0.5 * length(cross(b - a, c - a));
  }
  // The area of z = x y over the unit square: the integral of sqrt(1 + x^2 + y^2).
  double exact = 0;
  constexpr int kN = 400;
  for (int i = 0; i < kN; ++i)
    for (int j = 0; j < kN; ++j) {
      const double x = (i + 0.5) / kN, y = (j + 0.5) / kN;
      exact += std::sqrt(1 + x * x + y * y) / (kN * kN);
    }
  EXPECT_NEAR(area, exact, 1e-4 * exact);
  ASSERT_EQ(m.normals.size(), m.positions.size());
  for (size_t v = 0; v < m.positions.size(); ++v) {
    const Vec3 p = m.positions[v];
    EXPECT_NEAR(p.z, p.x * p.y, 1e-5f);
    const Vec3 n = normalize(Vec3(-p.y, -p.x, 1));  // (1, 0, y) x (0, 1, x)
    EXPECT_NEAR(dot(m.normals[v], n), 1, 1e-5f) << v;
    EXPECT_NEAR(m.uvs[v].x, p.x, 1e-5f);
    EXPECT_NEAR(m.uvs[v].y, p.y, 1e-5f);
  }
}

TEST(SceneFlattenError, PlymeshWithoutFilename) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nShape \"plymesh\"\n"), at(2, 1),
                      "plymesh has no \"string filename\""));
}

TEST(SceneFlattenError, PlymeshMissingFile) {
  TempDir dir;
  const std::string l2 = R"(Shape "plymesh" "string filename" "missing.ply")";
  std::string msg = error_of("WorldBegin\n" + l2 + "\n", dir.str());
  EXPECT_TRUE(IsError(msg, at(2, col(l2, "\"string")), "cannot open PLY file"));
  EXPECT_TRUE(Contains(msg, "missing.ply\""));
}

TEST(SceneFlattenError, PlymeshTruncatedBinary) {
  TempDir dir;
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f}) put_le(&ply, v);  // two of the three vertices
  dir.write("cut.ply", ply);
  const std::string l2 = R"(Shape "plymesh" "string filename" "cut.ply")";
  std::string msg = error_of("WorldBegin\n" + l2 + "\n", dir.str());
  EXPECT_TRUE(IsError(msg, at(2, col(l2, "\"string")), "truncated data"));
  EXPECT_TRUE(Contains(msg, "cut.ply\""));
}

// A quad with uv (0..1) in the xy plane: "displacement" lifts it along +z by the value; bad
// edge lengths and a file without uv get located errors.
TEST(SceneFlatten, DisplacedPlymesh) {
  TempDir dir;
  dir.write("uvquad.ply",
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
            "property float z\nproperty float u\nproperty float v\nelement face 1\n"
            "property list uchar int vertex_indices\nend_header\n"
            "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n");
  dir.write("quad.ply", kAsciiQuadPly);
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nTexture \"d\" \"float\" \"scale\" \"float tex\" 0.5 \"float scale\" 0.5\n"
      "Shape \"plymesh\" \"string filename\" \"uvquad.ply\" \"texture displacement\" \"d\" "
      "\"float edgelength\" 0.3\n",
      dir.str()));
  const TriangleMesh& m = std::get<TriangleMesh>(ls.scene.objects[0].shape);
  EXPECT_GT(m.triangle_count(), 20);
  for (const Vec3& p : m.positions) EXPECT_NEAR(p.z, 0.25f, 1e-6f);
  const std::string zero =
      R"(Shape "plymesh" "string filename" "uvquad.ply" "float displacement" 1 "float edgelength" 0)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + zero + "\n", dir.str()),
                      at(2, col(zero, "\"float edgelength")), "edgelength must be positive"));
  const std::string tiny =
      R"(Shape "plymesh" "string filename" "uvquad.ply" "float displacement" 1 "float edgelength" 1e-5)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + tiny + "\n", dir.str()),
                      at(2, col(tiny, "\"float edgelength")),
                      "edgelength would split the mesh into about"));
  const std::string no_uv =
      R"(Shape "plymesh" "string filename" "quad.ply" "float displacement" 1)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + no_uv + "\n", dir.str()),
                      at(2, col(no_uv, "\"float displacement")),
                      "displacement needs the PLY file's per-vertex uv"));
}

TEST(SceneFlattenError, PlymeshAsciiIndexOutOfRange) {
  TempDir dir;
  dir.write("bad.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
            "float z\n"
            "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  const std::string l2 = R"(Shape "plymesh" "string filename" "bad.ply")";
  std::string msg = error_of("WorldBegin\n" + l2 + "\n", dir.str());
  EXPECT_TRUE(IsError(msg, at(2, col(l2, "\"string")),
                      "vertex index 7 out of range (the file has 3 vertices)"));
  EXPECT_TRUE(Contains(msg, "bad.ply\""));
}

TEST(SceneFlattenError, SphereNegativeRadius) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nShape \"sphere\" \"float radius\" -1\n"), at(2, 1),
                      "sphere radius must be positive"));
}

TEST(SceneFlattenError, DiskInnerRadiusNotBelowRadius) {
  EXPECT_TRUE(
      IsError(error_of("WorldBegin\nShape \"disk\" \"float radius\" 1 \"float innerradius\" 2\n"),
              at(2, 1), "disk needs 0 <= innerradius < radius"));
}

TEST(SceneFlattenError, CylinderErrors) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nShape \"cylinder\" \"float radius\" 0\n"), at(2, 1),
                      "cylinder radius must be positive"));
  EXPECT_TRUE(
      IsError(error_of("WorldBegin\nShape \"cylinder\" \"float zmin\" 1 \"float zmax\" 1\n"),
              at(2, 1), "cylinder needs zmin != zmax"));
  EXPECT_TRUE(IsError(error_of("WorldBegin\nShape \"cylinder\" \"float phimax\" 0\n"), at(2, 1),
                      "cylinder phimax must be positive"));
  EXPECT_TRUE(IsError(
      error_of("WorldBegin\nScale 1 1 3\nAreaLightSource \"diffuse\"\nShape \"cylinder\"\n"),
      at(3, 1), "emitting cylinders must not be non-uniformly scaled"));
}

TEST(SceneFlattenError, UnsupportedShape) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nShape \"hyperboloid\"\n"), at(2, 1),
                      "shape \"hyperboloid\" is not supported"));
}

// pbrt-v4's curve: Bezier segments of degree + 1 points, then degree more each, or a B-spline's
// points past the first degree; widths along the whole curve; world space, the width scaled.
TEST(SceneParse, Curves) {
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nShape \"curve\" \"float width0\" 0.2 \"float width1\" 0.1\n"
      "  \"point3 P\" [0 0 0  1 0 0  2 0 0  3 0 0  4 0 0  5 0 0  6 0 0]\n"
      "Translate 0 5 0\nScale 2 2 2\n"
      "Shape \"curve\" \"string basis\" \"bspline\" \"integer degree\" 2 \"string type\" "
      "\"cylinder\"\n  \"point3 P\" [0 0 0  1 1 0  2 0 0  3 1 0]\n"
      "Shape \"curve\" \"string type\" \"ribbon\" \"point3 P\" [0 0 0  1 0 0  2 0 0  3 0 0]\n"
      "  \"normal N\" [0 1 0  0 0 1]\n"));
  ASSERT_EQ(ls.scene.objects.size(), 3u);
  const Curves& a = std::get<Curves>(ls.scene.objects[0].shape);
  ASSERT_EQ(a.segment_count(), 2);
  float r;
  expect_vec_near(a.point(1, 1, nullptr, &r), Vec3(6, 0, 0));
  EXPECT_NEAR(r, 0.05f, 1e-6f);  // width1 / 2 at the end
  a.point(1, 0, nullptr, &r);
  EXPECT_NEAR(r, 0.075f, 1e-6f);  // half way along the curve
  const Curves& b = std::get<Curves>(ls.scene.objects[1].shape);
  EXPECT_EQ(b.type, Curves::Type::kCylinder);
  ASSERT_EQ(b.segment_count(), 2);
  expect_vec_near(b.point(0, 0, nullptr, &r), Vec3(1, 6, 0));  // (0 + 1) / 2, scaled and moved
  EXPECT_NEAR(r, 1.0f, 1e-5f);                                 // the default width 1, scaled by 2
  const Curves& c = std::get<Curves>(ls.scene.objects[2].shape);
  expect_vec_near(c.ribbon_normal(0, 0), Vec3(0, 1, 0));
  expect_vec_near(c.ribbon_normal(0, 0.5f), normalize(Vec3(0, 1, 1)));
}

TEST(SceneFlattenError, BadCurves) {
  auto curve = [](const std::string& params) {
    return "WorldBegin\nShape \"curve\" \"point3 P\" [0 0 0 1 0 0 2 0 0 3 0 0] " + params + "\n";
  };
  EXPECT_TRUE(
      IsError(error_of(curve("\"integer degree\" 4")), at(2, 52), "curve degree 4 is not 2 or 3"));
  EXPECT_TRUE(IsError(error_of(curve("\"string basis\" \"hermite\"")), at(2, 52),
                      "curve basis \"hermite\" is unknown (bezier, bspline)"));
  EXPECT_TRUE(IsError(error_of(curve("\"string type\" \"tube\"")), at(2, 52),
                      "curve type \"tube\" is unknown (flat, cylinder, ribbon)"));
  EXPECT_TRUE(IsError(error_of(curve("\"float width\" -1")), at(2, 1),
                      "a curve's widths must be finite, not negative"));
  EXPECT_TRUE(IsError(error_of(curve("\"string type\" \"ribbon\"")), at(2, 1),
                      "a ribbon curve of 1 segment(s) takes 2 normals \"N\""));
  EXPECT_TRUE(IsError(
      error_of("WorldBegin\nShape \"curve\" \"point3 P\" [0 0 0 1 0 0 2 0 0 3 0 0 4 0 0]\n"),
      at(2, 15), "a degree 3 bezier curve takes 4 + k x 3 control points; got 5"));
  EXPECT_TRUE(IsError(error_of("WorldBegin\nAreaLightSource \"diffuse\"\n" +
                               curve("").substr(std::string("WorldBegin\n").size())),
                      at(2, 1), "a curve cannot emit"));
  const int warnings = warning_count();
  EXPECT_EQ(error_of(curve("\"normal N\" [0 1 0 0 1 0]")), "");
  EXPECT_EQ(warning_count(), warnings + 1);  // normals on a flat curve: unused, as pbrt-v4 warns
}

TEST(SceneParse, AlphaConstantOrTexture) {
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\n"
      "Texture \"mask\" \"float\" \"checkerboard\" \"float tex1\" 0 \"float tex2\" 1\n"
      "Texture \"half\" \"float\" \"constant\" \"float value\" 0.5\n"
      "Shape \"sphere\" \"float alpha\" 0.25\n"
      "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"texture alpha\" \"mask\"\n"
      "Shape \"disk\" \"texture alpha\" \"half\"\n"
      "Shape \"disk\" \"float alpha\" 1\n"));
  ASSERT_EQ(ls.scene.objects.size(), 4u);
  EXPECT_FLOAT_EQ(ls.scene.objects[0].alpha.value, 0.25f);
  EXPECT_TRUE(ls.scene.objects[0].has_alpha());
  ASSERT_TRUE(ls.scene.objects[1].alpha.textured());
  EXPECT_TRUE(std::holds_alternative<CheckerboardTexture>(
      ls.scene.textures.node(ls.scene.objects[1].alpha.texture)));
  EXPECT_FLOAT_EQ(ls.scene.objects[2].alpha.value, 0.5f);  // a constant texture is a constant
  EXPECT_FALSE(ls.scene.objects[2].alpha.textured());
  EXPECT_FALSE(ls.scene.objects[3].has_alpha());
}

TEST(SceneFlattenError, AlphaErrors) {
  const std::string l2 = R"(Shape "sphere" "float alpha" 1.5)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"float")),
                      "alpha must be in [0, 1]"));
  const std::string l3 = R"(Shape "sphere" "float alpha" 0.5)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\nAreaLightSource \"diffuse\"\n" + l3 + "\n"),
                      at(3, col(l3, "\"float")),
                      "alpha on an emitting shape is not supported (the area light at"));
  const std::string l4 = R"(Shape "sphere" "texture alpha" "colour")";
  EXPECT_FALSE(
      error_of("WorldBegin\nTexture \"colour\" \"spectrum\" \"constant\" \"rgb value\" [1 1 1]\n" +
               l4 + "\n")
          .empty());
}

TEST(SceneFlattenError, UnsupportedMaterial) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nMaterial \"hair\"\nShape \"sphere\"\n"), at(2, 1),
                      "material \"hair\" is not supported"));
}

TEST(SceneFlattenError, UnsupportedLight) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nLightSource \"laser\"\n"), at(2, 1),
                      "light \"laser\" is not supported"));
}

TEST(SceneFlattenError, NegativeReflectance) {
  const std::string l2 = R"(Material "diffuse" "rgb reflectance" [-0.1 0.5 0.5])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\nShape \"sphere\"\n"),
                      at(2, col(l2, "\"rgb")),
                      "parameter \"reflectance\" has a negative or non-finite value"));
}

TEST(SceneFlattenError, ReflectanceAboveOne) {
  const std::string l2 = R"(Material "diffuse" "rgb reflectance" [1.5 0.5 0.5])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\nShape \"sphere\"\n"),
                      at(2, col(l2, "\"rgb")),
                      "parameter \"reflectance\" is a reflectance and must not exceed 1"));
}

TEST(SceneFlattenError, NanParameter) {
  // std::from_chars accepts "nan", so parsing succeeds and the getter rejects the value.
  const std::string l2 = R"(Shape "sphere" "float radius" nan)";
  std::string msg = error_of("WorldBegin\n" + l2 + "\n");
  EXPECT_FALSE(msg.empty());
  EXPECT_TRUE(
      IsError(msg, at(2, col(l2, "\"float")), "parameter \"radius\" has a non-finite value"));
}

// A PFM image of one colour (PFM: header, then little-endian floats, rows from the bottom).
std::string constant_pfm(int w, int h, Rgb c) {
  std::string s = "PF\n" + std::to_string(w) + " " + std::to_string(h) + "\n-1.0\n";
  for (int i = 0; i < w * h; ++i)
    for (int k = 0; k < 3; ++k) put_le(&s, c[k]);
  return s;
}

TEST(SceneParse, InfiniteLightWithImage) {
  TempDir dir;
  const Rgb c(0.5f, 1.0f, 2.0f);
  dir.write("sky.pfm", constant_pfm(8, 8, c));
  dir.write("latlong.pfm", constant_pfm(16, 8, c));
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nAttributeBegin\nRotate -90 1 0 0\n"
      "LightSource \"infinite\" \"string filename\" \"sky.pfm\" \"float scale\" 2\nAttributeEnd\n"
      "LightSource \"infinite\" \"string filename\" \"sky.pfm\" \"float illuminance\" 3\n"
      "LightSource \"infinite\" \"string filename\" \"latlong.pfm\"\n",
      dir.str()));
  ASSERT_EQ(ls.scene.lights.size(), 3u);
  EXPECT_EQ(ls.scene.infinite_lights, (std::vector<int>{0, 1, 2}));
  const auto& a = std::get<ImageInfiniteLight>(ls.scene.lights[0]);
  EXPECT_TRUE(a.equal_area);
  EXPECT_FLOAT_EQ(a.scale, 2);
  expect_vec_near(a.world_from_light.vector(Vec3(0, 0, 1)), Vec3(0, 1, 0));
  EXPECT_NEAR(a.mean_radiance[2], 2 * 2.0f, 1e-4f);
  // "illuminance": the upper hemisphere of a constant image gives pi Y.
  const auto& b = std::get<ImageInfiniteLight>(ls.scene.lights[1]);
  EXPECT_NEAR(b.scale, 3 / (kPi * c.luminance()), 1e-3f * b.scale);
  const auto& l = std::get<ImageInfiniteLight>(ls.scene.lights[2]);
  EXPECT_FALSE(l.equal_area);
}

TEST(SceneFlattenError, InfiniteLightImageErrors) {
  TempDir dir;
  dir.write("sky.pfm", constant_pfm(8, 8, Rgb(1.0f)));
  dir.write("odd.pfm", constant_pfm(12, 8, Rgb(1.0f)));
  const std::string odd = R"(LightSource "infinite" "string filename" "odd.pfm")";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + odd + "\n", dir.str()), at(2, col(odd, "\"string")),
                      "environment image \"odd.pfm\" is 12x8: it must be square (equal-area) or "
                      "twice as wide as high"));
  const std::string both = R"(LightSource "infinite" "string filename" "sky.pfm" "rgb L" [1 1 1])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + both + "\n", dir.str()), at(2, col(both, "\"rgb")),
                      "an infinite light takes \"L\" or \"filename\", not both"));
  const std::string missing = R"(LightSource "infinite" "string filename" "none.exr")";
  std::string msg = error_of("WorldBegin\n" + missing + "\n", dir.str());
  EXPECT_TRUE(IsError(msg, at(2, col(missing, "\"string")), ""));
  EXPECT_TRUE(Contains(msg, "none.exr"));
  EXPECT_TRUE(IsError(
      error_of(
          "WorldBegin\nScale 1 2 1\nLightSource \"infinite\" \"string filename\" \"sky.pfm\"\n",
          dir.str()),
      at(3, 1), "the transform of an environment light must be a rotation"));
  const std::string portal =
      R"(LightSource "infinite" "string filename" "sky.pfm" "point3 portal" [0 0 0 1 0 0 1 1 0])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + portal + "\n", dir.str()),
                      at(2, col(portal, "\"point3")), "a portal takes 4 points; got 3"));
  const std::string flat =
      R"(LightSource "infinite" "string filename" "sky.pfm" "point3 portal" [0 0 0 1 0 0 1 0 0 2 0 0])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + flat + "\n", dir.str()),
                      at(2, col(flat, "\"point3")), "span no plane"));
  const std::string uniform =
      R"(LightSource "infinite" "rgb L" [1 1 1] "point3 portal" [0 0 0 1 0 0 1 1 0 0 1 0])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + uniform + "\n", dir.str()),
                      at(2, col(uniform, "\"point3")), "a portal needs an image infinite light"));
}

// A portal in the plane z = 0 (p1 - p0 = +y, p3 - p0 = +x: cross(p1 - p0, p3 - p0) = -z points
// into the scene): the light reaches the scene from directions with z > 0 only, its samples all
// come from there, and the texels it never shows are never drawn.
TEST(SceneParse, PortalLightsOnlyTheHalfItFaces) {
  TempDir dir;
  dir.write("sky.pfm", constant_pfm(64, 64, Rgb(1, 1, 1)));
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nLightSource \"infinite\" \"string filename\" \"sky.pfm\" \"point3 portal\" "
      "[0 0 0  0 1 0  1 1 0  1 0 0]\n",
      dir.str()));
  ASSERT_EQ(ls.scene.lights.size(), 1u);
  const Light& light = ls.scene.lights[0];
  const Wavelengths wl = sample_wavelengths(0.3f);
  EXPECT_GT(environment_radiance(light, normalize(Vec3(0.2f, 0.1f, 1)), wl).average(), 0);
  EXPECT_EQ(environment_radiance(light, normalize(Vec3(0.2f, 0.1f, -1)), wl).average(), 0);
  const auto& image = std::get<ImageInfiniteLight>(light);
  Rng rng(3);
  int front = 0;
  for (int i = 0; i < 2000; ++i) {
    float pdf = 0;
    const Vec2 uv = image_light_sample(image, {rng.uniform(), rng.uniform()}, &pdf);
    front += image_light_direction(image, uv).z > -0.1f;  // a texel the horizon crosses
  }
  EXPECT_EQ(front, 2000);
}

TEST(SceneParse, GoniometricAndProjectionLights) {
  TempDir dir;
  dir.write("gonio.pfm", constant_pfm(8, 8, Rgb(0.25f, 0.5f, 0.75f)));
  dir.write("slide.pfm", constant_pfm(8, 4, Rgb(1.0f, 1.0f, 1.0f)));
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nTranslate 1 2 3\n"
      "LightSource \"goniometric\" \"string filename\" \"gonio.pfm\" \"float power\" 10\n"
      "LightSource \"projection\" \"string filename\" \"slide.pfm\" \"float fov\" 40 \"float "
      "scale\" 3\n"
      "LightSource \"projection\" \"string filename\" \"slide.pfm\" \"float power\" 7\n",
      dir.str()));
  ASSERT_EQ(ls.scene.lights.size(), 3u);
  const auto& g = std::get<GoniometricLight>(ls.scene.lights[0]);
  expect_vec_near(g.world_from_light.point(Vec3(0, 0, 0)), Vec3(1, 2, 3));
  EXPECT_NEAR(g.mean_value, 0.5f, 1e-6f);  // the mean of the channels
  // "power": 4 pi times the mean value times the unit-luminance spectrum's scale.
  EXPECT_NEAR(g.intensity.rgb().luminance() * 4 * kPi * g.mean_value, 10.0f, 0.02f);
  const auto& p = std::get<ProjectionLight>(ls.scene.lights[1]);
  EXPECT_NEAR(p.tan_half_fov, std::tan(20 * kPi / 180), 1e-6f);
  EXPECT_FLOAT_EQ(p.half_width, 2);
  EXPECT_FLOAT_EQ(p.half_height, 1);
  EXPECT_FLOAT_EQ(p.scale, 3);
  const auto& q = std::get<ProjectionLight>(ls.scene.lights[2]);
  EXPECT_NEAR(q.tan_half_fov, 1.0f, 1e-6f);  // pbrt-v4's default fov, 90
  EXPECT_NEAR(q.power_rgb.luminance(), 7.0f, 1e-3f);
}

TEST(SceneFlattenError, GoniometricAndProjectionErrors) {
  TempDir dir;
  dir.write("wide.pfm", constant_pfm(8, 4, Rgb(1.0f)));
  const std::string wide = R"(LightSource "goniometric" "string filename" "wide.pfm")";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + wide + "\n", dir.str()),
                      at(2, col(wide, "\"string")),
                      "goniometric image \"wide.pfm\" is 8x4: it must be square"));
  EXPECT_TRUE(IsError(error_of("WorldBegin\nLightSource \"goniometric\"\n", dir.str()), at(2, 1),
                      "goniometric light needs \"string filename\""));
  EXPECT_TRUE(
      IsError(error_of("WorldBegin\nLightSource \"projection\" \"float fov\" 30\n", dir.str()),
              at(2, 1), "projection light needs \"string filename\""));
  const std::string fov =
      R"(LightSource "projection" "string filename" "wide.pfm" "float fov" 180)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + fov + "\n", dir.str()), at(2, col(fov, "\"float")),
                      "projection fov must be in (0, 180) degrees"));
}

TEST(SceneFlattenError, AreaLightOnPartialSphere) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\"\n"
                               "Shape \"sphere\" \"float zmax\" 0.5\nAttributeEnd\n"),
                      at(3, 1), "emitting spheres and disks must be whole"));
}

TEST(SceneFlattenError, AreaLightOnNonUniformlyScaledDisk) {
  EXPECT_TRUE(
      IsError(error_of("WorldBegin\nScale 1 2 1\nAreaLightSource \"diffuse\"\nShape \"disk\"\n"),
              at(3, 1), "not non-uniformly scaled"));
}

TEST(SceneParse, ImageAreaLight) {
  TempDir dir;
  dir.write("glow.pfm", constant_pfm(4, 2, Rgb(0.5f, 1.0f, 2.0f)));
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"string filename\" \"glow.pfm\" "
      "\"float scale\" 3\n"
      "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\nAttributeEnd\n"
      "AreaLightSource \"diffuse\" \"string filename\" \"glow.pfm\" \"float power\" 5\n"
      "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n",
      dir.str()));
  ASSERT_EQ(ls.scene.lights.size(), 2u);
  const auto& a = std::get<AreaLight>(ls.scene.lights[0]);
  ASSERT_TRUE(a.image != nullptr);
  EXPECT_FLOAT_EQ(a.image_scale, 3);
  EXPECT_NEAR(a.image_mean[2], 2.0f, 1e-6f);
  // "power": pi A times the image's mean luminance times the scale.
  const auto& b = std::get<AreaLight>(ls.scene.lights[1]);
  EXPECT_NEAR(b.image_scale * b.image_mean.luminance() * kPi * 0.5f, 5.0f, 1e-3f);
  const std::string both =
      R"(AreaLightSource "diffuse" "string filename" "glow.pfm" "rgb L" [1 1 1])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + both + "\nShape \"sphere\"\n", dir.str()),
                      at(2, col(both, "\"rgb")),
                      "an area light takes \"L\" or \"filename\", not both"));
}

TEST(SceneFlattenError, UnsupportedAreaLight) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nAreaLightSource \"projection\"\nShape \"sphere\"\n"),
                      at(2, 1), "area light \"projection\" is not supported"));
}

// pbrt-v4 reads a dielectric's or a coat's index as a value or a spectrum only.
TEST(SceneFlattenError, TexturedEta) {
  const std::string tex = "Texture \"e\" \"float\" \"constant\" \"float value\" 1.4";
  for (const std::string& material :
       {std::string(R"(Material "dielectric" "texture eta" "e")"),
        std::string(R"(Material "coatedconductor" "texture interface.eta" "e")")}) {
    EXPECT_TRUE(IsError(error_of("WorldBegin\n" + tex + "\n" + material + "\nShape \"sphere\"\n"),
                        at(3, col(material, "\"texture")),
                        "takes a value or a spectrum, not a texture"))
        << material;
  }
}

TEST(SceneFlattenError, UnknownCameraType) {
  EXPECT_TRUE(IsError(error_of("Camera \"fisheye\"\nWorldBegin\n"), at(1, 1),
                      "camera \"fisheye\" is unknown (perspective, orthographic, spherical, "
                      "realistic)"));
}

TEST(SceneFlattenError, BadCameraParameters) {
  const std::string mapping = R"(Camera "spherical" "string mapping" "cube")";
  EXPECT_TRUE(IsError(error_of(mapping + "\nWorldBegin\n"), at(1, col(mapping, "\"string")),
                      "spherical camera mapping \"cube\" is unknown (equalarea, equirectangular)"));
  const std::string aspect = R"(Camera "orthographic" "float frameaspectratio" -1)";
  EXPECT_TRUE(IsError(error_of(aspect + "\nWorldBegin\n"), at(1, col(aspect, "\"float")),
                      "frameaspectratio must be positive"));
  const std::string window = R"(Camera "orthographic" "float screenwindow" [1 1 -1 1])";
  EXPECT_TRUE(IsError(error_of(window + "\nWorldBegin\n"), at(1, col(window, "\"float")),
                      "screenwindow is empty"));
}

// pbrt-v4's realistic camera: a lens file (mm), the stop narrowed to aperturediameter, focused at
// focusdistance, on a film of the given diagonal; each mistake named where it is.
TEST(SceneParse, RealisticCamera) {
  TempDir dir;
  dir.write("lens.dat",
            "# r thickness eta diameter\n0 5 0 20\n51.68 6 1.5168 24\n-51.68 45 1 24\n");
  LoadedScene ls = flatten_scene(parse_scene_string(
      "Camera \"realistic\" \"string lensfile\" \"lens.dat\" \"float aperturediameter\" 4 "
      "\"float focusdistance\" 3\nFilm \"rgb\" \"float diagonal\" 20 \"integer xresolution\" 40 "
      "\"integer yresolution\" 30\nWorldBegin\n",
      dir.str()));
  EXPECT_EQ(ls.camera.projection, Projection::kRealistic);
  ASSERT_TRUE(ls.camera.lens);
  EXPECT_NEAR(ls.camera.lens->effective_focal_length(), 0.051f, 0.002f);
  // A 4:3 film of 20 mm diagonal: pixels 16 mm / 40 wide.
  EXPECT_NEAR(ls.camera.lens->pixel_spread() * ls.camera.lens->effective_focal_length(),
              0.016f / 40, 0.03f * 0.016f / 40);
  EXPECT_EQ(ls.data_files.size(), 1u);

  auto camera = [](const std::string& params) { return "Camera \"realistic\" " + params; };
  const std::string none = camera("\"float focusdistance\" 3");
  EXPECT_TRUE(IsError(error_of(none + "\nWorldBegin\n", dir.str()), at(1, 1),
                      "a realistic camera needs a \"lensfile\""));
  const std::string missing = camera("\"string lensfile\" \"no.dat\"");
  EXPECT_TRUE(IsError(error_of(missing + "\nWorldBegin\n", dir.str()),
                      at(1, col(missing, "\"string")), "lens file \"no.dat\" cannot be read"));
  dir.write("short.dat", "0 5 0 20\n51.68 6 1.5168\n-51.68 45 1 24\n");
  EXPECT_TRUE(
      IsError(error_of(camera("\"string lensfile\" \"short.dat\"") + "\nWorldBegin\n", dir.str()),
              "short.dat:2:1", "a lens element takes 4 values"));
  dir.write("text.dat", "0 5 0 20\n51.68 six 1.5168 24\n");
  EXPECT_TRUE(
      IsError(error_of(camera("\"string lensfile\" \"text.dat\"") + "\nWorldBegin\n", dir.str()),
              "text.dat:2:1", "a lens file holds numbers only"));
  const std::string close = camera("\"string lensfile\" \"lens.dat\" \"float focusdistance\" 0.05");
  EXPECT_TRUE(
      IsError(error_of(close + "\nWorldBegin\n", dir.str()), at(1, 1), "the lens cannot focus at"));
  const std::string shape = camera("\"string lensfile\" \"lens.dat\" \"string aperture\" \"hex\"");
  EXPECT_TRUE(IsError(error_of(shape + "\nWorldBegin\n", dir.str()),
                      at(1, col(shape, "\"string aperture")),
                      "is neither a built-in shape (gaussian, square, pentagon, star)"));
  const std::string diagonal = "Film \"rgb\" \"float diagonal\" 0";
  EXPECT_TRUE(IsError(error_of(diagonal + "\nWorldBegin\n", dir.str()),
                      at(1, col(diagonal, "\"float")), "diagonal must be positive"));
  // An aperture wider than the stop is the stop's, with a warning (as pbrt-v4).
  const int warnings = warning_count();
  EXPECT_EQ(error_of(camera("\"string lensfile\" \"lens.dat\" \"float aperturediameter\" 30") +
                         "\nWorldBegin\n",
                     dir.str()),
            "");
  EXPECT_EQ(warning_count(), warnings + 1);
  for (const char* builtin : {"gaussian", "square", "pentagon", "star"})
    EXPECT_EQ(error_of(camera("\"string lensfile\" \"lens.dat\" \"string aperture\" \"" +
                              std::string(builtin) + "\"") +
                           "\nWorldBegin\n",
                       dir.str()),
              "")
        << builtin;
}

TEST(SceneFlattenError, FovOutOfRange) {
  EXPECT_TRUE(IsError(error_of("Camera \"perspective\" \"float fov\" 180\nWorldBegin\n"), at(1, 1),
                      "fov must lie in (0, 180) degrees"));
}

TEST(SceneFlattenError, FilmResolutionZero) {
  EXPECT_TRUE(IsError(error_of("Film \"rgb\" \"integer xresolution\" 0\nWorldBegin\n"), at(1, 1),
                      "film resolution must be between 1 and 65536"));
}

TEST(SceneFlattenError, UnsupportedFilm) {
  EXPECT_TRUE(IsError(error_of("Film \"gbuffer\"\nWorldBegin\n"), at(1, 1),
                      "film \"gbuffer\" is not supported"));
}

TEST(SceneFlattenError, UnknownPixelFilter) {
  EXPECT_TRUE(IsError(error_of("PixelFilter \"blackman\"\nWorldBegin\n"), at(1, 1),
                      "pixel filter \"blackman\" is unknown"));
}

TEST(SceneFlattenError, UnknownSampler) {
  EXPECT_TRUE(IsError(error_of("Sampler \"lowdiscrepancy\"\nWorldBegin\n"), at(1, 1),
                      "sampler \"lowdiscrepancy\" is unknown"));
}

TEST(SceneFlattenError, UnsupportedIntegrator) {
  EXPECT_TRUE(IsError(error_of("Integrator \"ambientocclusion\"\nWorldBegin\n"), at(1, 1),
                      "integrator \"ambientocclusion\" is not supported"));
}

TEST(SceneFlattenError, ParameterOfWrongType) {
  const std::string l2 = R"(Shape "sphere" "integer radius" 2)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"integer")),
                      "parameter \"radius\" has type \"integer\"; expected \"float\""));
}

TEST(SceneFlattenError, ParameterTakesOneValue) {
  const std::string l2 = R"(Shape "sphere" "float radius" [1 2])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"float")),
                      "parameter \"radius\" takes one value; got 2"));
}

TEST(SceneParams, CoatedDiffuse) {
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nMaterial \"coateddiffuse\" \"rgb reflectance\" [0.2 0.4 0.6] \"float "
      "roughness\" 0.04 "
      "\"float thickness\" 0.05 \"float eta\" 1.33 \"integer maxdepth\" 5 \"integer nsamples\" 2\n"
      "Shape \"sphere\"\nMaterial \"coateddiffuse\"\nShape \"sphere\"\n"));
  const MaterialDesc& m = ls.scene.materials[ls.scene.objects[0].material];
  ASSERT_TRUE(std::holds_alternative<CoatedDiffuseDesc>(m));
  const CoatedDiffuseDesc& c = std::get<CoatedDiffuseDesc>(m);
  expect_spectrum_near(c.reflectance, Rgb(0.2f, 0.4f, 0.6f));
  EXPECT_NEAR(c.layer.roughness.alpha_x, 0.2f, 1e-6f);  // remapped
  EXPECT_FLOAT_EQ(c.layer.thickness, 0.05f);
  EXPECT_FLOAT_EQ(c.layer.eta, 1.33f);
  EXPECT_EQ(c.layer.max_depth, 5);
  EXPECT_EQ(c.layer.samples, 2);
  // pbrt-v4's defaults.
  const CoatedDiffuseDesc& d =
      std::get<CoatedDiffuseDesc>(ls.scene.materials[ls.scene.objects[1].material]);
  expect_spectrum_near(d.reflectance, Rgb(0.5f));
  EXPECT_FLOAT_EQ(d.layer.thickness, 0.01f);
  EXPECT_FLOAT_EQ(d.layer.eta, 1.5f);
  EXPECT_EQ(d.layer.max_depth, 10);
  EXPECT_EQ(d.layer.samples, 1);
  EXPECT_TRUE(d.layer.roughness.effectively_smooth());
  // Each constant coat gets its walks' table, which reaches the resolved material.
  ASSERT_TRUE(c.walk_table);
  EXPECT_TRUE(c.walk_table->made_for(c.layer));
  const Wavelengths wl = sample_wavelengths(0.5f);
  EXPECT_EQ(std::get<CoatedDiffuseMaterial>(resolve_material(m, wl)).walk_table,
            c.walk_table.get());
  ASSERT_TRUE(d.walk_table);
  EXPECT_TRUE(d.walk_table->made_for(d.layer));
}

TEST(SceneParams, CoatedDiffuseWithTexturedRoughnessHasNoWalkTable) {
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nTexture \"r\" \"float\" \"checkerboard\" \"float tex1\" 0.1 \"float tex2\" "
      "0.3\nMaterial \"coateddiffuse\" \"texture roughness\" \"r\"\nShape \"sphere\"\n"));
  const auto& c = std::get<CoatedDiffuseDesc>(ls.scene.materials[ls.scene.objects[0].material]);
  EXPECT_TRUE(c.roughness_tex.any());
  EXPECT_FALSE(c.walk_table);
}

TEST(SceneParams, CoatedConductor) {
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nMaterial \"coatedconductor\" \"float interface.roughness\" 0.09 \"float "
      "interface.eta\" 1.4 "
      "\"spectrum conductor.eta\" \"metal-Au-eta\" \"spectrum conductor.k\" \"metal-Au-k\" "
      "\"float conductor.roughness\" 0.16 \"float thickness\" 0.02\nShape \"sphere\"\n"
      "Material \"coatedconductor\" \"rgb reflectance\" [0.9 0.5 0.2]\nShape \"sphere\"\n"));
  const auto& c = std::get<CoatedConductorDesc>(ls.scene.materials[ls.scene.objects[0].material]);
  EXPECT_NEAR(c.layer.roughness.alpha_x, 0.3f, 1e-6f);
  EXPECT_FLOAT_EQ(c.layer.eta, 1.4f);
  EXPECT_FLOAT_EQ(c.layer.thickness, 0.02f);
  EXPECT_NEAR(c.conductor.roughness.alpha_x, 0.4f, 1e-6f);
  expect_spectrum_near(c.conductor.eta, *named_spectrum("metal-Au-eta", SpectrumKind::kUnbounded));
  const auto& d = std::get<CoatedConductorDesc>(ls.scene.materials[ls.scene.objects[1].material]);
  ASSERT_TRUE(d.conductor.reflectance.has_value());
  expect_spectrum_near(*d.conductor.reflectance, Rgb(0.9f, 0.5f, 0.2f));
  EXPECT_FLOAT_EQ(d.layer.eta, 1.5f);
  EXPECT_TRUE(d.layer.roughness.effectively_smooth());
}

TEST(SceneFlattenError, CoatedDiffuseBadValues) {
  const std::string l1 = R"(Material "coateddiffuse" "float thickness" -1)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l1 + "\nShape \"sphere\"\n"),
                      at(2, col(l1, "\"float thickness")), "thickness must be positive"));
  const std::string l2 = R"(Material "coateddiffuse" "rgb albedo" [0.5 0.5 0.5] "float g" 1)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\nShape \"sphere\"\n"),
                      at(2, col(l2, "\"float g")), "g must lie in (-1, 1)"));
  const std::string l3 = R"(Material "coateddiffuse" "integer maxdepth" 0)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l3 + "\nShape \"sphere\"\n"),
                      at(2, col(l3, "\"integer maxdepth")), "maxdepth must be in [1, 1000]"));
}

TEST(SceneParams, LoopSubdivisionMesh) {
  LoadedScene ls = flatten_scene(parse_scene_string(
      "WorldBegin\nShape \"loopsubdiv\" \"integer levels\" 2 \"point3 P\" [1 0 0 -1 0 0 0 1 0 0 -1 "
      "0 0 0 1 0 0 -1] "
      "\"integer indices\" [0 2 4 2 1 4 1 3 4 3 0 4 2 0 5 1 2 5 3 1 5 0 3 5]\n"));
  ASSERT_EQ(ls.scene.objects.size(), 1u);
  const auto& m = std::get<TriangleMesh>(ls.scene.objects[0].shape);
  EXPECT_EQ(m.indices.size(), 24u * 16);
  EXPECT_EQ(m.positions.size(), 66u);
  EXPECT_EQ(m.normals.size(), m.positions.size());  // shading normals
}

TEST(SceneFlattenError, LoopSubdivisionBadInput) {
  const std::string l1 =
      R"(Shape "loopsubdiv" "integer levels" -1 "point3 P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 2])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l1 + "\n"), at(2, col(l1, "\"integer levels")),
                      "loopsubdiv levels must be in [0, 8]"));
  const std::string l2 =
      R"(Shape "loopsubdiv" "point3 P" [0 0 0 1 0 0 0 1 0 0 -1 0 0 0 1] "integer indices" [0 1 2 1 0 3 0 1 4])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, 1),
                      "loopsubdiv: an edge is shared by more than two triangles"));
  const std::string l3 =
      R"(Shape "loopsubdiv" "point3 P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 5])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l3 + "\n"), at(2, col(l3, "\"integer indices")),
                      "vertex index 5 out of range (3 vertices)"));
}

TEST(SceneFlattenError, UnknownNamedSpectrum) {
  TempDir dir;
  const std::string l2 = R"(Material "conductor" "spectrum eta" "metal-Unobtainium")";
  EXPECT_TRUE(IsError(
      error_of("WorldBegin\n" + l2 + "\nShape \"sphere\"\n", dir.str()),
      at(2, col(l2, "\"spectrum")),
      "\"metal-Unobtainium\" is neither a known named spectrum nor a readable spectrum file"));
}

TEST(SceneFlattenError, SpectrumFileWithText) {
  TempDir dir;
  dir.write("bad.spd", "400 0.5\n500 half\n");
  const std::string l2 = R"(Material "diffuse" "spectrum reflectance" "bad.spd")";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\nShape \"sphere\"\n", dir.str()),
                      at(2, col(l2, "\"spectrum")),
                      "spectrum file \"bad.spd\" holds something other than numbers"));
}

TEST(SceneFlattenError, SpectrumWavelengthsMustIncrease) {
  const std::string l2 = R"(Material "diffuse" "spectrum reflectance" [500 0.5 400 0.5])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\nShape \"sphere\"\n"),
                      at(2, col(l2, "\"spectrum")), "spectrum wavelengths must increase"));
}

TEST(SceneFlattenError, BlackbodyNonPositive) {
  const std::string l2 = R"(LightSource "point" "blackbody I" -10)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\n"), at(2, col(l2, "\"blackbody")),
                      "blackbody temperature must be positive"));
}

TEST(SceneFlattenError, UnknownTexture) {
  const std::string l2 = R"(Material "diffuse" "texture reflectance" "nope")";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\nShape \"sphere\"\n"),
                      at(2, col(l2, "\"texture")), "unknown texture \"nope\""));
}

TEST(SceneFlattenError, TextureErrorsNameTheDirective) {
  const std::string tex =
      "Texture \"img\" \"spectrum\" \"imagemap\" \"string filename\" \"missing.png\"";
  const std::string use = R"(Material "diffuse" "texture reflectance" "img")";
  // A missing image: at its filename, naming the file.
  std::string e = error_of("WorldBegin\n" + tex + "\n" + use + "\nShape \"sphere\"\n");
  EXPECT_TRUE(IsError(e, at(2, col(tex, "\"string filename")), "missing.png"));
  // Unknown class, a float texture where a spectrum is needed, and the reverse.
  EXPECT_TRUE(IsError(error_of("WorldBegin\nTexture \"n\" \"spectrum\" \"fbm\"\n" +
                               use.substr(0, use.size() - 5) + "\"n\"\nShape \"sphere\"\n"),
                      at(2, 1), "texture class \"fbm\" is not supported"));
  EXPECT_TRUE(
      IsError(error_of("WorldBegin\nTexture \"c\" \"float\" \"checkerboard\"\n"
                       "Material \"diffuse\" \"texture reflectance\" \"c\"\nShape \"sphere\"\n"),
              at(2, 1), "is a float texture; a spectrum texture is needed here"));
  EXPECT_TRUE(
      IsError(error_of("WorldBegin\nTexture \"c\" \"spectrum\" \"checkerboard\"\n"
                       "Material \"conductor\" \"texture roughness\" \"c\"\nShape \"sphere\"\n"),
              at(2, 1), "is a spectrum texture; a float texture is needed here"));
  // Unknown names and modes.
  const std::string l3 = R"(Material "diffuse" "texture reflectance" "nope")";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n\n" + l3 + "\nShape \"sphere\"\n"),
                      at(3, col(l3, "\"texture")), "unknown texture \"nope\""));
  const std::string wrap = R"(Texture "c" "spectrum" "checkerboard" "string mapping" "cubic")";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + wrap +
                               "\nMaterial \"diffuse\" \"texture reflectance\" \"c\"\n"
                               "Shape \"sphere\"\n"),
                      at(2, col(wrap, "\"string mapping")),
                      "texture mapping \"cubic\" is unknown"));
}

TEST(SceneParse, MixMaterialNamesTwoMaterials) {
  LoadedScene ls = flatten_scene(
      parse_scene_string("WorldBegin\nMakeNamedMaterial \"a\" \"string type\" \"diffuse\"\n"
                         "MakeNamedMaterial \"b\" \"string type\" \"conductor\"\n"
                         "Texture \"t\" \"float\" \"checkerboard\"\n"
                         "MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string materials\" "
                         "[\"a\" \"b\"] \"texture amount\" \"t\"\n"
                         "NamedMaterial \"m\"\nShape \"sphere\"\n"
                         "Material \"mix\" \"string materials\" [\"b\" \"m\"] \"float amount\" "
                         "0.3\nShape \"sphere\"\n"));
  const auto* m = std::get_if<MixDesc>(&ls.scene.materials[size_t(ls.scene.objects[0].material)]);
  ASSERT_TRUE(m);
  EXPECT_TRUE(std::holds_alternative<DiffuseDesc>(ls.scene.materials[size_t(m->materials[0])]));
  EXPECT_TRUE(std::holds_alternative<ConductorDesc>(ls.scene.materials[size_t(m->materials[1])]));
  EXPECT_TRUE(m->amount.textured());
  const auto* n = std::get_if<MixDesc>(&ls.scene.materials[size_t(ls.scene.objects[1].material)]);
  ASSERT_TRUE(n);
  EXPECT_FLOAT_EQ(n->amount.value, 0.3f);
  EXPECT_EQ(n->materials[1], ls.scene.objects[0].material);  // a mix of a mix
  EXPECT_TRUE(material_is_textured(ls.scene.materials[size_t(ls.scene.objects[1].material)]));
  // The choice: amount 0 and 1 pick one side everywhere; the checkerboard amount (1 then 0)
  // picks by cell; the nested mix ends at a material that is not a mix.
  TextureContext in_first{{0, 0, 0}, {0.5f, 0.5f}}, in_second{{0, 0, 0}, {1.5f, 0.5f}};
  EXPECT_EQ(choose_mix(ls.scene, ls.scene.objects[0].material, in_first), m->materials[1]);
  EXPECT_EQ(choose_mix(ls.scene, ls.scene.objects[0].material, in_second), m->materials[0]);
  int hits_b = 0;
  for (int i = 0; i < 1000; ++i) {
    TextureContext c{{float(i) * 0.013f, 0.5f, -float(i) * 0.007f}, {1.5f, 0.5f}};
    int chosen = choose_mix(ls.scene, ls.scene.objects[1].material, c);
    EXPECT_FALSE(std::holds_alternative<MixDesc>(ls.scene.materials[size_t(chosen)]));
    hits_b += chosen == n->materials[0];
    EXPECT_EQ(chosen,
              choose_mix(ls.scene, ls.scene.objects[1].material, c));  // the same every time
  }
  EXPECT_NEAR(hits_b / 1000.0, 0.7, 0.05);  // "b" directly with 1 - 0.3, "a" through "m" otherwise
}

TEST(SceneFlattenError, MixMaterialErrors) {
  const std::string one = R"(Material "mix" "string materials" "a")";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + one + "\nShape \"sphere\"\n"),
                      at(2, col(one, "\"string materials")),
                      "mix needs \"string materials\" with two named materials"));
  const std::string unknown = R"(Material "mix" "string materials" ["a" "b"])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + unknown + "\nShape \"sphere\"\n"),
                      at(2, col(unknown, "\"string materials")), "unknown named material \"a\""));
  const std::string self =
      R"(MakeNamedMaterial "a" "string type" "mix" "string materials" ["a" "a"])";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + self + "\nNamedMaterial \"a\"\nShape \"sphere\"\n"),
                      at(2, col(self, "\"string materials")),
                      "named material \"a\" contains itself"));
}

TEST(SceneFlattenError, ConductorWithReflectanceAndEta) {
  EXPECT_TRUE(
      IsError(error_of("WorldBegin\nMaterial \"conductor\" \"rgb reflectance\" [0.5 0.5 0.5] "
                       "\"spectrum eta\" \"metal-Au-eta\"\nShape \"sphere\"\n"),
              at(2, 1), "conductor has both reflectance and eta/k"));
}

TEST(SceneFlattenError, DielectricNegativeEta) {
  const std::string l2 = R"(Material "dielectric" "float eta" -1.5)";
  EXPECT_TRUE(IsError(error_of("WorldBegin\n" + l2 + "\nShape \"sphere\"\n"),
                      at(2, col(l2, "\"float")), "eta must be positive"));
}

TEST(SceneFlattenError, SpotLightFromEqualsTo) {
  EXPECT_TRUE(IsError(
      error_of("WorldBegin\nLightSource \"spot\" \"point3 from\" [1 1 1] \"point3 to\" [1 1 1]\n"),
      at(2, 1), "spot light with from == to"));
}

TEST(SceneFlattenError, NegativeLightScale) {
  EXPECT_TRUE(IsError(error_of("WorldBegin\nLightSource \"point\" \"float scale\" -1\n"), at(2, 1),
                      "light scale must be a non-negative number"));
}

// ---------------------------------------------------------------------------------------------
// Warnings

TEST(SceneWarnings, UnusedParameterWarns) {
  ParsedScene p =
      parse_scene_string("WorldBegin\nShape \"sphere\" \"float radius\" 2 \"float bogus\" 1\n");
  int before = warning_count();
  (void)flatten_scene(p);
  EXPECT_EQ(warning_count() - before, 1);
  EXPECT_FALSE(p.shapes[0].params.find_any("bogus")->used);
  EXPECT_TRUE(p.shapes[0].params.find_any("radius")->used);
}

TEST(SceneWarnings, NoWarningWhenAllParametersAreUsed) {
  ParsedScene p = parse_scene_string(
      "WorldBegin\nMaterial \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\nShape \"sphere\" "
      "\"float radius\" 2\n");
  int before = warning_count();
  (void)flatten_scene(p);
  EXPECT_EQ(warning_count(), before);
}

TEST(SceneWarnings, UnusedMaterialParameterWarns) {
  ParsedScene p =
      parse_scene_string("WorldBegin\nMaterial \"diffuse\" \"float sigma\" 20\nShape \"sphere\"\n");
  int before = warning_count();
  (void)flatten_scene(p);
  EXPECT_EQ(warning_count() - before, 1);
}

// ---------------------------------------------------------------------------------------------
// PLY reader

TEST(PlyReader, AsciiQuadIsTwoTriangles) {
  TempDir dir;
  fs::path path = dir.write("quad.ply", kAsciiQuadPly);
  PlyMesh m = read_ply(path.string(), FileLoc{"scene.pbrt", 3, 5});
  ASSERT_EQ(m.positions.size(), 4u);
  expect_vec_near(m.positions[2], Vec3(1, 1, 0));
  EXPECT_TRUE(m.normals.empty());
  EXPECT_TRUE(m.uvs.empty());
  EXPECT_EQ(m.quads, 1);
  EXPECT_EQ(m.indices.size(), 6u);  // two triangles
  EXPECT_EQ(m.indices, (std::vector<int>{0, 1, 2, 0, 2, 3}));
}

TEST(PlyReader, BinaryLittleEndianRoundTrip) {
  TempDir dir;
  std::string ply =
      "ply\r\nformat binary_little_endian 1.0\r\n"
      "element vertex 4\r\n"
      "property float x\r\nproperty float y\r\nproperty float z\r\n"
      "property float nx\r\nproperty float ny\r\nproperty float nz\r\n"
      "property float u\r\nproperty float v\r\n"
      "element face 2\r\nproperty list uchar int vertex_indices\r\nend_header\n";
  const float verts[4][8] = {{0, 0, 0, 0, 0, 1, 0, 0},
                             {1, 0, 0, 0, 0, 1, 1, 0},
                             {1, 1, 0, 0, 0, 1, 1, 1},
                             {0, 1, 0.5f, 0, 0, 1, 0, 1}};
  for (const auto& v : verts)
    for (float x : v) put_le(&ply, x);
  put_le<uint8_t>(&ply, 3);
  for (int i : {0, 1, 2}) put_le<int32_t>(&ply, i);
  put_le<uint8_t>(&ply, 4);
  for (int i : {0, 1, 2, 3}) put_le<int32_t>(&ply, i);
  fs::path path = dir.write("mesh.ply", ply);

  PlyMesh m = read_ply(path.string(), FileLoc{"scene.pbrt", 1, 1});
  ASSERT_EQ(m.positions.size(), 4u);
  ASSERT_EQ(m.normals.size(), 4u);
  ASSERT_EQ(m.uvs.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    expect_vec_near(m.positions[i], Vec3(verts[i][0], verts[i][1], verts[i][2]), 0);
    expect_vec_near(m.normals[i], Vec3(verts[i][3], verts[i][4], verts[i][5]), 0);
    EXPECT_EQ(m.uvs[i].x, verts[i][6]);
    EXPECT_EQ(m.uvs[i].y, verts[i][7]);
  }
  EXPECT_EQ(m.quads, 1);
  EXPECT_EQ(m.indices, (std::vector<int>{0, 1, 2, 0, 1, 2, 0, 2, 3}));
}

TEST(PlyReader, BinaryBigEndianWithDoublesAndExtraProperties) {
  TempDir dir;
  std::string ply =
      "ply\nformat binary_big_endian 1.0\n"
      "element vertex 3\n"
      "property double x\nproperty double y\nproperty double z\nproperty uchar red\n"
      "element face 1\nproperty uchar flags\nproperty list ushort uint "
      "vertex_indices\nend_header\n";
  const double verts[3][3] = {{0, 0, 0}, {2, 0, 0}, {0, 3, -1}};
  for (const auto& v : verts) {
    for (double x : v) put_be(&ply, x);
    put_be<uint8_t>(&ply, 200);
  }
  put_be<uint8_t>(&ply, 7);
  put_be<uint16_t>(&ply, 3);
  for (uint32_t i : {2u, 1u, 0u}) put_be(&ply, i);
  fs::path path = dir.write("be.ply", ply);

  PlyMesh m = read_ply(path.string(), FileLoc{});
  ASSERT_EQ(m.positions.size(), 3u);
  expect_vec_near(m.positions[2], Vec3(0, 3, -1), 0);
  EXPECT_TRUE(m.normals.empty());
  EXPECT_EQ(m.quads, 0);
  EXPECT_EQ(m.indices, (std::vector<int>{2, 1, 0}));
}

TEST(PlyReader, MissingFile) {
  TempDir dir;
  std::string path = (dir.path() / "nope.ply").string();
  try {
    (void)read_ply(path, FileLoc{"scene.pbrt", 3, 5});
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_TRUE(IsError(e.what(), "scene.pbrt:3:5", "cannot open PLY file \"" + path + "\""));
  }
}

TEST(PlyReader, NotAPlyFile) {
  TempDir dir;
  fs::path path = dir.write("x.ply", "OFF\n3 1 0\n");
  try {
    (void)read_ply(path.string(), FileLoc{"scene.pbrt", 3, 5});
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_TRUE(IsError(e.what(), "scene.pbrt:3:5", "missing 'ply' magic"));
  }
}

// Found by fuzzing (scripts/fuzz.sh, ply_fuzzer): an unsigned index past the range of int was
// converted to int (undefined behaviour) before the range check.
TEST(PlyReader, IndexBeyondIntIsAnError) {
  TempDir dir;
  fs::path path = dir.write(
      "huge.ply",
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2172748161\n");
  try {
    (void)read_ply(path.string(), FileLoc{"scene.pbrt", 3, 5});
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_TRUE(IsError(e.what(), "scene.pbrt:3:5", "bad vertex index 2172748161"));
  }
}

// Found by fuzzing (ply_fuzzer): a list length stored as a float NaN passed the length check and
// was converted to int.
TEST(PlyReader, ListLengthThatIsNotACountIsAnError) {
  TempDir dir;
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list float int vertex_indices\nend_header\n";
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put_le(&ply, v);
  put_le(&ply, std::numeric_limits<float>::quiet_NaN());
  for (int32_t i : {0, 1, 2}) put_le(&ply, i);
  fs::path path = dir.write("nan.ply", ply);
  try {
    (void)read_ply(path.string(), FileLoc{"scene.pbrt", 3, 5});
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_TRUE(IsError(e.what(), "scene.pbrt:3:5", "bad list length"));
  }
}

// Found by fuzzing (ply_fuzzer): an element count past the range of long long was read as the
// largest one, and an element without properties then looped that many times.
TEST(PlyReader, ElementCountOutOfRangeIsAnError) {
  TempDir dir;
  fs::path path = dir.write("count.ply",
                            "ply\nformat ascii 1.0\nelement thing 99999999999999999999999\n"
                            "element vertex 1\nproperty float x\nproperty float y\n"
                            "property float z\nend_header\n0 0 0\n");
  try {
    (void)read_ply(path.string(), FileLoc{"scene.pbrt", 3, 5});
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_TRUE(IsError(e.what(), "scene.pbrt:3:5", "bad element line"));
  }
}

TEST(PlyReader, ElementWithoutPropertiesIsSkipped) {
  TempDir dir;
  fs::path path = dir.write("empty.ply",
                            "ply\nformat ascii 1.0\nelement thing 4000000000000\n"
                            "element vertex 3\nproperty float x\nproperty float y\n"
                            "property float z\nelement face 1\n"
                            "property list uchar int vertex_indices\nend_header\n"
                            "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  PlyMesh m = read_ply(path.string(), FileLoc{"scene.pbrt", 3, 5});
  EXPECT_EQ(m.positions.size(), 3u);
  EXPECT_EQ(m.indices.size(), 3u);
}

TEST(PlyReader, FaceWithFiveVertices) {
  TempDir dir;
  fs::path path = dir.write(
      "penta.ply",
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n-1 0.5 0\n5 0 1 2 3 4\n");
  try {
    (void)read_ply(path.string(), FileLoc{"scene.pbrt", 3, 5});
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_TRUE(IsError(e.what(), "scene.pbrt:3:5", "face with 5 vertices"));
  }
}

TEST(PlyReader, TruncatedAscii) {
  TempDir dir;
  fs::path path = dir.write(
      "short.ply",
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n");
  try {
    (void)read_ply(path.string(), FileLoc{"scene.pbrt", 3, 5});
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_TRUE(IsError(e.what(), "scene.pbrt:3:5", "truncated or malformed data"));
  }
}

}  // namespace
}  // namespace bpm
