#include "scene/render_scene.h"

#include <bit>

#include "base/rng.h"

namespace bpm {

bool alpha_passes(const TextureSet& textures, const FloatParam& alpha, const SurfacePoint& sp,
                  Vec3 o, Vec3 d) {
  float a = alpha.textured() ? textures.value(alpha.texture, texture_context(sp)) : alpha.value;
  if (a >= 1) return false;
  if (!(a > 0)) return true;
  auto bits = [](Vec3 v) {
    return (uint64_t(std::bit_cast<uint32_t>(v.x)) << 32 | std::bit_cast<uint32_t>(v.y)) ^
           mix64(std::bit_cast<uint32_t>(v.z));
  };
  uint64_t h = stream_key(bits(o), bits(d), bits(sp.p), 0xa1fa);
  double u = double(h >> 11) * 0x1.0p-53;
  return u >= a;
}

int medium_at(const RenderScene& scene, Vec3 p, Vec3 d, int outer) {
  Ray ray{p, d, kInf};
  for (int guard = 0; guard < 10000; ++guard) {
    Hit hit;
    if (!scene.intersect(ray, &hit)) return outer;
    const SurfacePoint sp = scene.surface(ray, hit);
    const Object& o = scene.objects[size_t(hit.object)];
    if (o.medium_inside != o.medium_outside)
      return dot(d, sp.ng) > 0 ? o.medium_inside : o.medium_outside;
    ray = spawn_ray(sp, d);
  }
  return outer;
}

int choose_mix(const RenderScene& scene, int material, const TextureContext& ctx) {
  // Nested mixes choose in turn; flatten_materials.cpp rejects cycles, the bound is a safeguard.
  for (int depth = 0; depth < 64; ++depth) {
    const auto* mix = std::get_if<MixDesc>(&scene.materials[size_t(material)]);
    if (!mix) return material;
    float amount =
        mix->amount.textured() ? scene.textures.value(mix->amount.texture, ctx) : mix->amount.value;
    int chosen;
    if (amount <= 0) {
      chosen = mix->materials[0];
    } else if (amount >= 1) {
      chosen = mix->materials[1];
    } else {
      uint64_t h = stream_key(std::bit_cast<uint32_t>(ctx.p.x), std::bit_cast<uint32_t>(ctx.p.y),
                              std::bit_cast<uint32_t>(ctx.p.z), uint64_t(material));
      double u = double(h >> 11) * 0x1.0p-53;
      chosen = u < amount ? mix->materials[1] : mix->materials[0];
    }
    material = chosen;
  }
  return material;
}

const Material& WavelengthMaterials::resolve_into(int material, const TextureContext& ctx,
                                                  Material& storage) const {
  storage = material_at(*scene, material, wl, ctx);
  return storage;
}

}  // namespace bpm
