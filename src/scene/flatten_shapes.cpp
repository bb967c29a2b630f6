// Shapes (triangle, bilinear and subdivision meshes, PLY meshes, spheres, disks, cylinders,
// curves) and the diffuse area lights attached to them.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "scene/displace.h"
#include "scene/flatten_internal.h"
#include "scene/loop_subdivision.h"
#include "scene/ply.h"

namespace bpm::flatten_internal {

namespace fs = std::filesystem;

void Flattener::check_indices(const std::vector<int>& idx, size_t n, const FileLoc& loc) {
  for (int i : idx)
    if (i < 0 || size_t(i) >= n)
      throw Error(loc, "vertex index " + std::to_string(i) + " out of range (" + std::to_string(n) +
                           " vertices)");
}

TriangleMesh Flattener::mesh_from(const Transform& xf, bool flip, std::vector<Vec3> P,
                                  std::vector<Vec3> N, std::vector<Vec2> uv,
                                  const std::vector<int>& idx) {
  TriangleMesh m;
  m.positions.reserve(P.size() + 2);  // Embree reads vertex buffers in 16-byte chunks
  for (Vec3 p : P) m.positions.push_back(xf.point(p));
  for (Vec3 n : N) m.normals.push_back(normalize(xf.normal(n)));
  m.uvs = std::move(uv);
  m.indices.assign(idx.begin(), idx.end());
  m.flip_normal = flip;
  return m;
}

void Flattener::add_shape(const ShapeEntity& s, RenderScene* rs) {
  const ParamSet& ps = s.params;
  bool flip = s.reverse_orientation != s.world_from_object.swaps_handedness();
  for (const char* ignored : {"emission", "faceIndices"})
    if (auto* p = ps.find_any(ignored)) p->used = true;
  Object obj;
  obj.source = s.loc.str();
  if (const Param* a = ps.find_any("alpha")) {
    obj.alpha = float_or_texture(ps, "alpha", 1);
    if (!obj.alpha.textured() && !(obj.alpha.value >= 0 && obj.alpha.value <= 1))
      throw Error(a->loc, "alpha must be in [0, 1]");
    if (obj.has_alpha() && s.area_light)
      throw Error(a->loc, "alpha on an emitting shape is not supported (the area light at " +
                              s.area_light->loc.str() + ")");
  }
  if (s.name == "trianglemesh" || s.name == "bilinearmesh") {
    obj.shape = mesh_shape(s, flip);
  } else if (s.name == "loopsubdiv") {
    obj.shape = loopsubdiv_shape(s, flip);
  } else if (s.name == "plymesh") {
    obj.shape = plymesh_shape(s, flip);
  } else if (s.name == "sphere") {
    obj.shape = sphere_shape(s, flip);
  } else if (s.name == "disk") {
    obj.shape = disk_shape(s, flip);
  } else if (s.name == "cylinder") {
    obj.shape = cylinder_shape(s, flip);
  } else if (s.name == "curve") {
    obj.shape = curve_shape(s, flip);
  } else {
    throw Error(s.loc, "shape \"" + s.name + "\" is not supported");
  }
  ps.warn_unused("shape \"" + s.name + "\"");
  obj.material = material_id(s.material);
  obj.medium_inside = medium_id(s.medium.inside, s.medium.loc);
  obj.medium_outside = medium_id(s.medium.outside, s.medium.loc);
  int id = int(rs->objects.size());
  if (s.area_light) add_area_light(*s.area_light, &obj, id, rs);
  rs->objects.push_back(std::move(obj));
}

// A "trianglemesh", or a "bilinearmesh" of planar patches (two triangles each).
TriangleMesh Flattener::mesh_shape(const ShapeEntity& s, bool flip) {
  const ParamSet& ps = s.params;
  bool bilinear = s.name == "bilinearmesh";
  auto P = ps.get_point3s("P");
  if (P.empty()) throw Error(s.loc, s.name + " has no \"point3 P\"");
  auto idx = ps.get_ints("indices");
  size_t per = bilinear ? 4 : 3;
  if (idx.empty()) {
    if (P.size() != per) throw Error(s.loc, s.name + " has no \"integer indices\"");
    for (size_t i = 0; i < per; ++i) idx.push_back(int(i));
  }
  const FileLoc& iloc = ps.find_any("indices") ? ps.find_any("indices")->loc : s.loc;
  if (idx.size() % per != 0)
    throw Error(iloc, "\"indices\" has " + std::to_string(idx.size()) +
                          " values, not a multiple of " + std::to_string(per));
  check_indices(idx, P.size(), iloc);
  auto N = ps.get_normals("N");
  auto uv = ps.get_point2s("uv");
  if (uv.empty()) uv = ps.get_point2s("st");
  if (!N.empty() && N.size() != P.size())
    throw Error(ps.find_any("N")->loc, "\"N\" has " + std::to_string(N.size()) + " normals for " +
                                           std::to_string(P.size()) + " vertices");
  if (!uv.empty() && uv.size() != P.size())
    throw Error(ps.find_any("uv") ? ps.find_any("uv")->loc : s.loc,
                "\"uv\" count differs from the vertex count");
  if (auto* S = ps.find_any("S")) {
    S->used = true;
    warning(S->loc, "per-vertex tangents \"S\" are ignored");
  }
  if (bilinear) idx = bilinear_to_triangles(P, N, uv, idx);
  return mesh_from(s.world_from_object, flip, P, N, uv, idx);
}

// A "loopsubdiv" control mesh, subdivided "levels" times (loop_subdivision.h).
TriangleMesh Flattener::loopsubdiv_shape(const ShapeEntity& s, bool flip) {
  const ParamSet& ps = s.params;
  auto P = ps.get_point3s("P");
  auto idx = ps.get_ints("indices");
  if (P.empty() || idx.empty())
    throw Error(s.loc, "loopsubdiv needs \"point3 P\" and \"integer indices\"");
  const FileLoc& iloc = ps.find_any("indices")->loc;
  if (idx.size() % 3 != 0)
    throw Error(iloc,
                "\"indices\" has " + std::to_string(idx.size()) + " values, not a multiple of 3");
  check_indices(idx, P.size(), iloc);
  int levels = ps.get_int("levels", 3);
  if (levels < 0 || levels > 8)
    throw Error(ps.find_any("levels")->loc, "loopsubdiv levels must be in [0, 8]");
  SubdividedMesh sub;
  try {
    sub = loop_subdivide(P, idx, levels);
  } catch (const std::invalid_argument& e) {
    throw Error(s.loc, std::string("loopsubdiv: ") + e.what());
  }
  return mesh_from(s.world_from_object, flip, std::move(sub.positions), std::move(sub.normals), {},
                   sub.indices);
}

// A "plymesh", read from its file (relative paths from the file that names it).
TriangleMesh Flattener::plymesh_shape(const ShapeEntity& s, bool flip) {
  const ParamSet& ps = s.params;
  std::string file = ps.get_string("filename", "");
  if (file.empty()) throw Error(s.loc, "plymesh has no \"string filename\"");
  const float edge_length = ps.get_float("edgelength", 1);
  fs::path path = fs::path(file).is_absolute() ? fs::path(file) : fs::path(s.directory) / file;
  read_data_file(path.string());
  PlyMesh ply = read_ply(path.string(), ps.find_any("filename")->loc);
  if (const Param* d = ps.find_any("displacement")) displace_ply(ps, *d, edge_length, s, &ply);
  return mesh_from(s.world_from_object, flip, ply.positions, ply.normals, ply.uvs, ply.indices);
}

// pbrt-v4's displacement of a "plymesh" (scene/displace.h) by a float texture or value.
void Flattener::displace_ply(const ParamSet& ps, const Param& displacement, float edge_length,
                             const ShapeEntity& s, PlyMesh* ply) {
  const Param* e = ps.find_any("edgelength");
  if (!(edge_length > 0) || !std::isfinite(edge_length))
    throw Error(e ? e->loc : displacement.loc, "edgelength must be positive");
  if (ply->uvs.size() != ply->positions.size())
    throw Error(displacement.loc, "displacement needs the PLY file's per-vertex uv");
  constexpr size_t kMaxTriangles = size_t(1) << 27;
  const size_t n = displaced_triangle_count(*ply, s.world_from_object, edge_length);
  if (n > kMaxTriangles)
    throw Error(e ? e->loc : displacement.loc, "edgelength would split the mesh into about " +
                                                   std::to_string(n) + " triangles (at most " +
                                                   std::to_string(kMaxTriangles) + ")");
  const FloatParam f = float_or_texture(ps, "displacement", 0);
  const TextureSet& textures = scene_->textures;
  displace_mesh(ply, s.world_from_object, edge_length, [&](Vec3 p, Vec2 uv) {
    return f.textured() ? textures.value(f.texture, TextureContext{p, uv}) : f.value;
  });
}

Sphere Flattener::sphere_shape(const ShapeEntity& s, bool flip) {
  const ParamSet& ps = s.params;
  Sphere sp;
  sp.world_from_object = s.world_from_object;
  sp.radius = ps.get_float("radius", 1);
  if (!(sp.radius > 0)) throw Error(s.loc, "sphere radius must be positive");
  sp.z_min = std::clamp(ps.get_float("zmin", -sp.radius), -sp.radius, sp.radius);
  sp.z_max = std::clamp(ps.get_float("zmax", sp.radius), -sp.radius, sp.radius);
  if (sp.z_min > sp.z_max) std::swap(sp.z_min, sp.z_max);
  sp.phi_max = radians(std::clamp(ps.get_float("phimax", 360), 0.0f, 360.0f));
  sp.flip_normal = flip;
  return sp;
}

Disk Flattener::disk_shape(const ShapeEntity& s, bool flip) {
  const ParamSet& ps = s.params;
  Disk d;
  d.world_from_object = s.world_from_object;
  d.height = ps.get_float("height", 0);
  d.radius = ps.get_float("radius", 1);
  d.inner_radius = ps.get_float("innerradius", 0);
  if (!(d.radius > 0) || d.inner_radius < 0 || d.inner_radius >= d.radius)
    throw Error(s.loc, "disk needs 0 <= innerradius < radius");
  d.phi_max = radians(std::clamp(ps.get_float("phimax", 360), 0.0f, 360.0f));
  d.flip_normal = flip;
  return d;
}

Cylinder Flattener::cylinder_shape(const ShapeEntity& s, bool flip) {
  const ParamSet& ps = s.params;
  Cylinder c;
  c.world_from_object = s.world_from_object;
  c.radius = ps.get_float("radius", 1);
  if (!(c.radius > 0)) throw Error(s.loc, "cylinder radius must be positive");
  float z0 = ps.get_float("zmin", -1), z1 = ps.get_float("zmax", 1);
  c.z_min = std::fmin(z0, z1);
  c.z_max = std::fmax(z0, z1);
  if (!(c.z_max > c.z_min)) throw Error(s.loc, "cylinder needs zmin != zmax");
  c.phi_max = radians(std::clamp(ps.get_float("phimax", 360), 0.0f, 360.0f));
  if (!(c.phi_max > 0)) throw Error(s.loc, "cylinder phimax must be positive");
  c.flip_normal = flip;
  return c;
}

namespace {

// Whether a bilinear patch is planar: its fourth corner within 1e-4 of its size of the plane of
// the other three.
bool planar_patch(Vec3 p00, Vec3 p10, Vec3 p01, Vec3 p11) {
  const Vec3 n = cross(p10 - p00, p01 - p00);
  const float ln = length(n), size = std::fmax(length(p10 - p00), length(p01 - p00));
  return !(ln > 0) || std::fabs(dot(p11 - p00, n / ln)) <= 1e-4f * size;
}

template <class T>
T bilerp(const T& v00, const T& v10, const T& v01, const T& v11, float u, float v) {
  return (v00 * (1 - u) + v10 * u) * (1 - v) + (v01 * (1 - u) + v11 * u) * v;
}

}  // namespace

std::vector<int> Flattener::bilinear_to_triangles(std::vector<Vec3>& P, std::vector<Vec3>& N,
                                                  std::vector<Vec2>& uv,
                                                  const std::vector<int>& idx) {
  bool curved = false;
  for (size_t i = 0; i < idx.size(); i += 4)
    curved = curved || !planar_patch(P[size_t(idx[i])], P[size_t(idx[i + 1])],
                                     P[size_t(idx[i + 2])], P[size_t(idx[i + 3])]);
  // A curved patch gets vertices of its own with the patch's normals; without normals in the
  // file, every patch then does, and the file's vertices are dropped.
  const bool own_normals = curved && N.empty();
  const size_t file_vertices = P.size();
  if (own_normals) N.assign(P.size(), Vec3(0, 0, 1));
  const bool has_uv = !uv.empty();
  if (curved && !has_uv) uv.assign(P.size(), Vec2(0, 0));
  std::vector<int> tris;
  for (size_t i = 0; i < idx.size(); i += 4) {
    const size_t a = size_t(idx[i]), b = size_t(idx[i + 1]), c = size_t(idx[i + 2]),
                 d = size_t(idx[i + 3]);  // p00 p10 p01 p11
    const Vec3 p00 = P[a], p10 = P[b], p01 = P[c], p11 = P[d];
    const bool planar = planar_patch(p00, p10, p01, p11);
    if (planar && !own_normals) {
      tris.insert(tris.end(), {int(a), int(b), int(d), int(a), int(d), int(c)});
      continue;
    }
    // A grid of k x k cells: each cell's two triangles stray from the patch by a quarter of the
    // cell's twist, |p11 - p10 - p01 + p00| / (4 k^2), kept below 1e-4 of the patch's size.
    const float twist = length(p11 - p10 - p01 + p00);
    const float size = std::fmax(length(p10 - p00), length(p01 - p00));
    const int k = planar ? 1 : std::clamp(int(std::ceil(std::sqrt(twist / (4e-4f * size)))), 2, 64);
    const int first = int(P.size());
    for (int jv = 0; jv <= k; ++jv)
      for (int iu = 0; iu <= k; ++iu) {
        const float u = float(iu) / float(k), v = float(jv) / float(k);
        P.push_back(bilerp(p00, p10, p01, p11, u, v));
        // The patch's own normal, dp/du x dp/dv (pbrt-v4's), unless the file gives normals.
        const Vec3 dpdu = (p10 - p00) * (1 - v) + (p11 - p01) * v;
        const Vec3 dpdv = (p01 - p00) * (1 - u) + (p11 - p10) * u;
        N.push_back(own_normals ? normalize(cross(dpdu, dpdv))
                                : normalize(bilerp(N[a], N[b], N[c], N[d], u, v)));
        uv.push_back(has_uv ? bilerp(uv[a], uv[b], uv[c], uv[d], u, v) : Vec2(u, v));
      }
    for (int jv = 0; jv < k; ++jv)
      for (int iu = 0; iu < k; ++iu) {
        const int q = first + jv * (k + 1) + iu;
        tris.insert(tris.end(), {q, q + 1, q + k + 2, q, q + k + 2, q + k + 1});
      }
  }
  if (own_normals) {
    for (auto* v : {&P, &N}) v->erase(v->begin(), v->begin() + ptrdiff_t(file_vertices));
    uv.erase(uv.begin(), uv.begin() + ptrdiff_t(file_vertices));
    for (int& t : tris) t -= int(file_vertices);
  }
  return tris;
}

namespace {

// A segment's cubic Bezier control points from the file's, by pbrt-v4's conversions.
void bezier_segment(const std::vector<Vec3>& P, int seg, int degree, bool bspline, Vec3 out[4]) {
  if (!bspline) {
    const Vec3* p = &P[size_t(seg * degree)];
    if (degree == 2) return elevate_quadratic_bezier(p, out);
    for (int k = 0; k < 4; ++k) out[k] = p[k];
    return;
  }
  const Vec3* p = &P[size_t(seg)];
  if (degree == 2) return quadratic_bspline_to_bezier(p, out);
  cubic_bspline_to_bezier(p, out);
}

}  // namespace

// pbrt-v4's "curve": P holds Bezier segments (degree + 1 points, then degree more per segment)
// or a uniform B-spline (a segment per point past the first degree); the width runs linearly
// from width0 to width1 along the whole curve; ribbons turn with the normals N at the segments'
// ends. Every segment becomes a cubic Bezier in world space. pbrt-v4's splitdepth is read and
// has no use here: Embree refines the curve itself.
Curves Flattener::curve_shape(const ShapeEntity& s, bool flip) {
  const ParamSet& ps = s.params;
  auto loc_of = [&](const char* name) {
    return ps.find_any(name) ? ps.find_any(name)->loc : s.loc;
  };
  const float width = ps.get_float("width", 1);
  const float w0 = ps.get_float("width0", width), w1 = ps.get_float("width1", width);
  if (!(w0 >= 0 && w1 >= 0 && std::isfinite(w0) && std::isfinite(w1)) || (w0 == 0 && w1 == 0))
    throw Error(s.loc, "a curve's widths must be finite, not negative and not both zero");
  const int degree = ps.get_int("degree", 3);
  if (degree != 2 && degree != 3)
    throw Error(loc_of("degree"), "curve degree " + std::to_string(degree) + " is not 2 or 3");
  const std::string basis = ps.get_string("basis", "bezier");
  if (basis != "bezier" && basis != "bspline")
    throw Error(loc_of("basis"), "curve basis \"" + basis + "\" is unknown (bezier, bspline)");
  const std::vector<Vec3> P = ps.get_point3s("P");
  const bool bspline = basis == "bspline";
  const int n = int(P.size());
  if (n < degree + 1 || (!bspline && (n - 1 - degree) % degree != 0))
    throw Error(loc_of("P"),
                "a degree " + std::to_string(degree) + " " + basis + " curve takes " +
                    (bspline ? "at least " + std::to_string(degree + 1)
                             : std::to_string(degree + 1) + " + k x " + std::to_string(degree)) +
                    " control points; got " + std::to_string(n));
  const int segments = bspline ? n - degree : (n - 1) / degree;
  Curves c;
  const std::string type = ps.get_string("type", "flat");
  if (type == "flat")
    c.type = Curves::Type::kFlat;
  else if (type == "cylinder")
    c.type = Curves::Type::kCylinder;
  else if (type == "ribbon")
    c.type = Curves::Type::kRibbon;
  else
    throw Error(loc_of("type"), "curve type \"" + type + "\" is unknown (flat, cylinder, ribbon)");
  std::vector<Vec3> N = ps.get_normals("N");
  if (c.type != Curves::Type::kRibbon && !N.empty()) {
    warning(loc_of("N"), "curve normals are used by \"ribbon\" curves only");
    N.clear();
  }
  if (c.type == Curves::Type::kRibbon && int(N.size()) != segments + 1)
    throw Error(N.empty() ? s.loc : loc_of("N"),
                "a ribbon curve of " + std::to_string(segments) + " segment(s) takes " +
                    std::to_string(segments + 1) + " normals \"N\", one per segment end; got " +
                    std::to_string(N.size()));
  for (Vec3& v : N)
    if (!(length_squared(v) > 0)) throw Error(loc_of("N"), "a curve normal is zero");
  ps.get_int("splitdepth", 3);
  const Transform& xf = s.world_from_object;
  const float det = std::fabs(
      dot(xf.vector(Vec3(1, 0, 0)), cross(xf.vector(Vec3(0, 1, 0)), xf.vector(Vec3(0, 0, 1)))));
  const float scale = std::cbrt(det);
  for (int seg = 0; seg < segments; ++seg) {
    Vec3 b[4];
    bezier_segment(P, seg, degree, bspline, b);
    const float r0 = 0.5f * scale * (w0 + (w1 - w0) * float(seg) / float(segments)),
                r1 = 0.5f * scale * (w0 + (w1 - w0) * float(seg + 1) / float(segments));
    c.first.push_back(uint32_t(c.control.size() / 4));
    for (int k = 0; k < 4; ++k) {
      const Vec3 p = xf.point(b[k]);
      c.control.insert(c.control.end(), {p.x, p.y, p.z, r0 + (r1 - r0) * float(k) / 3});
    }
    if (c.type == Curves::Type::kRibbon) {
      c.end_normals.push_back(normalize(xf.normal(N[size_t(seg)])));
      c.end_normals.push_back(normalize(xf.normal(N[size_t(seg) + 1])));
      for (int k = 0; k < 4; ++k) c.control_normals.push_back(c.ribbon_normal(seg, float(k) / 3));
    }
  }
  for (float v : c.control)
    if (!std::isfinite(v)) throw Error(loc_of("P"), "a curve's control points must be finite");
  c.control_normals.reserve(c.control_normals.size() + 1);  // Embree reads 16 bytes at a time
  c.flip_normal = flip;
  return c;
}

void Flattener::add_area_light(const SceneEntity& a, Object* obj, int id, RenderScene* rs) {
  if (a.name != "diffuse") throw Error(a.loc, "area light \"" + a.name + "\" is not supported");
  const ParamSet& ps = a.params;
  std::shared_ptr<const TexImage> image;
  Rgb image_mean(0.0f);
  if (ps.find_any("filename")) {
    if (const Param* l = ps.find_any("L"))
      throw Error(l->loc, "an area light takes \"L\" or \"filename\", not both");
    image = light_image(ps, "an image area");
    for (int y = 0; y < image->height; ++y)
      for (int x = 0; x < image->width; ++x) {
        image_mean += image->texel(x, y, TexWrap::kClamp).clamped_zero();
      }
    image_mean = image_mean / float(image->width * image->height);
  }
  SpectrumCurve L = image ? SpectrumCurve(0.0f) : light_spectrum(ps, "L");
  float scale = ps.get_float("scale", 1);
  if (scale < 0) throw Error(ps.find_any("scale")->loc, "area light scale must not be negative");
  bool two_sided = ps.get_bool("twosided", false);
  float power = ps.get_float("power", -1);
  if (image && power > 0) {
    // pbrt-v4 normalises by the image's mean luminance.
    if (!(image_mean.luminance() > 0))
      throw Error(ps.find_any("power")->loc, "\"power\" is given but the image is black");
    scale /= image_mean.luminance();
  }
  ps.warn_unused("area light");
  if (std::holds_alternative<Sphere>(obj->shape) || std::holds_alternative<Disk>(obj->shape)) {
    const Transform& xf = std::holds_alternative<Sphere>(obj->shape)
                              ? std::get<Sphere>(obj->shape).world_from_object
                              : std::get<Disk>(obj->shape).world_from_object;
    bool full = std::holds_alternative<Sphere>(obj->shape) ? std::get<Sphere>(obj->shape).is_full()
                                                           : std::get<Disk>(obj->shape).is_full();
    if (!xf.is_similarity() || !full)
      throw Error(a.loc, "emitting spheres and disks must be whole and not non-uniformly scaled");
  }
  if (std::holds_alternative<Curves>(obj->shape))
    throw Error(a.loc, "a curve cannot emit (pbrt-v4 cannot sample curves as lights either)");
  if (auto* c = std::get_if<Cylinder>(&obj->shape); c && !c->world_from_object.is_similarity())
    throw Error(a.loc, "emitting cylinders must not be non-uniformly scaled");
  obj->first_light = int(rs->lights.size());
  for (int p = 0; p < primitive_count(obj->shape); ++p) {
    AreaLight l;
    l.object = id;
    l.primitive = p;
    l.two_sided = two_sided;
    l.area = primitive_area(obj->shape, p);
    float s = scale;
    // pbrt-v4 applies "power" to each shape it creates, i.e. to each triangle of a mesh.
    if (power > 0 && l.area > 0) s *= power / (kPi * (two_sided ? 2 : 1) * l.area);
    l.radiance = L.scaled(s);
    l.image = image;
    l.image_scale = s;
    l.image_mean = image_mean;
    rs->lights.push_back(l);
  }
}

}  // namespace bpm::flatten_internal
