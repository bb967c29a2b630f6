#include "textures/texture.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>

#include "base/error.h"
#include "textures/image_file.h"

namespace bpm {
namespace {

float srgb_to_linear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

// Texel coordinate i on an axis of n texels, or -1 outside the image for kBlack.
int wrap_coordinate(int i, int n, TexWrap wrap) {
  switch (wrap) {
    case TexWrap::kRepeat:
      return ((i % n) + n) % n;
    case TexWrap::kClamp:
      return std::clamp(i, 0, n - 1);
    case TexWrap::kBlack:
      return i < 0 || i >= n ? -1 : i;
    case TexWrap::kOctahedralSphere:
      return std::clamp(i, 0, n - 1);  // after the fold below
  }
  return 0;
}

}  // namespace

Rgb TexImage::texel(int x, int y, TexWrap wrap) const {
  if (wrap == TexWrap::kOctahedralSphere) {
    // An octahedral map of the sphere continues across each edge mirrored about that edge's middle.
    if (x < 0 || x >= width) {
      x = x < 0 ? -x - 1 : 2 * width - 1 - x;
      y = height - 1 - y;
    }
    if (y < 0 || y >= height) {
      x = width - 1 - x;
      y = y < 0 ? -y - 1 : 2 * height - 1 - y;
    }
  }
  x = wrap_coordinate(x, width, wrap);
  y = wrap_coordinate(y, height, wrap);
  if (x < 0 || y < 0) return Rgb(0.0f);
  const float* t = texels.data() + (size_t(y) * width + x) * channels;
  return channels == 1 ? Rgb(t[0]) : Rgb(t[0], t[1], t[2]);
}

Rgb TexImage::lookup(Vec2 st, TexFilter filter, TexWrap wrap) const {
  float x = st.x * width, y = st.y * height;
  if (!std::isfinite(x) || !std::isfinite(y)) return Rgb(0.0f);
  if (filter == TexFilter::kPoint) return texel(int(std::floor(x)), int(std::floor(y)), wrap);
  x -= 0.5f;
  y -= 0.5f;
  int xi = int(std::floor(x)), yi = int(std::floor(y));
  float dx = x - float(xi), dy = y - float(yi);
  return texel(xi, yi, wrap) * ((1 - dx) * (1 - dy)) + texel(xi + 1, yi, wrap) * (dx * (1 - dy)) +
         texel(xi, yi + 1, wrap) * ((1 - dx) * dy) + texel(xi + 1, yi + 1, wrap) * (dx * dy);
}

std::shared_ptr<const TexImage> load_texture_image(const std::string& path,
                                                   const TexEncoding& encoding, bool colours) {
  static std::mutex mutex;
  static std::map<std::string, std::shared_ptr<const TexImage>> cache;
  if (colours) prepare_texel_spectra();  // what every texel's colour will need, before the render
  std::string key =
      path + "|" + std::to_string(int(encoding.kind)) + "|" + std::to_string(encoding.gamma);
  std::lock_guard<std::mutex> lock(mutex);
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  std::shared_ptr<const TexImage> img = read_texture_image(path, encoding);
  cache[key] = img;
  return img;
}

std::shared_ptr<const TexImage> read_texture_image(const std::string& path,
                                                   const TexEncoding& encoding) {
  // More than 2^28 values (1 GiB of floats) is refused, not allocated.
  const ImageFile file = read_image_file(path, double(1 << 28));
  auto img = std::make_shared<TexImage>();
  img->path = path;
  img->width = file.width;
  img->height = file.height;
  const int n = file.channels;
  const std::vector<float>& all = file.values;
  // Grey (one channel, or grey plus alpha) stays one channel; otherwise R, G, B.
  img->channels = n < 3 ? 1 : 3;
  img->texels.resize(size_t(file.width) * file.height * img->channels);
  for (size_t i = 0, count = size_t(file.width) * file.height; i < count; ++i)
    for (int c = 0; c < img->channels; ++c) {
      float v = all[i * n + c];
      if (!file.is_float) {
        if (encoding.kind == TexEncoding::Kind::kSrgb)
          v = srgb_to_linear(v);
        else if (encoding.kind == TexEncoding::Kind::kGamma)
          v = std::pow(std::max(v, 0.0f), encoding.gamma);
      }
      if (!std::isfinite(v)) throw Error("image \"" + path + "\" has a non-finite texel");
      img->texels[i * img->channels + c] = v;
    }
  return img;
}

Vec2 TexMapping::map(const TextureContext& ctx) const {
  switch (kind) {
    case Kind::kUV:
      return {su * ctx.uv.x + du, sv * ctx.uv.y + dv};
    case Kind::kSpherical: {
      Vec3 d = normalize(texture_from_world.point(ctx.p));
      float theta = std::acos(std::clamp(d.z, -1.0f, 1.0f));
      float phi = std::atan2(d.y, d.x);
      if (phi < 0) phi += 2 * kPi;
      return {theta / kPi, phi / (2 * kPi)};
    }
    case Kind::kCylindrical: {
      Vec3 q = texture_from_world.point(ctx.p);
      return {(kPi + std::atan2(q.y, q.x)) / (2 * kPi), q.z};
    }
    case Kind::kPlanar: {
      Vec3 q = texture_from_world.point(ctx.p);
      return {ds + dot(q, vs), dt + dot(q, vt)};
    }
  }
  return {0, 0};
}

namespace {

// The image's texel value at the point, before scale and invert.
Rgb image_lookup(const ImageTexture& t, const TextureContext& ctx) {
  Vec2 st = t.mapping.map(ctx);
  st.y = 1 - st.y;  // t runs up the image; rows run down
  return t.image->lookup(st, t.filter, t.wrap);
}

// The image's value at the point, after scale and invert (pbrt-v4's image textures).
Rgb image_rgb(const ImageTexture& t, const TextureContext& ctx) {
  Rgb v = image_lookup(t, ctx) * t.scale;
  if (t.invert)
    for (int c = 0; c < 3; ++c) v[c] = std::max(0.0f, 1 - v[c]);
  return v;
}

bool checker_first(const CheckerboardTexture& c, const TextureContext& ctx) {
  if (c.dimension == 3) {
    Vec3 q = c.texture_from_world.point(ctx.p);
    long s = long(std::floor(q.x)) + long(std::floor(q.y)) + long(std::floor(q.z));
    return s % 2 == 0;
  }
  Vec2 st = c.mapping.map(ctx);
  long s = long(std::floor(st.x)) + long(std::floor(st.y));
  return s % 2 == 0;
}

}  // namespace

Spectrum TextureSet::spectrum(int i, const TextureContext& ctx, const Wavelengths& wl) const {
  const TextureNode& n = node(i);
  if (auto* c = std::get_if<ConstantTexture>(&n)) return c->spectrum.sample(wl);
  if (auto* im = std::get_if<ImageTexture>(&n))
    return rgb_texel_spectrum(image_rgb(*im, ctx), im->kind, wl);
  if (auto* c = std::get_if<CheckerboardTexture>(&n))
    return spectrum(checker_first(*c, ctx) ? c->tex1 : c->tex2, ctx, wl);
  if (auto* s = std::get_if<ScaleTexture>(&n)) {
    float k = value(s->scale, ctx);
    return k == 0 ? Spectrum() : spectrum(s->tex, ctx, wl) * k;
  }
  const MixTexture& m = std::get<MixTexture>(n);
  float a = value(m.amount, ctx);
  Spectrum out;
  if (a != 1) out += spectrum(m.tex1, ctx, wl) * (1 - a);
  if (a != 0) out += spectrum(m.tex2, ctx, wl) * a;
  return out;
}

float TextureSet::value(int i, const TextureContext& ctx) const {
  const TextureNode& n = node(i);
  if (auto* c = std::get_if<ConstantTexture>(&n)) return c->value;
  if (auto* im = std::get_if<ImageTexture>(&n)) {
    // pbrt-v4 reads an RGB image as a float texture by the mean of its three channels, scaled,
    // then inverted.
    const Rgb c = image_lookup(*im, ctx);
    const float v = (c[0] + c[1] + c[2]) / 3 * im->scale;
    return im->invert ? std::max(0.0f, 1 - v) : v;
  }
  if (auto* c = std::get_if<CheckerboardTexture>(&n))
    return value(checker_first(*c, ctx) ? c->tex1 : c->tex2, ctx);
  if (auto* s = std::get_if<ScaleTexture>(&n)) {
    float k = value(s->scale, ctx);
    return k == 0 ? 0 : value(s->tex, ctx) * k;
  }
  const MixTexture& m = std::get<MixTexture>(n);
  float a = value(m.amount, ctx);
  float out = 0;
  if (a != 1) out += value(m.tex1, ctx) * (1 - a);
  if (a != 0) out += value(m.tex2, ctx) * a;
  return out;
}

}  // namespace bpm
