// Loop subdivision surfaces (Loop 1987), pbrt-v4's "loopsubdiv" shape: `levels` rounds of the
// 1-to-4 triangle split with Loop's vertex and edge rules (boundary edges keep the cubic B-spline
// rules), then every vertex moved to its limit position. Shading normals are the area-weighted
// normals of the limit mesh (pbrt-v4 uses the limit surface's tangents; the two agree as the mesh
// refines).
#pragma once
#include <vector>

#include "base/vec.h"

namespace bpm {

struct SubdividedMesh {
  std::vector<Vec3> positions, normals;
  std::vector<int> indices;
};

// indices: triangles into positions (checked by the caller). Throws std::invalid_argument for an
// edge shared by more than two triangles (the scheme needs a manifold mesh).
SubdividedMesh loop_subdivide(const std::vector<Vec3>& positions, const std::vector<int>& indices,
                              int levels);

}  // namespace bpm
