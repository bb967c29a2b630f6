// pbrt-v4's textures: functions of the surface point that materials read their parameters from.
// A scene's textures are nodes of one TextureSet (a texture may read others: scale, mix,
// checkerboard); a material parameter names a node, or holds a constant.
//
// Without ray differentials bpm evaluates every texture at a point: an image is sampled with the
// "point" or "bilinear" filter of its finest level, and a checkerboard is not antialiased. Both
// converge to the same image as pbrt-v4's filtered lookups once pixels take many samples.
#pragma once
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "base/color.h"
#include "base/transform.h"
#include "base/vec.h"

namespace bpm {

// Where a texture is evaluated: the world-space point and the surface's (u, v).
struct TextureContext {
  Vec3 p;
  Vec2 uv;
};

enum class TexWrap { kRepeat, kClamp, kBlack, kOctahedralSphere };
enum class TexFilter { kPoint, kBilinear };

// Linear texel values, rows from the top of the image (as files store them); 1 or 3 channels.
struct TexImage {
  int width = 0, height = 0, channels = 3;
  std::vector<float> texels;
  std::string path;
  Rgb texel(int x, int y, TexWrap wrap) const;
  // The texel containing st (in [0, 1]^2 over the image, t down) or the bilinear blend of the
  // four nearest texel centres, pbrt-v4's Image::Bilerp.
  Rgb lookup(Vec2 st, TexFilter filter, TexWrap wrap) const;
};

// How 8-bit texels are decoded to linear values (pbrt-v4's "encoding"); float images are linear.
struct TexEncoding {
  enum class Kind { kSrgb, kLinear, kGamma } kind = Kind::kSrgb;
  float gamma = 2.2f;
};

// Reads an image through OpenImageIO (PNG, JPEG, TGA, EXR, PFM, HDR, TIFF, ...). Integer formats
// are decoded with the encoding; float formats are kept as they are. Images are cached by path and
// encoding. Throws Error naming the file. Builds the table of texel spectra (base/color.h) first
// unless the image's texels are never colours (a normal map): about 0.7 s of CPU, once.
std::shared_ptr<const TexImage> load_texture_image(const std::string& path,
                                                   const TexEncoding& encoding,
                                                   bool colours = true);
// The same without the cache (and without building the texel-spectrum table).
std::shared_ptr<const TexImage> read_texture_image(const std::string& path,
                                                   const TexEncoding& encoding);

// pbrt-v4's TextureMapping2D: (s, t) from the surface point.
struct TexMapping {
  enum class Kind { kUV, kSpherical, kCylindrical, kPlanar } kind = Kind::kUV;
  float su = 1, sv = 1, du = 0, dv = 0;  // uv
  Transform texture_from_world;          // spherical, cylindrical, planar
  Vec3 vs{1, 0, 0}, vt{0, 1, 0};         // planar
  float ds = 0, dt = 0;                  // planar
  Vec2 map(const TextureContext& ctx) const;
};

struct ConstantTexture {
  SpectrumCurve spectrum;  // spectrum textures
  float value = 1;         // float textures
};
struct ImageTexture {
  std::shared_ptr<const TexImage> image;
  TexMapping mapping;
  TexFilter filter = TexFilter::kBilinear;
  TexWrap wrap = TexWrap::kRepeat;
  float scale = 1;
  bool invert = false;
  SpectrumKind kind = SpectrumKind::kAlbedo;  // how a spectrum texture reads its texels
};
// tex1 where the cells' integer coordinates sum to an even number, else tex2.
struct CheckerboardTexture {
  int dimension = 2;
  TexMapping mapping;            // 2D
  Transform texture_from_world;  // 3D
  int tex1 = -1, tex2 = -1;
};
struct ScaleTexture {
  int tex = -1, scale = -1;  // scale is a float texture
};
// (1 - amount) tex1 + amount tex2.
struct MixTexture {
  int tex1 = -1, tex2 = -1, amount = -1;  // amount is a float texture
};
using TextureNode =
    std::variant<ConstantTexture, ImageTexture, CheckerboardTexture, ScaleTexture, MixTexture>;

class TextureSet {
 public:
  int add(TextureNode node) {
    nodes_.push_back(std::move(node));
    return int(nodes_.size()) - 1;
  }
  const TextureNode& node(int i) const { return nodes_[size_t(i)]; }
  size_t size() const { return nodes_.size(); }

  // A spectrum texture at the wavelengths (image texels read as the image's kind says; albedo
  // texels are clamped to [0, 1]). A float texture gives its value at every wavelength.
  Spectrum spectrum(int node, const TextureContext& ctx, const Wavelengths& wl) const;
  // A float texture; an image gives the mean of its channels (pbrt-v4's reading).
  float value(int node, const TextureContext& ctx) const;

 private:
  std::vector<TextureNode> nodes_;
};

// A material's spectral parameter: a constant curve, or a texture node when texture >= 0.
struct SpectrumParam {
  SpectrumCurve curve;
  int texture = -1;
  SpectrumParam() = default;
  SpectrumParam(SpectrumCurve c) : curve(std::move(c)) {}  // NOLINT: a constant converts implicitly
  bool textured() const { return texture >= 0; }
};

// A material's float parameter.
struct FloatParam {
  float value = 0;
  int texture = -1;
  bool textured() const { return texture >= 0; }
};

}  // namespace bpm
