#include <bit>

#include "base/rng.h"
#include "scene/render_scene.h"

namespace bpm {

int choose_mix(const RenderScene& scene, int material, const TextureContext& ctx) {
  // Nested mixes choose in turn; flatten.cpp rejects cycles, the bound is a safeguard.
  for (int depth = 0; depth < 64; ++depth) {
    const auto* mix = std::get_if<MixDesc>(&scene.materials[size_t(material)]);
    if (!mix) return material;
    float amount = mix->amount.textured() ? scene.textures.value(mix->amount.texture, ctx) : mix->amount.value;
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

}  // namespace bpm
