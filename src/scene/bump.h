// pbrt-v4's bump and normal mapping. A material's "displacement" (a float texture d(u, v)) or
// "normalmap" (an image of tangent-space normals) bends the shading normal of the points it
// shades; RenderScene::surface applies it to every hit, so that every integrator shades, gathers
// photons and compensates for shading normals with the bent normal.
#pragma once
#include <memory>
#include <optional>

#include "scene/shapes.h"
#include "textures/texture.h"

namespace bpm {

struct Bump {
  std::optional<FloatParam> displacement;  // a constant or a float texture
  std::shared_ptr<const TexImage> normal_map;
  bool active() const { return displacement.has_value() || normal_map != nullptr; }
};

// The surface's shading partial derivatives at a point, as pbrt-v4 computes them for its shading
// geometry: dp/du and dp/dv (for a mesh with per-vertex normals, the tangents pbrt-v4 derives
// from them), and dn/du, dn/dv.
struct SurfaceDerivatives {
  Vec3 dpdu, dpdv, dndu, dndv;
};
SurfaceDerivatives surface_derivatives(const Shape& shape, int prim, const SurfacePoint& sp);

// Bends sp.ns as pbrt-v4's BumpMap or NormalMap does (the normal map first, when a material has
// both: pbrt-v4 then ignores the displacement), keeping it on the side of sp.ng. The displacement's
// finite differences step 0.0005 in u and v (pbrt-v4's step without ray differentials; it steps
// half the pixel footprint in (u, v) where it has them).
void apply_bump(const Bump& bump, const TextureSet& textures, const SurfaceDerivatives& d,
                SurfacePoint* sp);

}  // namespace bpm
