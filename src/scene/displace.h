// pbrt-v4's displaced "plymesh": every edge longer than `edge_length` (measured in world space) is
// split at its midpoint, longest first, until none is; then every vertex moves along its normal by
// the displacement at its object-space point and uv, and the normals are recomputed from the
// displaced triangles (each triangle's unit normal added to its corners'). A mesh without normals
// gets them the same way before it is split.
#pragma once
#include <cstddef>
#include <functional>

#include "base/transform.h"
#include "scene/ply.h"

namespace bpm {

// The triangles splitting would make, counted before any is made (the caller refuses too many).
size_t displaced_triangle_count(const PlyMesh& mesh, const Transform& world_from_object,
                                float edge_length);

// mesh->uvs must hold one uv per vertex; edge_length > 0.
void displace_mesh(PlyMesh* mesh, const Transform& world_from_object, float edge_length,
                   const std::function<float(Vec3 p, Vec2 uv)>& displacement);

}  // namespace bpm
