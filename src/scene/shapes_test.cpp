// Tests of the analytic cylinder (intersections against a closed-form reference in double
// precision, partial cylinders, surface points, bounds, the Embree scene) and of alpha masks in
// the Embree scene (meshes through the filter functions, analytic shapes in their callbacks), and
// of a mesh's open edges and the scene's query of primitives near a point.
#include "scene/shapes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "base/rng.h"
#include "base/sampling.h"
#include "scene/render_scene.h"

namespace bpm {
namespace {

float radians(float degrees) { return degrees * kPi / 180; }
bool contains(const Bounds3& b, Vec3 p) {
  return p.x >= b.lo.x && p.y >= b.lo.y && p.z >= b.lo.z && p.x <= b.hi.x && p.y <= b.hi.y &&
         p.z <= b.hi.z;
}

Transform cylinder_transform() {
  return Transform::translate(Vec3(0.5f, -1, 2)) *
         Transform::rotate(35, normalize(Vec3(1, 2, -0.5f))) *
         Transform::scale(Vec3(1.5f, 1.5f, 1.5f));
}

Cylinder make_cylinder(float phi_max_degrees = 360) {
  Cylinder c;
  c.world_from_object = cylinder_transform();
  c.radius = 0.8f;
  c.z_min = -0.3f;
  c.z_max = 1.1f;
  c.phi_max = radians(phi_max_degrees);
  return c;
}

// All ray parameters where the ray (in object space) meets the infinite cylinder, kept when the
// point lies on the bounded, partial surface: a direct solve without the stable form.
std::vector<double> reference_hits(const Cylinder& c, Vec3 o_world, Vec3 d_world) {
  Transform inv = c.world_from_object.inverse();
  Vec3 o = inv.point(o_world), d = inv.vector(d_world);
  double a = double(d.x) * d.x + double(d.y) * d.y;
  double b = 2 * (double(o.x) * d.x + double(o.y) * d.y);
  double cc = double(o.x) * o.x + double(o.y) * o.y - double(c.radius) * c.radius;
  double disc = b * b - 4 * a * cc;
  std::vector<double> ts;
  if (a == 0 || disc < 0) return ts;
  for (double t : {(-b - std::sqrt(disc)) / (2 * a), (-b + std::sqrt(disc)) / (2 * a)}) {
    double z = o.z + t * d.z;
    double phi = std::atan2(o.y + t * d.y, o.x + t * d.x);
    if (phi < 0) phi += 2 * M_PI;
    if (t > 0 && z >= c.z_min && z <= c.z_max && phi <= c.phi_max) ts.push_back(t);
  }
  return ts;
}

TEST(Cylinder, IntersectionsMatchTheClosedForm) {
  for (float phi_max : {360.0f, 250.0f, 90.0f}) {
    Cylinder c = make_cylinder(phi_max);
    Rng rng(11 + int(phi_max));
    Vec3 centre = c.world_from_object.point(Vec3(0, 0, 0.4f));
    int hits = 0, second_wall = 0;
    for (int k = 0; k < 20000; ++k) {
      // Rays from a shell around the cylinder toward points near it, and from inside it.
      bool inside = k % 4 == 0;
      Vec3 o = inside ? c.world_from_object.point(Vec3(0.2f, -0.3f, 0.5f))
                      : centre + sample_uniform_sphere({rng.uniform(), rng.uniform()}) * 5.0f;
      Vec3 target =
          centre + sample_uniform_sphere({rng.uniform(), rng.uniform()}) * (2.5f * rng.uniform());
      Vec3 d = normalize(target - o);
      std::vector<double> ref = reference_hits(c, o, d);
      double t = intersect_cylinder(c, o, d, 0, 1e30);
      if (ref.empty()) {
        EXPECT_LT(t, 0) << "phi_max " << phi_max << " ray " << k;
        continue;
      }
      ASSERT_GT(t, 0) << "phi_max " << phi_max << " ray " << k;
      EXPECT_NEAR(t, ref[0], 1e-5 * (1 + ref[0]));
      ++hits;
      if (ref.size() == 2) {
        // Past the first hit, the second one.
        double t2 = intersect_cylinder(c, o, d, ref[0] + 1e-4, 1e30);
        EXPECT_NEAR(t2, ref[1], 1e-5 * (1 + ref[1]));
        ++second_wall;
      } else if (double(ref[0]) != 0) {
        EXPECT_LT(intersect_cylinder(c, o, d, ref[0] + 1e-4, 1e30), 0);
      }
      // A ray stopped before the hit misses.
      EXPECT_LT(intersect_cylinder(c, o, d, 0, ref[0] * 0.999), 0);
    }
    EXPECT_GT(hits, 2000) << phi_max;
    EXPECT_GT(second_wall, phi_max > 100 ? 500 : 20)
        << phi_max;  // a quarter cylinder is rarely crossed twice
  }
  // Along the axis, never.
  Cylinder c = make_cylinder();
  Vec3 axis = c.world_from_object.vector(Vec3(0, 0, 1));
  EXPECT_LT(
      intersect_cylinder(c, c.world_from_object.point(Vec3(0.3f, 0, -5)), normalize(axis), 0, 1e30),
      0);
}

TEST(Cylinder, SurfacePointNormalAndUv) {
  Cylinder c = make_cylinder(270);
  Rng rng(5);
  for (bool flip : {false, true}) {
    c.flip_normal = flip;
    for (int k = 0; k < 1000; ++k) {
      float phi = rng.uniform() * c.phi_max, z = c.z_min + rng.uniform() * (c.z_max - c.z_min);
      Vec3 po(c.radius * std::cos(phi), c.radius * std::sin(phi), z);
      // A point slightly off the surface is projected back onto it.
      Vec3 off = c.world_from_object.point(po * 1.0001f - Vec3(0, 0, po.z * 0.0001f));
      SurfacePoint sp = surface_point(Shape(c), 0, {}, off);
      EXPECT_LT(length(sp.p - c.world_from_object.point(po)), 1e-4f);
      Vec3 axis_point = c.world_from_object.point(Vec3(0, 0, z));
      Vec3 outward = normalize(sp.p - axis_point);
      EXPECT_NEAR(dot(sp.ng, outward), flip ? -1.0f : 1.0f, 1e-4f);
      EXPECT_NEAR(sp.uv.x, phi / c.phi_max, 1e-4f);
      EXPECT_NEAR(sp.uv.y, (z - c.z_min) / (c.z_max - c.z_min), 1e-4f);
      Bounds3 b = world_bounds(Shape(c), 0);
      EXPECT_TRUE(contains(b, sp.p));
    }
  }
}

TEST(Cylinder, EmbreeSceneFindsTheCylinder) {
  RenderScene scene;
  Object obj;
  obj.shape = make_cylinder(200);
  scene.objects.push_back(obj);
  scene.materials.push_back(MaterialDesc{});
  scene.commit();
  const Cylinder& c = std::get<Cylinder>(scene.objects[0].shape);
  Rng rng(3);
  Vec3 centre = c.world_from_object.point(Vec3(0, 0, 0.4f));
  int hits = 0;
  for (int k = 0; k < 5000; ++k) {
    Vec3 o = centre + sample_uniform_sphere({rng.uniform(), rng.uniform()}) * 6.0f;
    Vec3 d = normalize(centre + sample_uniform_sphere({rng.uniform(), rng.uniform()}) * 1.5f - o);
    std::vector<double> ref = reference_hits(c, o, d);
    Ray ray{o, d, kInf};
    Hit h;
    bool hit = scene.intersect(ray, &h);
    ASSERT_EQ(hit, !ref.empty()) << k;
    EXPECT_EQ(scene.occluded_ray(ray), hit);
    if (!hit) continue;
    ++hits;
    EXPECT_NEAR(h.t, ref[0], 1e-4 * (1 + ref[0]));
    SurfacePoint sp = scene.surface(ray, h);
    EXPECT_LT(length(sp.p - (o + d * float(ref[0]))), 1e-3f);
  }
  EXPECT_GT(hits, 1000);
}

TriangleMesh square(float z) {
  TriangleMesh m;
  m.positions = {Vec3(-1, -1, z), Vec3(1, -1, z), Vec3(1, 1, z), Vec3(-1, 1, z)};
  m.positions.reserve(6);
  m.uvs = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

// Rays toward -z from random points above the layers, through the square [-0.9, 0.9]^2.
template <class PerRay>
void cast_down(uint64_t seed, int n, PerRay&& per_ray) {
  Rng rng(seed);
  for (int k = 0; k < n; ++k) {
    Vec3 o(2 * rng.uniform() - 1, 2 * rng.uniform() - 1, 5);
    Vec3 target(1.8f * rng.uniform() - 0.9f, 1.8f * rng.uniform() - 0.9f, 0);
    per_ray(Ray{o, normalize(target - o), kInf}, target);
  }
}

TEST(Alpha, ConstantAlphaStopsThatFractionOfRaysAndLayersDecideIndependently) {
  for (bool analytic : {false, true}) {
    RenderScene scene;
    scene.materials.push_back(MaterialDesc{});
    for (float z : {1.0f, 0.5f}) {  // two layers of alpha 0.3
      Object obj;
      if (analytic) {
        Disk d;
        d.world_from_object = Transform::translate(Vec3(0, 0, z));
        d.radius = 3;
        obj.shape = d;
      } else {
        obj.shape = square(z);
      }
      obj.alpha = FloatParam{0.3f, -1};
      scene.objects.push_back(obj);
    }
    scene.commit();
    const int n = 40000;
    int first = 0, second = 0, none = 0, occluded = 0, same = 0;
    cast_down(analytic ? 21 : 22, n, [&](const Ray& ray, Vec3) {
      Hit h, h2;
      bool hit = scene.intersect(ray, &h);
      if (!hit)
        ++none;
      else if (h.object == 0)
        ++first;
      else
        ++second;
      occluded += scene.occluded_ray(ray);
      // The same ray always gets the same answer.
      same += scene.intersect(ray, &h2) == hit && (!hit || h2.object == h.object);
    });
    // P(first) = 0.3, P(second) = 0.7 * 0.3, P(none) = 0.49; binomial sigma < 0.0025.
    EXPECT_NEAR(first / double(n), 0.3, 0.0125) << analytic;
    EXPECT_NEAR(second / double(n), 0.21, 0.0125) << analytic;
    EXPECT_NEAR(none / double(n), 0.49, 0.0125) << analytic;
    EXPECT_NEAR(occluded / double(n), 0.51, 0.0125) << analytic;
    EXPECT_EQ(same, n);
  }
}

TEST(Alpha, TexturedAlphaCutsOutTheCheckerboardCells) {
  for (bool analytic : {false, true}) {
    RenderScene scene;
    scene.materials.push_back(MaterialDesc{});
    CheckerboardTexture cb;
    cb.mapping.su = cb.mapping.sv = 4;
    cb.tex1 = scene.textures.add(ConstantTexture{SpectrumCurve(0.0f), 0.0f});
    cb.tex2 = scene.textures.add(ConstantTexture{SpectrumCurve(1.0f), 1.0f});
    Object obj;
    if (analytic) {
      // A quarter disk of radius 2 centred at (-1, -1): its uv differ, so compare cells by uv.
      Disk d;
      d.world_from_object = Transform::translate(Vec3(-1, -1, 1));
      d.radius = 3;
      d.phi_max = kPi / 2;
      obj.shape = d;
    } else {
      obj.shape = square(1);
    }
    obj.alpha = FloatParam{0, scene.textures.add(cb)};
    scene.objects.push_back(obj);
    scene.commit();
    int hits = 0, passes = 0;
    cast_down(analytic ? 31 : 32, 5000, [&](const Ray& ray, Vec3) {
      float t = (1 - ray.o.z) / ray.d.z;
      SurfacePoint sp = surface_point(scene.objects[0].shape, 0, {}, ray.o + ray.d * t);
      if (!analytic) {
        Vec3 p = ray.o + ray.d * t;
        sp.uv = {(p.x + 1) / 2, (p.y + 1) / 2};
      }
      float s = 4 * sp.uv.x, tt = 4 * sp.uv.y;
      if (std::fabs(s - std::round(s)) < 1e-3f || std::fabs(tt - std::round(tt)) < 1e-3f) return;
      bool opaque = (int(std::floor(s)) + int(std::floor(tt))) % 2 != 0;
      Hit h;
      ASSERT_EQ(scene.intersect(ray, &h), opaque) << sp.uv.x << " " << sp.uv.y;
      ASSERT_EQ(scene.occluded_ray(ray), opaque);
      (opaque ? hits : passes) += 1;
    });
    EXPECT_GT(hits, 1500);
    EXPECT_GT(passes, 1500);
  }
}

// A quad's two triangles share their diagonal; its four sides are open. Corners repeated as
// vertices of their own (a seam of uvs) still meet by position. An edge of three triangles (a fin
// on the quad's diagonal) counts as open: no one surface goes on across it.
TEST(TriangleMesh, OpenEdgesAreTheBordersOfTheMesh) {
  TriangleMesh quad;
  quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  quad.compute_open_edges();
  // Triangle 0: edges 0-1 and 1-2 open, 2-0 (the diagonal) shared; triangle 1: 0-2 shared.
  EXPECT_EQ(quad.open_edges, (std::vector<uint8_t>{0b011, 0b110}));
  TriangleMesh split = quad;
  split.positions = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 0}, {1, 0, 1}, {0, 0, 1}};
  split.indices = {0, 1, 2, 3, 4, 5};
  split.compute_open_edges();
  EXPECT_EQ(split.open_edges, quad.open_edges);
  TriangleMesh fin = quad;
  fin.positions.push_back({0.5f, 1, 0.5f});
  fin.indices.insert(fin.indices.end(), {0, 2, 4});
  fin.compute_open_edges();
  EXPECT_EQ(fin.open_edges[0], 0b111);
  EXPECT_EQ(fin.open_edges[1], 0b111);
  EXPECT_EQ(fin.open_edges[2], 0b111);
  // A corner lifted: the two triangles meet at an angle across the diagonal, both bent.
  TriangleMesh bent = quad;
  bent.positions[3] = {0, 0.5f, 1};
  bent.compute_open_edges();
  EXPECT_EQ(bent.open_edges,
            (std::vector<uint8_t>{0b011 | TriangleMesh::kBentBit, 0b110 | TriangleMesh::kBentBit}));
  // Both faces of a double-sided quad: its sides have two triangles each, but on the same side of
  // them (no surface beyond), and the diagonal has four.
  TriangleMesh two_sided = quad;
  two_sided.indices = {0, 1, 2, 0, 2, 3, 0, 2, 1, 0, 3, 2};
  two_sided.compute_open_edges();
  EXPECT_EQ(two_sided.open_edges, (std::vector<uint8_t>{0b111, 0b111, 0b111, 0b111}));
  // A quad folded flat onto itself along its diagonal: the diagonal is a border.
  TriangleMesh folded = quad;
  folded.positions[3] = {1, 0, 0};
  folded.compute_open_edges();
  EXPECT_EQ(folded.open_edges[0] & 0b100, 0b100);
}

// The query visits every primitive within the radius (and may visit more), and stops when told.
TEST(RenderScene, ForEachNearVisitsThePrimitivesWithinTheRadius) {
  RenderScene scene;
  for (int k = 0; k < 50; ++k) {  // small triangles along x, one object each
    TriangleMesh m;
    const float x = float(k);
    m.positions = {{x, 0, 0}, {x + 0.5f, 0, 0}, {x, 0, 0.5f}};
    m.indices = {0, 1, 2};
    Object o;
    o.shape = m;
    scene.objects.push_back(o);
  }
  Sphere ball;
  ball.world_from_object = Transform::translate(Vec3(10, 2, 0));
  ball.radius = 0.5f;
  Object o;
  o.shape = ball;
  scene.objects.push_back(o);
  scene.commit();
  std::vector<int> seen;
  scene.for_each_near(Vec3(20.2f, 0.1f, 0.1f), 1.2f, [&](int object, int prim) {
    EXPECT_EQ(prim, 0);
    seen.push_back(object);
    return true;
  });
  for (int k : {19, 20, 21}) EXPECT_NE(std::find(seen.begin(), seen.end(), k), seen.end()) << k;
  seen.clear();
  scene.for_each_near(Vec3(10, 1.2f, 0), 0.5f, [&](int object, int) {
    seen.push_back(object);
    return true;
  });
  EXPECT_NE(std::find(seen.begin(), seen.end(), 50), seen.end()) << "the sphere";
  int visits = 0;
  scene.for_each_near(Vec3(25, 0, 0), 100.0f, [&](int, int) { return ++visits < 3; });
  EXPECT_EQ(visits, 3);
}

}  // namespace
}  // namespace bpm
