#include "scene/bump.h"

#include <cmath>

namespace bpm {
namespace {

// dn/du and dn/dv from the second derivatives of p (the Weingarten equations).
void weingarten(Vec3 dpdu, Vec3 dpdv, Vec3 d2pduu, Vec3 d2pduv, Vec3 d2pdvv, Vec3* dndu,
                Vec3* dndv) {
  const float E = dot(dpdu, dpdu), F = dot(dpdu, dpdv), G = dot(dpdv, dpdv);
  const Vec3 n = normalize(cross(dpdu, dpdv));
  const float e = dot(n, d2pduu), f = dot(n, d2pduv), g = dot(n, d2pdvv);
  const float egf2 = E * G - F * F, inv = egf2 != 0 ? 1 / egf2 : 0;
  *dndu = dpdu * ((f * F - e * G) * inv) + dpdv * ((e * F - f * E) * inv);
  *dndv = dpdu * ((g * F - f * G) * inv) + dpdv * ((f * F - g * E) * inv);
}

// Object-space derivatives moved to world space: tangents as vectors, normal derivatives as
// normals.
SurfaceDerivatives to_world(const Transform& t, Vec3 dpdu, Vec3 dpdv, Vec3 dndu, Vec3 dndv) {
  return {t.vector(dpdu), t.vector(dpdv), t.normal(dndu), t.normal(dndv)};
}

SurfaceDerivatives mesh_derivatives(const TriangleMesh& m, int prim, const SurfacePoint& sp) {
  const uint32_t i0 = m.indices[3 * prim], i1 = m.indices[3 * prim + 1],
                 i2 = m.indices[3 * prim + 2];
  const Vec3 p0 = m.positions[i0], p1 = m.positions[i1], p2 = m.positions[i2];
  // pbrt-v4's default vertex uvs: (0,0), (1,0), (1,1).
  const Vec2 uv0 = m.uvs.empty() ? Vec2(0, 0) : m.uvs[i0];
  const Vec2 uv1 = m.uvs.empty() ? Vec2(1, 0) : m.uvs[i1];
  const Vec2 uv2 = m.uvs.empty() ? Vec2(1, 1) : m.uvs[i2];
  const Vec2 duv02(uv0.x - uv2.x, uv0.y - uv2.y), duv12(uv1.x - uv2.x, uv1.y - uv2.y);
  const Vec3 dp02 = p0 - p2, dp12 = p1 - p2;
  const float det = duv02.x * duv12.y - duv02.y * duv12.x;
  const bool degenerate = std::fabs(det) < 1e-9f;
  SurfaceDerivatives d{};
  if (!degenerate) {
    const float inv = 1 / det;
    d.dpdu = (dp02 * duv12.y - dp12 * duv02.y) * inv;
    d.dpdv = (dp12 * duv02.x - dp02 * duv12.x) * inv;
  }
  if (degenerate || length_squared(cross(d.dpdu, d.dpdv)) == 0) {
    const Frame f = Frame::from_z(normalize(cross(p2 - p0, p1 - p0)));
    d.dpdu = f.s;
    d.dpdv = f.t;
  }
  if (m.normals.empty()) return d;
  // With per-vertex normals pbrt-v4 shades with tangents perpendicular to the shading normal,
  // ss along dp/du, and dn/du, dn/dv from the vertex normals.
  Vec3 ss = d.dpdu, ts = cross(sp.ns, ss);
  if (length_squared(ts) > 0) {
    ss = cross(ts, sp.ns);
  } else {
    const Frame f = Frame::from_z(sp.ns);
    ss = f.s;
    ts = f.t;
  }
  d.dpdu = ss;
  d.dpdv = ts;
  const Vec3 n0 = m.normals[i0], n1 = m.normals[i1], n2 = m.normals[i2];
  if (degenerate) {
    const Vec3 dn = cross(n2 - n0, n1 - n0);
    if (length_squared(dn) == 0) {
      d.dndu = d.dndv = Vec3(0, 0, 0);
    } else {
      const Frame f = Frame::from_z(normalize(dn));
      d.dndu = f.s;
      d.dndv = f.t;
    }
  } else {
    const float inv = 1 / det;
    const Vec3 dn1 = n0 - n2, dn2 = n1 - n2;
    d.dndu = (dn1 * duv12.y - dn2 * duv02.y) * inv;
    d.dndv = (dn2 * duv02.x - dn1 * duv12.x) * inv;
  }
  return d;
}

SurfaceDerivatives sphere_derivatives(const Sphere& s, Vec3 p_world) {
  const Vec3 p = s.world_from_object.inverse().point(p_world);
  const float r = s.radius, z_radius = std::sqrt(p.x * p.x + p.y * p.y);
  const float cos_phi = z_radius > 0 ? p.x / z_radius : 1,
              sin_phi = z_radius > 0 ? p.y / z_radius : 0;
  const float cos_theta = std::clamp(p.z / r, -1.0f, 1.0f);
  const float sin_theta = std::sqrt(std::fmax(0.0f, 1 - cos_theta * cos_theta));
  const float theta_min = std::acos(std::clamp(std::fmin(s.z_min, s.z_max) / r, -1.0f, 1.0f));
  const float theta_max = std::acos(std::clamp(std::fmax(s.z_min, s.z_max) / r, -1.0f, 1.0f));
  const float dt = theta_max - theta_min;
  const Vec3 dpdu(-s.phi_max * p.y, s.phi_max * p.x, 0);
  const Vec3 dpdv = Vec3(p.z * cos_phi, p.z * sin_phi, -r * sin_theta) * dt;
  const Vec3 d2pduu = Vec3(p.x, p.y, 0) * (-s.phi_max * s.phi_max);
  const Vec3 d2pduv = Vec3(-sin_phi, cos_phi, 0) * (dt * p.z * s.phi_max);
  const Vec3 d2pdvv = p * (-dt * dt);
  Vec3 dndu, dndv;
  weingarten(dpdu, dpdv, d2pduu, d2pduv, d2pdvv, &dndu, &dndv);
  return to_world(s.world_from_object, dpdu, dpdv, dndu, dndv);
}

SurfaceDerivatives cylinder_derivatives(const Cylinder& c, Vec3 p_world) {
  const Vec3 p = c.world_from_object.inverse().point(p_world);
  const Vec3 dpdu(-c.phi_max * p.y, c.phi_max * p.x, 0), dpdv(0, 0, c.z_max - c.z_min);
  const Vec3 d2pduu = Vec3(p.x, p.y, 0) * (-c.phi_max * c.phi_max);
  Vec3 dndu, dndv;
  weingarten(dpdu, dpdv, d2pduu, Vec3(0, 0, 0), Vec3(0, 0, 0), &dndu, &dndv);
  return to_world(c.world_from_object, dpdu, dpdv, dndu, dndv);
}

SurfaceDerivatives disk_derivatives(const Disk& k, Vec3 p_world) {
  const Vec3 p = k.world_from_object.inverse().point(p_world);
  const float r = std::sqrt(p.x * p.x + p.y * p.y);
  const Vec3 dpdu(-k.phi_max * p.y, k.phi_max * p.x, 0);
  const Vec3 dpdv = r > 0 ? Vec3(p.x, p.y, 0) * ((k.inner_radius - k.radius) / r) : Vec3(0, 0, 0);
  return to_world(k.world_from_object, dpdu, dpdv, Vec3(0, 0, 0), Vec3(0, 0, 0));
}

}  // namespace

SurfaceDerivatives surface_derivatives(const Shape& shape, int prim, const SurfacePoint& sp) {
  if (auto* m = std::get_if<TriangleMesh>(&shape)) return mesh_derivatives(*m, prim, sp);
  if (auto* s = std::get_if<Sphere>(&shape)) return sphere_derivatives(*s, sp.p);
  if (auto* c = std::get_if<Cylinder>(&shape)) return cylinder_derivatives(*c, sp.p);
  if (auto* c = std::get_if<Curves>(&shape)) {  // pbrt-v4 gives curves no normal derivatives
    SurfaceDerivatives d;
    curve_derivatives(*c, prim, sp, &d.dpdu, &d.dpdv);
    return d;
  }
  return disk_derivatives(std::get<Disk>(shape), sp.p);
}

void apply_bump(const Bump& bump, const TextureSet& textures, const SurfaceDerivatives& d,
                SurfacePoint* sp) {
  Vec3 dpdu, dpdv;
  const Vec3 n = sp->ns;
  if (bump.normal_map) {
    // The map's RGB, 2 rgb - 1, is the normal in the frame (dp/du, n x dp/du, n), read at
    // (u, 1 - v) with the image's rows from the top, repeating.
    const Rgb c =
        bump.normal_map->lookup({sp->uv.x, 1 - sp->uv.y}, TexFilter::kBilinear, TexWrap::kRepeat);
    Vec3 local = normalize(Vec3(2 * c[0] - 1, 2 * c[1] - 1, 2 * c[2] - 1));
    const Vec3 x = normalize(d.dpdu), y = cross(n, x);
    const Vec3 ns = normalize(x * local.x + y * local.y + n * local.z);
    const float ulen = length(d.dpdu), vlen = length(d.dpdv);
    dpdu = normalize(d.dpdu - ns * dot(d.dpdu, ns)) * ulen;
    dpdv = normalize(cross(ns, dpdu)) * vlen;
  } else {
    constexpr float kStep = 0.0005f;
    const TextureContext at{sp->p, sp->uv};
    auto displace = [&](const TextureContext& c) {
      return bump.displacement->textured() ? textures.value(bump.displacement->texture, c)
                                           : bump.displacement->value;
    };
    const float d0 = displace(at);
    const float du = displace({sp->p + d.dpdu * kStep, Vec2(sp->uv.x + kStep, sp->uv.y)});
    const float dv = displace({sp->p + d.dpdv * kStep, Vec2(sp->uv.x, sp->uv.y + kStep)});
    dpdu = d.dpdu + n * ((du - d0) / kStep) + d.dndu * d0;
    dpdv = d.dpdv + n * ((dv - d0) / kStep) + d.dndv * d0;
  }
  const Vec3 ns = cross(dpdu, dpdv);
  const float len = length(ns);
  if (!(len > 0) || !std::isfinite(len)) return;  // a degenerate frame: the normal stays
  sp->ns = face_forward(ns / len, sp->ng);
}

}  // namespace bpm
