// Tests of lights: emitted power against numerical integrals, the density of light_sample_li
// (Monte Carlo estimates of solid-angle integrals, agreement with light_pdf_li, and a chi-square
// test of the sampled directions), and the spot light falloff.
#include "lights/light.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <tuple>
#include <utility>

#include "base/chi2_test_util.h"
#include "base/rng.h"
#include "base/sampling.h"
#include "base/transform.h"
#include "scene/shapes.h"
#include "textures/texture.h"

namespace bpm {
namespace {

const SceneBoundsInfo kBounds{Vec3(0, 0, 0), 10};
// Lights are tested at one fixed set of wavelengths; kLs is kL there.
const Wavelengths kWl = sample_wavelengths(0.37f);
const SpectrumCurve kL = SpectrumCurve::from_rgb(Rgb(1.0f, 2.0f, 0.5f), SpectrumKind::kIlluminant);
const Spectrum kLs = kL.sample(kWl);

SpectrumCurve light_rgb(float r, float g, float b) {
  return SpectrumCurve::from_rgb(Rgb(r, g, b), SpectrumKind::kIlluminant);
}

// The emission curve of a light, and its power per unit of that curve (light_power / curve rgb).
const SpectrumCurve& emission_curve(const Light& l) {
  if (auto* p = std::get_if<PointLight>(&l)) return p->intensity;
  if (auto* p = std::get_if<SpotLight>(&l)) return p->intensity;
  if (auto* p = std::get_if<GoniometricLight>(&l)) return p->intensity;
  if (auto* p = std::get_if<DistantLight>(&l)) return p->radiance;
  if (auto* p = std::get_if<UniformInfiniteLight>(&l)) return p->radiance;
  return std::get<AreaLight>(l).radiance;
}
// The spectral power at kWl that light_power's colour stands for.
Spectrum spectral_power(const Light& l) {
  const SpectrumCurve& c = emission_curve(l);
  return c.sample(kWl) * (light_power(l, kBounds)[1] / c.rgb()[1]);
}

struct D3 {
  double x, y, z;
};
D3 d3(Vec3 v) { return {v.x, v.y, v.z}; }
D3 sub(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
double ddot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 dcross(D3 a, D3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double dlen(D3 a) { return std::sqrt(ddot(a, a)); }

TriangleMesh make_triangle(bool flip = false) {
  TriangleMesh m;
  m.positions = {Vec3(0.2f, -0.1f, 1.0f), Vec3(1.7f, 0.3f, 1.2f), Vec3(0.4f, 1.4f, 0.7f)};
  m.indices = {0, 1, 2};
  m.flip_normal = flip;
  return m;
}
double triangle_area(const TriangleMesh& m) {
  D3 p0 = d3(m.positions[0]), p1 = d3(m.positions[1]), p2 = d3(m.positions[2]);
  return 0.5 * dlen(dcross(sub(p1, p0), sub(p2, p0)));
}
// The documented orientation (shapes.h, pbrt-v4): cross(p0 - p2, p1 - p2).
Vec3 triangle_normal(const TriangleMesh& m) {
  Vec3 n = normalize(cross(m.positions[0] - m.positions[2], m.positions[1] - m.positions[2]));
  return m.flip_normal ? -n : n;
}
// Solid angle of the triangle seen from p (Van Oosterom and Strackee 1983).
double triangle_solid_angle(const TriangleMesh& m, Vec3 p) {
  D3 a = sub(d3(m.positions[0]), d3(p)), b = sub(d3(m.positions[1]), d3(p)),
     c = sub(d3(m.positions[2]), d3(p));
  double la = dlen(a), lb = dlen(b), lc = dlen(c);
  double num = std::fabs(ddot(a, dcross(b, c)));
  double den = la * lb * lc + ddot(a, b) * lc + ddot(a, c) * lb + ddot(b, c) * la;
  return 2 * std::atan2(num, den);
}

Sphere make_sphere(Vec3 center, float radius) {
  Sphere s;
  s.world_from_object = Transform::translate(center);
  s.radius = radius;
  return s;
}

// A partial cylinder under a similarity transform.
Cylinder make_cylinder() {
  Cylinder c;
  c.world_from_object = Transform::translate(Vec3(1, 2, 3)) *
                        Transform::rotate(30, normalize(Vec3(1, 1, 0))) *
                        Transform::scale(Vec3(2, 2, 2));
  c.radius = 0.25f;
  c.z_min = -0.2f;
  c.z_max = 0.3f;
  c.phi_max = 1.5f * kPi;
  return c;
}

AreaLight make_area_light(const Shape& shape, bool two_sided) {
  AreaLight l;
  l.object = 0;
  l.primitive = 0;
  l.radiance = kL;
  l.two_sided = two_sided;
  l.area = primitive_area(shape, 0);
  return l;
}

void expect_mean(const MeanAccumulator& a, double expected, double extra, const char* what) {
  EXPECT_NEAR(a.mean, expected, kMeanTestSigmas * a.standard_error() + extra)
      << what << ": mean " << a.mean << " +- " << a.standard_error() << ", expected " << expected;
}

// ---------------------------------------------------------------------------------------------
// Power.

// Power of a diffuse emitter = integral over its area and over the sphere of directions of
// L(p, w) |cos|: estimated with uniform points (own barycentric sampling) and uniform directions.
template <class PointSampler>
void check_area_light_power(const Shape& shape, const AreaLight& l, double area,
                            PointSampler&& sample_point, uint64_t seed) {
  Spectrum power = spectral_power(Light(l));
  Rgb power_rgb = light_power(Light(l), kBounds);
  Rng rng(seed);
  MeanAccumulator est[Spectrum::kChannels];
  for (int k = 0; k < 200000; ++k) {
    Vec3 n = sample_point(rng);
    Vec3 w = sample_uniform_sphere({rng.uniform(), rng.uniform()});
    Spectrum le = area_light_radiance(l, n, {}, w, kWl);
    for (int c = 0; c < Spectrum::kChannels; ++c)
      est[c].add(double(le[c]) * std::fabs(dot(n, w)) * area / kUniformSpherePdfSolidAngle);
  }
  for (int c = 0; c < Spectrum::kChannels; ++c)
    expect_mean(est[c], power[c], 0, l.two_sided ? "two-sided" : "one-sided");
  // And the closed form: pi A L per emitting side.
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(power_rgb[c], kPi * area * kL.rgb()[c] * (l.two_sided ? 2 : 1),
                1e-5 * power_rgb[c]);
  (void)shape;
}

TEST(LightPower, TriangleAreaLight) {
  Shape shape = make_triangle();
  const auto& mesh = std::get<TriangleMesh>(shape);
  double area = triangle_area(mesh);
  EXPECT_NEAR(primitive_area(shape, 0), area, 1e-6 * area);
  for (bool two_sided : {false, true}) {
    AreaLight l = make_area_light(shape, two_sided);
    check_area_light_power(
        shape, l, area,
        [&](Rng& rng) {
          float su = std::sqrt(rng.uniform()), v = rng.uniform();
          SurfacePoint sp = surface_point(shape, 0, {su * (1 - v), su * v}, {});
          return sp.ng;
        },
        two_sided ? 2 : 1);
  }
}

TEST(LightPower, SphereAreaLight) {
  Vec3 c(1, 2, 3);
  float r = 0.5f;
  Shape shape = make_sphere(c, r);
  double area = 4 * M_PI * r * r;
  EXPECT_NEAR(primitive_area(shape, 0), area, 1e-5 * area);
  for (bool two_sided : {false, true}) {
    AreaLight l = make_area_light(shape, two_sided);
    check_area_light_power(
        shape, l, area,
        [&](Rng& rng) {
          Vec3 d = sample_uniform_sphere({rng.uniform(), rng.uniform()});
          SurfacePoint sp = surface_point(shape, 0, {}, c + d * r);
          EXPECT_GT(dot(sp.ng, d), 0.999f);  // outward normal
          return sp.ng;
        },
        3 + two_sided);
  }
}

TEST(LightPower, CylinderAreaLight) {
  Cylinder c = make_cylinder();
  Shape shape = c;
  double area = 1.5 * M_PI * (0.25 * 2) * (0.5 * 2);  // phi_max r h in world units (scale 2)
  EXPECT_NEAR(primitive_area(shape, 0), area, 1e-5 * area);
  for (bool two_sided : {false, true}) {
    AreaLight l = make_area_light(shape, two_sided);
    check_area_light_power(
        shape, l, area,
        [&](Rng& rng) {
          float phi = rng.uniform() * c.phi_max, z = c.z_min + rng.uniform() * (c.z_max - c.z_min);
          SurfacePoint sp =
              surface_point(shape, 0, {},
                            c.world_from_object.point(
                                Vec3(c.radius * std::cos(phi), c.radius * std::sin(phi), z)));
          return sp.ng;
        },
        5 + two_sided);
  }
}

TEST(LightPower, PrimitiveAreaUnderScaleAndForPartialShapes) {
  Sphere s = make_sphere(Vec3(1, 2, 3), 0.5f);
  s.world_from_object = Transform::translate(Vec3(1, 2, 3)) * Transform::scale(Vec3(2, 2, 2));
  EXPECT_NEAR(primitive_area(Shape(s), 0), 4 * M_PI * 1.0 * 1.0, 1e-4);  // world radius 1
  Sphere part = make_sphere(Vec3(0, 0, 0), 0.5f);
  part.z_min = -0.25f;
  part.z_max = 0.5f;
  part.phi_max = kPi;
  // A spherical zone has area 2 pi r h; half of it in phi.
  EXPECT_NEAR(primitive_area(Shape(part), 0), M_PI * 0.5 * 0.75, 1e-5);
  Disk d;
  d.radius = 2;
  d.inner_radius = 1;
  d.world_from_object = Transform::scale(Vec3(3, 3, 3));
  EXPECT_NEAR(primitive_area(Shape(d), 0), M_PI * (4 - 1) * 9, 1e-3);
}

TEST(LightPower, PointLight) {
  PointLight p{Vec3(1, 2, 3), light_rgb(2.0f, 3.0f, 4.0f)};
  Rgb power = light_power(Light(p), kBounds);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(power[c], 4 * M_PI * p.intensity.rgb()[c], 1e-5 * power[c]);
  auto s = light_sample_li(Light(p), nullptr, Vec3(1, 2, 5), {0.5f, 0.5f}, kBounds, kWl);
  ASSERT_TRUE(s.has_value());
  EXPECT_TRUE(s->is_delta);
  EXPECT_NEAR(s->radiance[0], p.intensity.value(kWl.lambda[0]) / 4, 1e-6f);
  EXPECT_NEAR(s->wi.z, -1.0f, 1e-6f);
}

SpotLight make_spot() {
  SpotLight l;
  l.position = Vec3(0.5f, -1, 2);
  l.frame = Frame::from_z(normalize(Vec3(0.3f, -0.4f, 0.87f)));
  l.intensity = light_rgb(2.0f, 1.0f, 0.5f);
  l.cos_falloff_start = std::cos(20 * kPi / 180);
  l.cos_falloff_end = std::cos(35 * kPi / 180);
  return l;
}

TEST(LightPower, SpotLightMatchesIntegralOfFalloff) {
  SpotLight l = make_spot();
  Rgb power = light_power(Light(l), kBounds);
  // Power = I * integral over the sphere of falloff = I * 2 pi * integral_{-1}^{1} falloff(cos)
  // dcos.
  const int n = 200000;
  double integral = 0;
  for (int k = 0; k < n; ++k) {
    double c = -1 + (k + 0.5) * 2.0 / n;
    integral += spot_falloff(l, Vec3(float(std::sqrt(1 - c * c)), 0, float(c)));
  }
  integral *= 2 * M_PI * 2.0 / n;
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(power[c], l.intensity.rgb()[c] * integral, 1e-3 * power[c]) << c;
}

// The intensity that light_sample_li delivers, integrated over all directions from the light.
TEST(LightPower, SpotLightMatchesSampledIntensity) {
  SpotLight l = make_spot();
  Spectrum power = spectral_power(Light(l));
  Rng rng(7);
  MeanAccumulator est[Spectrum::kChannels];
  for (int k = 0; k < 200000; ++k) {
    Vec3 w = sample_uniform_sphere({rng.uniform(), rng.uniform()});
    const float d = 2;
    auto s = light_sample_li(Light(l), nullptr, l.position + w * d, {0.5f, 0.5f}, kBounds, kWl);
    for (int c = 0; c < Spectrum::kChannels; ++c)
      est[c].add(s ? double(s->radiance[c]) * d * d / kUniformSpherePdfSolidAngle : 0.0);
    if (s) {
      ASSERT_TRUE(s->is_delta);
      ASSERT_NEAR(dot(s->wi, w), -1.0f, 1e-5f);
    }
  }
  for (int c = 0; c < Spectrum::kChannels; ++c) expect_mean(est[c], power[c], 0, "spot power");
}

TEST(SpotLight, Falloff) {
  SpotLight l = make_spot();
  auto f = [&](double c) {
    return spot_falloff(l, Vec3(float(std::sqrt(std::fmax(0.0, 1 - c * c))), 0, float(c)));
  };
  EXPECT_EQ(f(1.0), 1.0f);
  EXPECT_EQ(f(l.cos_falloff_start + 1e-4), 1.0f);
  EXPECT_EQ(f(l.cos_falloff_end - 1e-4), 0.0f);
  EXPECT_EQ(f(-1.0), 0.0f);
  EXPECT_EQ(f(0.0), 0.0f);
  // Smoothstep: 1/2 halfway between the two cosines.
  EXPECT_NEAR(f(0.5 * (l.cos_falloff_start + l.cos_falloff_end)), 0.5f, 1e-4f);
  float prev = -1;
  for (int k = 0; k <= 20000; ++k) {
    double c = -1 + 2.0 * k / 20000;
    float v = f(c);
    ASSERT_GE(v, 0.0f);
    ASSERT_LE(v, 1.0f);
    ASSERT_GE(v, prev) << "not monotone at cos " << c;
    prev = v;
  }
  // The cone axis is frame.n: a point along the axis receives the full intensity.
  auto s = light_sample_li(Light(l), nullptr, l.position + l.frame.n * 3, {}, kBounds, kWl);
  ASSERT_TRUE(s.has_value());
  EXPECT_NEAR(s->radiance[0], l.intensity.value(kWl.lambda[0]) / 9, 1e-5f);
  EXPECT_FALSE(
      light_sample_li(Light(l), nullptr, l.position - l.frame.n * 3, {}, kBounds, kWl).has_value());
}

// ---------------------------------------------------------------------------------------------
// light_sample_li densities.

// E[Li / pdf] over light_sample_li equals the integral of the incident radiance over solid
// angle; each sample's pdf equals light_pdf_li at the sampled point.
struct LiCheck {
  MeanAccumulator est[Spectrum::kChannels];
  int n_samples = 0, n_none = 0;
};

template <class PerSample>
LiCheck run_li(const Light& light, const Shape& shape, Vec3 p_ref, uint64_t seed, int n,
               PerSample&& per_sample) {
  LiCheck r;
  Rng rng(seed);
  for (int k = 0; k < n; ++k) {
    auto s = light_sample_li(light, &shape, p_ref, {rng.uniform(), rng.uniform()}, kBounds, kWl);
    ++r.n_samples;
    if (!s) {
      ++r.n_none;
      for (auto& e : r.est) e.add(0);
      continue;
    }
    EXPECT_FALSE(s->is_delta);
    EXPECT_NEAR(length(s->wi), 1.0f, 1e-5f);
    EXPECT_GT(s->pdf_solid_angle, 0);
    float pdf = light_pdf_li(light, &shape, p_ref, s->wi, s->p_light, s->n_light);
    EXPECT_NEAR(pdf, s->pdf_solid_angle, 1e-3f * s->pdf_solid_angle);
    for (int c = 0; c < Spectrum::kChannels; ++c)
      r.est[c].add(double(s->radiance[c]) / s->pdf_solid_angle);
    per_sample(*s);
  }
  return r;
}

TEST(LightSampleLi, TriangleSolidAngle) {
  for (bool flip : {false, true}) {
    Shape shape = make_triangle(flip);
    const auto& mesh = std::get<TriangleMesh>(shape);
    Vec3 ng = triangle_normal(mesh);
    Vec3 centroid = (mesh.positions[0] + mesh.positions[1] + mesh.positions[2]) / 3;
    Vec3 front = centroid + ng * 0.6f + Vec3(0.3f, -0.2f, 0.1f);
    ASSERT_GT(dot(front - mesh.positions[0], ng), 0.1f);
    Vec3 back = centroid - (front - centroid);
    for (bool two_sided : {false, true}) {
      Light light = make_area_light(shape, two_sided);
      for (bool from_front : {true, false}) {
        Vec3 p_ref = from_front ? front : back;
        bool lit = two_sided || from_front;
        double omega = triangle_solid_angle(mesh, p_ref);
        auto check = [&](const LightLiSample& s) {
          // On the triangle, in its plane, with its normal, and in the direction of wi.
          EXPECT_NEAR(dot(s.p_light - mesh.positions[0], ng), 0.0f, 1e-5f);
          EXPECT_NEAR(dot(s.n_light, ng), 1.0f, 1e-5f);
          EXPECT_NEAR(dot(normalize(s.p_light - p_ref), s.wi), 1.0f, 1e-5f);
          EXPECT_NEAR(s.radiance[1], kLs[1], 1e-6f);
        };
        LiCheck r =
            run_li(light, shape, p_ref, 100 + 10 * flip + 2 * two_sided + lit, 100000, check);
        if (!lit) {
          EXPECT_EQ(r.n_none, r.n_samples) << "the back of a one-sided emitter must be dark";
          continue;
        }
        EXPECT_EQ(r.n_none, 0);
        for (int c = 0; c < Spectrum::kChannels; ++c)
          expect_mean(r.est[c], kLs[c] * omega, 0, "triangle");
      }
    }
  }
}

TEST(LightSampleLi, SphereFromOutsideSamplesTheCone) {
  Vec3 c(1, 2, 3);
  float radius = 0.5f;
  Sphere sphere = make_sphere(c, radius);
  Shape shape = sphere;
  Light light = make_area_light(shape, false);
  Vec3 p_ref = c + Vec3(0.9f, -1.1f, 0.6f);
  double d = dlen(sub(d3(p_ref), d3(c)));
  double cos_max = std::sqrt(1 - radius * radius / (d * d));
  double omega = 2 * M_PI * (1 - cos_max);
  Vec3 axis = normalize(c - p_ref);
  auto check = [&](const LightLiSample& s) {
    EXPECT_GE(dot(s.wi, axis), cos_max - 1e-5);
    EXPECT_NEAR(length(s.p_light - c), radius, 1e-4f);
    // The nearest intersection along wi.
    double t = intersect_sphere(sphere, p_ref, s.wi, 1e-4, 1e30);
    if (t > 0) {  // (a direction within float rounding of the silhouette may miss in double)
      EXPECT_LT(length(p_ref + s.wi * float(t) - s.p_light), 2e-3f);
    }
    EXPECT_GT(dot(s.n_light, normalize(s.p_light - c)), 0.999f);
    EXPECT_GE(dot(s.n_light, -s.wi), 0.0f);
  };
  LiCheck r = run_li(light, shape, p_ref, 200, 100000, check);
  // Every sample returns L / pdf = L * omega: a zero-variance estimator; 1e-4 covers float
  // rounding.
  for (int ch = 0; ch < Spectrum::kChannels; ++ch)
    expect_mean(r.est[ch], kLs[ch] * omega, 1e-4 * kLs[ch] * omega, "sphere");
}

// From inside, points are sampled by area; a two-sided sphere surrounds p_ref with radiance L.
// From a point outside a partial cylinder, E[Li / pdf] counts every emitting-side crossing of
// each direction (light_sample_li leaves occlusion to the shadow ray): the reference counts
// them along uniformly drawn directions.
TEST(LightSampleLi, CylinderMatchesCountedCrossings) {
  Cylinder c = make_cylinder();
  Shape shape = c;
  Vec3 p_ref = c.world_from_object.point(Vec3(0.6f, -0.5f, 0.1f));
  for (bool two_sided : {false, true}) {
    Light light = make_area_light(shape, two_sided);
    Rng rng(400 + two_sided);
    MeanAccumulator ref;
    for (int k = 0; k < 400000; ++k) {
      Vec3 w = sample_uniform_sphere({rng.uniform(), rng.uniform()});
      int n = 0;
      double t = 0;
      while ((t = intersect_cylinder(c, p_ref, w, t + 1e-5, 1e30)) > 0) {
        SurfacePoint sp = surface_point(shape, 0, {}, p_ref + w * float(t));
        if (two_sided || dot(sp.ng, w) < 0) ++n;
      }
      ref.add(n / kUniformSpherePdfSolidAngle);
    }
    LiCheck r = run_li(light, shape, p_ref, 410 + two_sided, 200000, [&](const LightLiSample& s) {
      Vec3 po = c.world_from_object.inverse().point(s.p_light);
      EXPECT_NEAR(std::hypot(po.x, po.y), c.radius, 1e-4f);
    });
    for (int ch = 0; ch < Spectrum::kChannels; ++ch) {
      double se = std::sqrt(r.est[ch].standard_error() * r.est[ch].standard_error() +
                            kLs[ch] * ref.standard_error() * kLs[ch] * ref.standard_error());
      EXPECT_NEAR(r.est[ch].mean, kLs[ch] * ref.mean, kMeanTestSigmas * se)
          << "two-sided " << two_sided;
    }
  }
}

TEST(LightSampleLi, SphereFromInside) {
  Vec3 c(1, 2, 3);
  float radius = 0.5f;
  Sphere sphere = make_sphere(c, radius);
  Shape shape = sphere;
  Vec3 p_ref = c + Vec3(0.1f, -0.15f, 0.2f);
  auto none = [](const LightLiSample&) {};
  LiCheck dark = run_li(make_area_light(shape, false), shape, p_ref, 300, 10000, none);
  EXPECT_EQ(dark.n_none, dark.n_samples) << "a one-sided sphere emits outward only";
  Light light = make_area_light(shape, true);
  LiCheck r = run_li(light, shape, p_ref, 301, 100000, none);
  for (int ch = 0; ch < Spectrum::kChannels; ++ch)
    expect_mean(r.est[ch], kLs[ch] * 4 * M_PI, 0, "inside sphere");

  // The directions follow light_pdf_li (the chi-square harness of the BSDF tests; the image
  // lights' test runs two more, on their texels).
  chi2::Options o;
  o.n_tests = 3;
  o.sub = 32;  // this pdf is smooth (no discontinuity inside cells): O(h^2) integration suffices
  auto res = chi2::run(
      [&](Rng& rng) -> std::optional<Vec3> {
        auto s =
            light_sample_li(light, &shape, p_ref, {rng.uniform(), rng.uniform()}, kBounds, kWl);
        if (!s) return std::nullopt;
        return s->wi;
      },
      [&](Vec3 w) {
        double t = intersect_sphere(sphere, p_ref, w, 0, 1e30);
        if (!(t > 0)) return 0.0;
        Vec3 p = p_ref + w * float(t);
        SurfacePoint sp = surface_point(shape, 0, {}, p);
        return double(light_pdf_li(light, &shape, p_ref, w, sp.p, sp.ng));
      },
      302, o);
  EXPECT_TRUE(res.passed()) << res.report;
}

// ---------------------------------------------------------------------------------------------
// Environment image lights.

// A small image with a smooth gradient and one bright texel, in either layout, rotated so that
// the light's +z is the world's +y.
ImageInfiniteLight make_image_light(bool equal_area) {
  auto im = std::make_shared<TexImage>();
  im->width = equal_area ? 16 : 32;
  im->height = 16;
  im->channels = 3;
  im->texels.resize(size_t(im->width) * im->height * 3);
  for (int y = 0; y < im->height; ++y)
    for (int x = 0; x < im->width; ++x) {
      float* t = &im->texels[(size_t(y) * im->width + x) * 3];
      t[0] = 0.2f + 0.6f * x / im->width;
      t[1] = 0.1f + 0.5f * y / im->height;
      t[2] = 0.3f;
      if (x == 5 && y == 9) t[0] = t[1] = t[2] = 40;  // a sun
    }
  ImageInfiniteLight l;
  l.image = im;
  l.equal_area = equal_area;
  l.world_from_light = Transform::rotate(-90, Vec3(1, 0, 0));
  l.scale = 1.5f;
  prepare_image_light(&l);
  return l;
}

// The texel (x, y) an image light's direction falls in.
std::pair<int, int> texel_of(const ImageInfiniteLight& l, Vec3 w) {
  Vec2 uv = image_light_uv(l, w);
  return {std::clamp(int(uv.x * l.image->width), 0, l.image->width - 1),
          std::clamp(int(uv.y * l.image->height), 0, l.image->height - 1)};
}
Spectrum texel_radiance(const ImageInfiniteLight& l, int x, int y) {
  return rgb_texel_spectrum(l.image->texel(x, y, TexWrap::kClamp), SpectrumKind::kIlluminant, kWl) *
         l.scale;
}
// The integral of the radiance over the sphere, texel by texel (each texel's solid angle from
// the layout's geometry, independently of image_light_jacobian).
Spectrum integrated_radiance(const ImageInfiniteLight& l) {
  const TexImage& im = *l.image;
  Spectrum sum;
  for (int y = 0; y < im.height; ++y) {
    double omega =
        l.equal_area ? 4 * M_PI / (im.width * im.height)
                     : 2 * M_PI / im.width *
                           (std::cos(M_PI * y / im.height) - std::cos(M_PI * (y + 1) / im.height));
    for (int x = 0; x < im.width; ++x) sum += texel_radiance(l, x, y) * float(omega);
  }
  return sum;
}

TEST(ImageLight, OrientationAndRadiance) {
  for (bool equal_area : {true, false}) {
    ImageInfiniteLight l = make_image_light(equal_area);
    // The light's +z is the world's +y: the centre of an equal-area image, the top row of a
    // latitude-longitude one.
    auto [x, y] = texel_of(l, Vec3(0, 1, 0));
    if (equal_area) {
      EXPECT_TRUE((x == 7 || x == 8) && (y == 7 || y == 8)) << x << "," << y;
    } else {
      EXPECT_EQ(y, 0);
    }
    Rng rng(17);
    for (int k = 0; k < 2000; ++k) {
      Vec3 w = sample_uniform_sphere({rng.uniform(), rng.uniform()});
      auto [tx, ty] = texel_of(l, w);
      Spectrum L = environment_radiance(Light(l), w, kWl);
      Spectrum expected = texel_radiance(l, tx, ty);
      for (int c = 0; c < Spectrum::kChannels; ++c)
        ASSERT_NEAR(L[c], expected[c], 1e-4f * expected[c] + 1e-6f);
      // The mapping's inverse.
      EXPECT_NEAR(dot(image_light_direction(l, image_light_uv(l, w)), w), 1.0f, 1e-4f);
    }
    EXPECT_TRUE(environment_radiance(Light(PointLight{}), Vec3(0, 0, 1), kWl).is_black());
  }
}

TEST(ImageLight, SampledRadianceIntegratesToTheImageAndDensitiesAgree) {
  for (bool equal_area : {true, false}) {
    ImageInfiniteLight l = make_image_light(equal_area);
    Light light = l;
    Shape none = Sphere{};  // unused by environment lights
    Spectrum expected = integrated_radiance(l);
    LiCheck r = run_li(light, none, Vec3(0.3f, 0.1f, -0.2f), 500 + equal_area, 200000,
                       [&](const LightLiSample& s) {
                         EXPECT_TRUE(s.is_infinite);
                         Spectrum L = environment_radiance(light, s.wi, kWl);
                         EXPECT_NEAR(s.radiance[0], L[0], 1e-4f * L[0]);
                       });
    for (int c = 0; c < Spectrum::kChannels; ++c)
      expect_mean(r.est[c], expected[c], 0, equal_area ? "equal-area" : "lat-long");
    // The power the light sampler uses: the mean radiance times 4 pi, times the disk pi r^2.
    Rgb power = light_power(light, kBounds);
    double disk = M_PI * kBounds.radius * kBounds.radius;
    Rgb sum(0.0f);
    for (int y = 0; y < l.image->height; ++y)
      for (int x = 0; x < l.image->width; ++x) {
        double omega = l.equal_area ? 4 * M_PI / (l.image->width * l.image->height)
                                    : 2 * M_PI / l.image->width *
                                          (std::cos(M_PI * y / l.image->height) -
                                           std::cos(M_PI * (y + 1) / l.image->height));
        sum += l.image->texel(x, y, TexWrap::kClamp) * float(omega);
      }
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(power[c], sum[c] * l.scale * disk, 0.01 * power[c]) << c;
  }
}

// The directions light_sample_li draws follow light_pdf_li: a chi-square test over quarters of
// texels of equal solid angle (halves in u, and halves in v for the equal-area layout or in
// cos theta for the latitude-longitude one), whose expected counts are exact since the density is
// constant over each texel; the solid angles come from the layouts' geometry. Both layouts.
TEST(ImageLight, SampledDirectionsFollowThePdf) {
  for (bool equal_area : {true, false}) {
    ImageInfiniteLight l = make_image_light(equal_area);
    Light light = l;
    const TexImage& im = *l.image;
    auto row_cos = [&](int y) { return std::cos(M_PI * y / im.height); };
    const int n = 800000;
    std::vector<int> count(size_t(im.width) * im.height * 4, 0);
    Rng rng(600 + equal_area);
    for (int k = 0; k < n; ++k) {
      auto s = light_sample_li(light, nullptr, Vec3(0, 0, 0), {rng.uniform(), rng.uniform()},
                               kBounds, kWl);
      ASSERT_TRUE(s.has_value());
      Vec2 uv = image_light_uv(l, s->wi);
      auto [x, y] = texel_of(l, s->wi);
      int qu = uv.x * im.width - x >= 0.5f;
      int qv;
      if (equal_area) {
        qv = uv.y * im.height - y >= 0.5f;
      } else {
        double c = dot(s->wi, l.world_from_light.vector(Vec3(0, 0, 1)));
        qv = (c - row_cos(y)) / (row_cos(y + 1) - row_cos(y)) >= 0.5;
      }
      ++count[(size_t(y) * im.width + x) * 4 + qv * 2 + qu];
    }
    double chi2 = 0, mass = 0;
    for (int y = 0; y < im.height; ++y) {
      double omega = equal_area ? 4 * M_PI / (im.width * im.height)
                                : 2 * M_PI / im.width * (row_cos(y) - row_cos(y + 1));
      for (int x = 0; x < im.width; ++x) {
        Vec3 centre = image_light_direction(l, {(x + 0.5f) / im.width, (y + 0.5f) / im.height});
        double p = light_pdf_li(light, nullptr, Vec3(0, 0, 0), centre, {}, {}) * omega;
        mass += p;
        for (int q = 0; q < 4; ++q) {
          double e = n * p / 4, o = count[(size_t(y) * im.width + x) * 4 + q];
          chi2 += (o - e) * (o - e) / e;
        }
      }
    }
    EXPECT_NEAR(mass, 1.0, 1e-4) << equal_area;
    int dof = im.width * im.height * 4 - 1;
    // Two tests in this file at a family-wise level of 1%.
    EXPECT_GT(chi2::chi2_survival(chi2, dof), chi2::sidak_alpha(0.01, 2))
        << (equal_area ? "equal-area" : "lat-long") << ": chi2 " << chi2 << " dof " << dof;
  }
}

TEST(ImageLight, IlluminanceOfAConstantImageIsPiTimesItsLuminance) {
  for (bool equal_area : {true, false}) {
    ImageInfiniteLight l = make_image_light(equal_area);
    auto im = std::make_shared<TexImage>(*l.image);
    for (size_t i = 0; i < im->texels.size(); i += 3) {
      im->texels[i] = 0.5f;
      im->texels[i + 1] = 1.0f;
      im->texels[i + 2] = 2.0f;
    }
    l.image = im;
    // Integrated within each texel, the horizon's texels included.
    double expected = M_PI * Rgb(0.5f, 1.0f, 2.0f).luminance();
    EXPECT_NEAR(image_light_illuminance(l), expected, 1e-3 * expected) << equal_area;
  }
}

// ---------------------------------------------------------------------------------------------
// Goniometric and projection lights.

std::shared_ptr<TexImage> gradient_image(int w, int h) {
  auto im = std::make_shared<TexImage>();
  im->width = w;
  im->height = h;
  im->texels.resize(size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* t = &im->texels[(size_t(y) * w + x) * 3];
      t[0] = 0.1f + float(x) / w;
      t[1] = 0.2f + float(y) / h;
      t[2] = (x + y) % 3 == 0 ? 2.0f : 0.5f;
    }
  return im;
}

GoniometricLight make_goniometric() {
  GoniometricLight l;
  l.world_from_light =
      Transform::translate(Vec3(0.5f, 1, -1)) * Transform::rotate(30, normalize(Vec3(1, 1, 0)));
  l.intensity = light_rgb(2.0f, 1.0f, 0.5f);
  l.image = gradient_image(8, 8);
  prepare_goniometric_light(&l);
  return l;
}

ProjectionLight make_projection(int w, int h, float fov_degrees) {
  ProjectionLight l;
  l.world_from_light =
      Transform::translate(Vec3(0.5f, 1, -1)) * Transform::rotate(-20, normalize(Vec3(1, 0, 1)));
  l.image = gradient_image(w, h);
  l.scale = 1.5f;
  l.tan_half_fov = std::tan(fov_degrees * kPi / 360);
  prepare_projection_light(&l);
  return l;
}

TEST(GoniometricLight, ImageCentreFacesTheLightsY) {
  GoniometricLight l = make_goniometric();
  // pbrt-v4 swaps y and z: the centre of the image (the equal-area square's +z) is the light's +y,
  // its corners the light's -y.
  const TexImage& im = *l.image;
  auto mean = [&](int x, int y) {
    Rgb c = im.texel(x, y, TexWrap::kClamp);
    return (c[0] + c[1] + c[2]) / 3;
  };
  Vec3 up = l.world_from_light.vector(Vec3(0, 1, 0));
  float centre = goniometric_value(l, up);
  EXPECT_TRUE(centre == mean(3, 3) || centre == mean(4, 4) || centre == mean(3, 4) ||
              centre == mean(4, 3))
      << centre;
  float pole = goniometric_value(l, -up);  // one of the four corners, by the signs of x and z there
  EXPECT_TRUE(pole == mean(0, 0) || pole == mean(7, 0) || pole == mean(0, 7) || pole == mean(7, 7))
      << pole;
  // Shading toward a point: I times the value over d^2, a delta light.
  Vec3 p = l.world_from_light.point(Vec3(0.3f, 2, 0.1f));
  auto s = light_sample_li(Light(l), nullptr, p, {0.5f, 0.5f}, kBounds, kWl);
  ASSERT_TRUE(s.has_value());
  EXPECT_TRUE(s->is_delta);
  float d2 = length_squared(p - l.world_from_light.point(Vec3(0, 0, 0)));
  Spectrum I = l.intensity.sample(kWl) * goniometric_value(l, -s->wi);
  EXPECT_NEAR(s->radiance[0], I[0] / d2, 1e-5f * I[0] / d2);
}

TEST(ProjectionLight, FrameOrientationAndInverse) {
  ProjectionLight l = make_projection(8, 4, 60);  // wider than high: fov on the height
  const float t = std::tan(kPi / 6);
  auto at = [&](Vec3 d_light) { return projection_uv(l, l.world_from_light.vector(d_light)); };
  // The centre; up (+y) is the image's top rows, +x its right columns.
  auto c = at(Vec3(0, 0, 1));
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->x, 0.5f, 1e-5f);
  EXPECT_NEAR(c->y, 0.5f, 1e-5f);
  EXPECT_LT(at(Vec3(0, 0.2f, 1))->y, 0.5f);
  EXPECT_GT(at(Vec3(0.2f, 0, 1))->x, 0.5f);
  // The frame: +-tan(fov / 2) vertically, twice that horizontally; nothing behind.
  EXPECT_TRUE(at(Vec3(0, 0.99f * t, 1)).has_value());
  EXPECT_FALSE(at(Vec3(0, 1.01f * t, 1)).has_value());
  EXPECT_TRUE(at(Vec3(1.98f * t, 0, 1)).has_value());
  EXPECT_FALSE(at(Vec3(2.02f * t, 0, 1)).has_value());
  EXPECT_FALSE(at(Vec3(0, 0, -1)).has_value());
  Rng rng(8);
  for (int k = 0; k < 1000; ++k) {
    Vec2 uv(rng.uniform(), rng.uniform());
    Vec3 w = l.world_from_light.vector(projection_direction_light(l, uv));
    auto back = projection_uv(l, w);
    ASSERT_TRUE(back.has_value());
    EXPECT_NEAR(back->x, uv.x, 1e-4f);
    EXPECT_NEAR(back->y, uv.y, 1e-4f);
  }
}

// The solid angle of the projected frame, integrated from the per-area factor, against the
// closed form for a rectangle at unit distance: 4 atan(a b / sqrt(1 + a^2 + b^2)).
TEST(ProjectionLight, FrameSolidAngle) {
  for (float fov : {30.0f, 90.0f, 120.0f}) {
    ProjectionLight l = make_projection(6, 4, fov);
    const int n = 400;
    double omega = 0;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        omega += projection_solid_angle_per_area(l, {(i + 0.5f) / n, (j + 0.5f) / n});
    omega /= double(n) * n;
    double a = 1.5 * l.tan_half_fov, b = l.tan_half_fov;
    double expected = 4 * std::atan(a * b / std::sqrt(1 + a * a + b * b));
    EXPECT_NEAR(omega, expected, 1e-4 * expected) << fov;
  }
}

// Photons from both lights: the mean flux is the integral of the intensity over directions,
// computed here texel by texel on a fine grid of directions.
TEST(GoniometricAndProjectionLights, MeanFluxIsTheIntegratedIntensity) {
  GoniometricLight g = make_goniometric();
  ProjectionLight p = make_projection(8, 4, 70);
  Spectrum expected_g, expected_p;
  const int n = 256;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      Vec2 uv((i + 0.5f) / n, (j + 0.5f) / n);
      Vec3 w = equal_area_square_to_sphere(uv);
      expected_g += light_intensity(g, g.world_from_light.vector(Vec3(w.x, w.z, w.y)), kWl) *
                    float(4 * M_PI / (n * n));
      Vec3 wp = p.world_from_light.vector(projection_direction_light(p, uv));
      expected_p +=
          light_intensity(p, wp, kWl) * (projection_solid_angle_per_area(p, uv) / float(n * n));
    }
  // The goniometric light's power as the light sampler sees it.
  Spectrum power_g = spectral_power(Light(g));
  for (int c = 0; c < Spectrum::kChannels; ++c)
    EXPECT_NEAR(power_g[c], expected_g[c], 2e-3f * expected_g[c]);
  for (auto [light, expected, name] : {std::tuple{Light(g), expected_g, "goniometric"},
                                       std::tuple{Light(p), expected_p, "projection"}}) {
    Rng rng(77);
    MeanAccumulator est[Spectrum::kChannels];
    Vec3 origin = std::holds_alternative<GoniometricLight>(light)
                      ? g.world_from_light.point(Vec3(0, 0, 0))
                      : p.world_from_light.point(Vec3(0, 0, 0));
    for (int k = 0; k < 200000; ++k) {
      auto s = light_sample_le(light, nullptr, {rng.uniform(), rng.uniform()},
                               {rng.uniform(), rng.uniform()}, kBounds, kWl);
      for (int c = 0; c < Spectrum::kChannels; ++c) est[c].add(s ? double(s->flux[c]) : 0.0);
      if (s) {
        ASSERT_LT(length(s->origin - origin), 1e-5f);
      }
    }
    for (int c = 0; c < Spectrum::kChannels; ++c)
      expect_mean(est[c], expected[c], 2e-3 * expected[c], name);
  }
  // The projection light's RGB power, which "power" normalises, is the same integral.
  Rgb prgb = light_power(Light(p), kBounds);
  EXPECT_GT(prgb.luminance(), 0);
}

// The density of a point-like light's photon directions (point_light_pdf_le, which the combined
// estimators weigh its paths by) is the one light_sample_le draws with: each photon's flux is
// the intensity toward its direction over that density, and the density integrates to one over
// the sphere (it is zero outside a spot light's cone, beside a projection light's frame). Lights
// with an area or at infinity have none.
TEST(LightSampleLe, PointLikeLightsDensityIsTheSampledOne) {
  const GoniometricLight g = make_goniometric();
  const ProjectionLight p = make_projection(8, 4, 70);
  const SpotLight spot = make_spot();
  auto intensity = [&](const Light& l, Vec3 w) {
    if (std::holds_alternative<PointLight>(l)) return kLs;
    if (std::holds_alternative<SpotLight>(l))
      return spot.intensity.sample(kWl) * spot_falloff(spot, spot.frame.to_local(w));
    if (std::holds_alternative<GoniometricLight>(l)) return light_intensity(g, w, kWl);
    return light_intensity(p, w, kWl);
  };
  for (const auto& [light, name] :
       {std::pair{Light(PointLight{Vec3(1, 2, 3), kL}), "point"}, std::pair{Light(spot), "spot"},
        std::pair{Light(g), "goniometric"}, std::pair{Light(p), "projection"}}) {
    Rng rng(stream_key(43, std::string(name).size()));
    // A direction on a texel's edge may read the texel beside it: count the agreements.
    int photons = 0, agree = 0;
    for (int k = 0; k < 20000; ++k) {
      auto s = light_sample_le(light, nullptr, {rng.uniform(), rng.uniform()},
                               {rng.uniform(), rng.uniform()}, kBounds, kWl);
      if (!s) continue;
      const std::optional<float> pdf = point_light_pdf_le(light, s->direction);
      ASSERT_TRUE(pdf.has_value()) << name;
      ++photons;
      const Spectrum I = intensity(light, s->direction);
      agree += I[0] > 0 && std::fabs(s->flux[0] * *pdf / I[0] - 1) < 2e-3f;
    }
    EXPECT_GT(photons, 19000) << name;
    EXPECT_GE(agree, photons - photons / 1000) << name;
    MeanAccumulator total;
    for (int k = 0; k < 200000; ++k) {
      const Vec3 w = sample_uniform_sphere({rng.uniform(), rng.uniform()});
      total.add(double(*point_light_pdf_le(light, w)) / kUniformSpherePdfSolidAngle);
    }
    expect_mean(total, 1.0, 1e-6, name);
  }
  EXPECT_FALSE(point_light_pdf_le(Light(DistantLight{Vec3(0, 1, 0), kL}), Vec3(0, -1, 0)));
  EXPECT_FALSE(point_light_pdf_le(Light(UniformInfiniteLight{kL}), Vec3(0, -1, 0)));
  EXPECT_EQ(*point_light_pdf_le(Light(spot), -spot.frame.n), 0.0f);
}

// Photon emission: the mean flux weight of light_sample_le is the light's power (what the photon
// passes divide by the number of photons), and photons leave where and whither the light emits.
void check_emission(const char* name, const Light& light, const Shape* shape,
                    const std::function<void(const LightLeSample&)>& check_sample) {
  Spectrum power = spectral_power(light);
  Rng rng(stream_key(41, std::string(name).size()));
  MeanAccumulator est[Spectrum::kChannels];
  for (int k = 0; k < 200000; ++k) {
    auto s = light_sample_le(light, shape, {rng.uniform(), rng.uniform()},
                             {rng.uniform(), rng.uniform()}, kBounds, kWl);
    for (int c = 0; c < Spectrum::kChannels; ++c) est[c].add(s ? double(s->flux[c]) : 0.0);
    if (!s) continue;
    ASSERT_NEAR(length(s->direction), 1.0f, 1e-4f) << name;
    check_sample(*s);
  }
  for (int c = 0; c < Spectrum::kChannels; ++c)
    EXPECT_NEAR(est[c].mean, power[c], 4 * est[c].standard_error() + 1e-6 * power[c])
        << name << " channel " << c;
}

// The photon starts outside the bounding sphere, heading through it.
void expect_crosses_scene(const LightLeSample& s) {
  Vec3 oc = kBounds.center - s.origin;
  float along = dot(oc, s.direction);
  EXPECT_GE(length(oc), kBounds.radius * 0.999f);
  EXPECT_LE(length(oc - s.direction * along), kBounds.radius * 1.0001f);
}

TEST(LightSampleLe, MeanFluxIsPowerForPointSpotDistantAndInfiniteLights) {
  check_emission("point", Light(PointLight{Vec3(1, 2, 3), kL}), nullptr,
                 [](const LightLeSample& s) { EXPECT_EQ(length(s.origin - Vec3(1, 2, 3)), 0.0f); });
  SpotLight spot = make_spot();
  check_emission("spot", Light(spot), nullptr, [&](const LightLeSample& s) {
    EXPECT_GE(dot(s.direction, spot.frame.n), spot.cos_falloff_end - 1e-5f);
  });
  Vec3 to_light = normalize(Vec3(0.3f, 1, -0.2f));
  check_emission("distant", Light(DistantLight{to_light, kL}), nullptr,
                 [&](const LightLeSample& s) {
                   EXPECT_NEAR(dot(s.direction, to_light), -1.0f, 1e-5f);
                   expect_crosses_scene(s);
                 });
  check_emission("uniform infinite", Light(UniformInfiniteLight{kL}), nullptr,
                 expect_crosses_scene);
}

TEST(LightSampleLe, MeanFluxIsPowerForTriangleLights) {
  for (bool two_sided : {false, true}) {
    Shape tri = make_triangle();
    AreaLight l = make_area_light(tri, two_sided);
    Vec3 n = triangle_normal(std::get<TriangleMesh>(tri));
    int back = 0;
    check_emission(
        two_sided ? "triangle two-sided" : "triangle", Light(l), &tri, [&](const LightLeSample& s) {
          EXPECT_NEAR(dot(s.origin - std::get<TriangleMesh>(tri).positions[0], n), 0.0f, 1e-4f);
          if (dot(s.direction, n) < 0) ++back;
        });
    if (two_sided)
      EXPECT_NEAR(back, 100000, 1500);
    else
      EXPECT_EQ(back, 0);
  }
}

TEST(LightSampleLe, MeanFluxOfImageInfiniteLightIsItsFluxThroughTheScene) {
  for (bool equal_area : {true, false}) {
    ImageInfiniteLight im = make_image_light(equal_area);
    // The flux of an environment light through the scene's disk: its integrated radiance times
    // pi r^2 (check_emission's closed form does not apply to an image).
    Light light = im;
    Rng rng(43 + equal_area);
    MeanAccumulator est[Spectrum::kChannels];
    for (int k = 0; k < 200000; ++k) {
      auto s = light_sample_le(light, nullptr, {rng.uniform(), rng.uniform()},
                               {rng.uniform(), rng.uniform()}, kBounds, kWl);
      for (int c = 0; c < Spectrum::kChannels; ++c) est[c].add(s ? double(s->flux[c]) : 0.0);
      if (!s) continue;
      expect_crosses_scene(*s);
      // The photon travels away from the direction whose radiance it carries.
      Spectrum L = environment_radiance(light, -s->direction, kWl);
      EXPECT_GT(L[0], 0.0f);
    }
    Spectrum expected = integrated_radiance(im) * float(M_PI * kBounds.radius * kBounds.radius);
    for (int c = 0; c < Spectrum::kChannels; ++c)
      expect_mean(est[c], expected[c], 0, equal_area ? "image equal-area" : "image lat-long");
  }
}

TEST(LightSampleLe, MeanFluxOfImageAreaLightIsPiATimesMeanRadiance) {
  // An image area light: the flux is pi A times the mean texel radiance.
  Shape tri = make_triangle();
  AreaLight l = make_area_light(tri, false);
  auto im = gradient_image(4, 4);
  l.image = im;
  l.image_scale = 1.5f;
  l.image_mean = Rgb(0.0f);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) l.image_mean += im->texel(x, y, TexWrap::kClamp) / 16.0f;
  Rng rng(91);
  MeanAccumulator est[Spectrum::kChannels], radiance[Spectrum::kChannels];
  for (int k = 0; k < 200000; ++k) {
    auto s = light_sample_le(Light(l), &tri, {rng.uniform(), rng.uniform()},
                             {rng.uniform(), rng.uniform()}, kBounds, kWl);
    for (int c = 0; c < Spectrum::kChannels; ++c) est[c].add(s ? double(s->flux[c]) : 0.0);
  }
  // The mean radiance over the triangle by uniform points, against the flux over pi A.
  for (int k = 0; k < 200000; ++k) {
    float su = std::sqrt(rng.uniform()), v = rng.uniform();
    SurfacePoint sp = surface_point(tri, 0, {su * (1 - v), su * v}, {});
    Spectrum L = area_light_radiance(l, sp.ng, sp.uv, sp.ng, kWl);
    for (int c = 0; c < Spectrum::kChannels; ++c) radiance[c].add(L[c]);
  }
  for (int c = 0; c < Spectrum::kChannels; ++c) {
    double flux_over = est[c].mean / (M_PI * l.area);
    EXPECT_NEAR(flux_over, radiance[c].mean,
                4 * (est[c].standard_error() / (M_PI * l.area) + radiance[c].standard_error()));
  }
  Rgb power = light_power(Light(l), kBounds);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(power[c], l.image_mean[c] * 1.5f * kPi * l.area, 1e-4f * power[c]);
}

TEST(LightSampleLe, MeanFluxIsPowerForSphereAndCylinderLights) {
  Shape sphere = make_sphere(Vec3(1, 2, 3), 0.5f);
  check_emission("sphere", Light(make_area_light(sphere, false)), &sphere,
                 [&](const LightLeSample& s) {
                   EXPECT_NEAR(length(s.origin - Vec3(1, 2, 3)), 0.5f, 1e-4f);
                   EXPECT_GT(dot(s.direction, s.origin - Vec3(1, 2, 3)), 0.0f);
                 });
  Cylinder cyl = make_cylinder();
  Shape cyl_shape = cyl;
  check_emission("cylinder", Light(make_area_light(cyl_shape, false)), &cyl_shape,
                 [&](const LightLeSample& s) {
                   Vec3 po = cyl.world_from_object.inverse().point(s.origin);
                   EXPECT_NEAR(std::hypot(po.x, po.y), cyl.radius, 1e-4f);
                   EXPECT_GT(dot(s.direction, s.n_light), 0.0f);
                 });
}

}  // namespace
}  // namespace bpm
