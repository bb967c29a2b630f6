// Reader for PLY meshes (ASCII and binary, either byte order): positions, normals, uv, and faces
// with three or four vertices (quads are split into two triangles).
#pragma once
#include <string>
#include <vector>

#include "base/error.h"
#include "base/vec.h"

namespace bpm {

struct PlyMesh {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;  // empty or one per vertex
  std::vector<Vec2> uvs;      // empty or one per vertex
  std::vector<int> indices;   // three per triangle
  int quads = 0;              // faces that had four vertices
};

// Throws Error naming the file (and `from`, the scene line that asked for it) when the file is
// missing, malformed, truncated or has an index out of range.
PlyMesh read_ply(const std::string& path, const FileLoc& from);

}  // namespace bpm
