#include "scene/ply.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

namespace bpm {
namespace {

enum class Format { kAscii, kBinaryLE, kBinaryBE };

struct Property {
  std::string name;
  std::string type;        // scalar type, or the item type of a list
  std::string count_type;  // non-empty for lists
};

struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> props;
};

int type_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32")
    return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

class Reader {
 public:
  Reader(std::istream& in, Format f, const std::string& path) : in_(in), f_(f), path_(path) {}

  double read(const std::string& t) {
    if (f_ == Format::kAscii) {
      double v;
      if (!(in_ >> v)) fail("truncated or malformed data");
      return v;
    }
    unsigned char buf[8];
    int n = type_size(t);
    if (!in_.read(reinterpret_cast<char*>(buf), n)) fail("truncated data");
    bool swap = (f_ == Format::kBinaryBE) != (std::endian::native == std::endian::big);
    if (swap) std::reverse(buf, buf + n);
    if (t == "char" || t == "int8") return double(int8_t(buf[0]));
    if (t == "uchar" || t == "uint8") return double(buf[0]);
    if (t == "short" || t == "int16") {
      int16_t v;
      std::memcpy(&v, buf, 2);
      return v;
    }
    if (t == "ushort" || t == "uint16") {
      uint16_t v;
      std::memcpy(&v, buf, 2);
      return v;
    }
    if (t == "int" || t == "int32") {
      int32_t v;
      std::memcpy(&v, buf, 4);
      return v;
    }
    if (t == "uint" || t == "uint32") {
      uint32_t v;
      std::memcpy(&v, buf, 4);
      return v;
    }
    if (t == "float" || t == "float32") {
      float v;
      std::memcpy(&v, buf, 4);
      return v;
    }
    double v;
    std::memcpy(&v, buf, 8);
    return v;
  }
  [[noreturn]] void fail(const std::string& what) {
    throw Error("PLY file \"" + path_ + "\": " + what);
  }

 private:
  std::istream& in_;
  Format f_;
  std::string path_;
};

struct Header {
  Format format = Format::kAscii;
  std::vector<Element> elements;
};

// Every failure it reports names the PLY file and `from`, the scene line that asked for it.
class PlyParser {
 public:
  PlyParser(std::istream& in, const std::string& path, const FileLoc& from)
      : in_(in), path_(path), from_(from) {}

  // Leaves the stream at the first byte of the body.
  Header read_header() {
    std::string line;
    std::getline(in_, line);
    if (line.rfind("ply", 0) != 0) fail("not a PLY file (missing 'ply' magic)");
    Header h;
    bool header_done = false;
    while (std::getline(in_, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      std::istringstream ls(line);
      std::string word;
      ls >> word;
      if (word == "format") {
        std::string f;
        ls >> f;
        if (f == "ascii")
          h.format = Format::kAscii;
        else if (f == "binary_little_endian")
          h.format = Format::kBinaryLE;
        else if (f == "binary_big_endian")
          h.format = Format::kBinaryBE;
        else
          fail("unknown format '" + f + "'");
      } else if (word == "element") {
        Element e;
        long long count = -1;
        if (!(ls >> e.name >> count) || count < 0) fail("bad element line '" + line + "'");
        e.count = size_t(count);
        h.elements.push_back(e);
      } else if (word == "property") {
        if (h.elements.empty()) fail("property before any element");
        Property p;
        std::string t;
        ls >> t;
        if (t == "list") {
          ls >> p.count_type >> p.type >> p.name;
          if (!type_size(p.count_type) || !type_size(p.type))
            fail("bad list property '" + line + "'");
        } else {
          p.type = t;
          ls >> p.name;
          if (!type_size(p.type)) fail("unknown property type '" + t + "'");
        }
        h.elements.back().props.push_back(p);
      } else if (word == "end_header") {
        header_done = true;
        break;
      }
    }
    if (!header_done) fail("header has no end_header");
    return h;
  }

  // Every row of `e` is read, whatever the element, so that the ones after it start in the right
  // place; only vertices and faces add to the mesh.
  void read_element(const Element& e, Reader& r, PlyMesh* mesh) {
    // An element without properties occupies no bytes, however many it claims to have.
    if (e.props.empty()) return;
    bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    int ix = -1, iy = -1, iz = -1, inx = -1, iny = -1, inz = -1, iu = -1, iv = -1, iidx = -1;
    for (int k = 0; k < int(e.props.size()); ++k) {
      const std::string& n = e.props[k].name;
      if (n == "x")
        ix = k;
      else if (n == "y")
        iy = k;
      else if (n == "z")
        iz = k;
      else if (n == "nx")
        inx = k;
      else if (n == "ny")
        iny = k;
      else if (n == "nz")
        inz = k;
      else if (n == "u" || n == "s" || n == "texture_u" || n == "texture_s")
        iu = k;
      else if (n == "v" || n == "t" || n == "texture_v" || n == "texture_t")
        iv = k;
      else if (n == "vertex_indices" || n == "vertex_index")
        iidx = k;
    }
    if (is_vertex && (ix < 0 || iy < 0 || iz < 0)) fail("vertex element lacks x, y or z");
    if (is_face && iidx < 0) fail("face element lacks vertex_indices");
    bool has_n = inx >= 0 && iny >= 0 && inz >= 0, has_uv = iu >= 0 && iv >= 0;
    std::vector<double> vals(e.props.size());
    std::vector<int> face;
    for (size_t i = 0; i < e.count; ++i) {
      for (int k = 0; k < int(e.props.size()); ++k) {
        const Property& p = e.props[k];
        if (p.count_type.empty()) {
          vals[k] = r.read(p.type);
          continue;
        }
        double n = r.read(p.count_type);
        if (!(n >= 0 && n <= 1e6 && n == std::floor(n))) fail("bad list length");
        if (k == iidx) face.clear();
        for (int j = 0; j < int(n); ++j) {
          double v = r.read(p.type);
          if (k != iidx) continue;
          // An index must be a whole number an int holds (checked against the vertex count later).
          if (!(v >= 0 && v <= double(std::numeric_limits<int>::max()) && v == std::floor(v))) {
            std::ostringstream msg;
            msg.precision(17);
            msg << "bad vertex index " << v;
            fail(msg.str());
          }
          face.push_back(int(v));
        }
      }
      if (is_vertex) {
        mesh->positions.push_back(Vec3(float(vals[ix]), float(vals[iy]), float(vals[iz])));
        if (has_n)
          mesh->normals.push_back(Vec3(float(vals[inx]), float(vals[iny]), float(vals[inz])));
        if (has_uv) mesh->uvs.push_back({float(vals[iu]), float(vals[iv])});
      } else if (is_face) {
        add_face(face, mesh);
      }
    }
  }

  void add_face(const std::vector<int>& face, PlyMesh* mesh) {
    if (face.size() == 3) {
      mesh->indices.insert(mesh->indices.end(), face.begin(), face.end());
    } else if (face.size() == 4) {
      // pbrt-v4 reads quads as bilinear patches; planar quads are exactly two triangles.
      int q[6] = {face[0], face[1], face[2], face[0], face[2], face[3]};
      mesh->indices.insert(mesh->indices.end(), q, q + 6);
      ++mesh->quads;
    } else {
      fail("face with " + std::to_string(face.size()) +
           " vertices (only triangles and quads are supported)");
    }
  }

  // Faces may come before the vertices they name, so indices are checked once both are read.
  void check_indices(const PlyMesh& mesh) {
    for (int idx : mesh.indices)
      if (idx < 0 || idx >= int(mesh.positions.size()))
        fail("vertex index " + std::to_string(idx) + " out of range (the file has " +
             std::to_string(mesh.positions.size()) + " vertices)");
    if (mesh.indices.empty()) fail("no faces");
  }

 private:
  std::istream& in_;
  std::string path_;
  FileLoc from_;

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(from_, "PLY file \"" + path_ + "\": " + what);
  }
};

}  // namespace

PlyMesh read_ply(const std::string& path, const FileLoc& from) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(from, "cannot open PLY file \"" + path + "\"");
  PlyParser ply(in, path, from);
  Header header = ply.read_header();
  PlyMesh mesh;
  Reader r(in, header.format, path);
  try {
    for (const Element& e : header.elements) ply.read_element(e, r, &mesh);
  } catch (const Error& e) {
    if (!e.loc().file.empty()) throw;  // already names the scene line
    throw Error(from, e.what());
  }
  ply.check_indices(mesh);
  return mesh;
}

}  // namespace bpm
