// Lights as a closed set, with pbrt-v4's interface split into free functions: sample_li (a
// direction toward the light from a reference point), pdf_li (its density, for MIS), emitted
// radiance, and power (for choosing lights in proportion to their flux).
#pragma once
#include <memory>
#include <optional>
#include <variant>

#include "base/color.h"
#include "base/sampling.h"
#include "base/spectrum.h"
#include "base/vec.h"
#include "scene/shapes.h"
#include "textures/texture.h"

namespace bpm {

struct PointLight {
  Vec3 position;
  SpectrumCurve intensity;  // W/sr per nm
};

// pbrt-v4 spot light: full intensity inside cos_falloff_start, smoothstep to zero at
// cos_falloff_end.
struct SpotLight {
  Vec3 position;
  Frame frame;  // frame.n is the axis of the cone
  SpectrumCurve intensity;
  float cos_falloff_start = 1, cos_falloff_end = 1;
};

struct DistantLight {
  Vec3 direction_to_light;  // unit
  SpectrumCurve radiance;   // irradiance on a surface facing the light
};

struct UniformInfiniteLight {
  SpectrumCurve radiance;
};

// pbrt-v4 "infinite" light with an environment image. A square image is pbrt-v4's equal-area
// octahedral layout (equal_area_sphere_to_square of the direction in the light's frame); an image
// twice as wide as high is the latitude-longitude layout of pbrt-v3 (u = phi / 2 pi, v = theta / pi
// from +z, rows from the top). The radiance toward a direction is its nearest texel, read as an
// illuminant RGB, times scale; directions are sampled in proportion to texel brightness times the
// texel's solid angle, uniformly within a texel.
struct ImageInfiniteLight {
  std::shared_ptr<const TexImage> image;
  bool equal_area = true;
  Transform world_from_light;  // a rotation
  float scale = 1;
  Distribution2D distribution;  // over the image's (u, v), rows from the top
  Rgb mean_radiance;            // over directions, scale included
  // pbrt-v4's portal: the light reaches the scene only along directions w (toward the light) with
  // dot(w, n) > 0, the half of the sphere the portal faces; none: every direction.
  std::optional<Vec3> portal_normal;
};
// Builds the distribution and the mean of an image light whose image, layout, frame and scale
// are set.
void prepare_image_light(ImageInfiniteLight* l);
// The direction (world space) of image coordinates (u, v), and back.
Vec3 image_light_direction(const ImageInfiniteLight& l, Vec2 uv);
Vec2 image_light_uv(const ImageInfiniteLight& l, Vec3 w_world);
// Image coordinates drawn by the light's distribution, with their density over solid angle; and
// that density at given coordinates.
Vec2 image_light_sample(const ImageInfiniteLight& l, Vec2 u, float* pdf_solid_angle);
float image_light_pdf(const ImageInfiniteLight& l, Vec2 uv);
// The illuminance (luminance-weighted irradiance) of the light at a surface facing the light's +z,
// at scale 1: what pbrt-v4's "illuminance" parameter normalises.
double image_light_illuminance(const ImageInfiniteLight& l);

// pbrt-v4 goniometric light: a point whose intensity toward w is the spectrum I times the value
// of a square equal-area image (the mean of its channels) at the direction in the light's frame
// with y and z swapped (pbrt-v4's convention: the image's centre points along the light's +y).
struct GoniometricLight {
  Transform world_from_light;  // origin at the light; a rotation otherwise
  SpectrumCurve intensity;     // scale included
  std::shared_ptr<const TexImage> image;
  Distribution2D distribution;  // over the image, in proportion to its values
  float mean_value = 0;
};
void prepare_goniometric_light(GoniometricLight* l);
// The image value toward the world direction w (unit).
float goniometric_value(const GoniometricLight& l, Vec3 w);

// pbrt-v4 projection light: a point that projects an image along the light's +z through a
// pinhole with field of view fov on the image's shorter axis; the intensity toward a direction is
// the nearest texel, as an illuminant RGB, times scale (the image appears upright with the light's
// +y up, as pbrt-v4 shows it).
struct ProjectionLight {
  Transform world_from_light;
  std::shared_ptr<const TexImage> image;
  float scale = 1;
  float tan_half_fov = 1;
  float half_width = 1, half_height = 1;  // of the screen at unit distance, over tan_half_fov
  Distribution2D distribution;            // over the image's (u, v), in proportion to power
  Rgb power_rgb;                          // integral of the intensity over directions
};
void prepare_projection_light(ProjectionLight* l);
// Image coordinates (u, v, rows from the top) toward the world direction w, or nullopt outside
// the projected frame.
std::optional<Vec2> projection_uv(const ProjectionLight& l, Vec3 w);
// The light-space direction through image coordinates, and the solid angle per unit image area.
Vec3 projection_direction_light(const ProjectionLight& l, Vec2 uv);
float projection_solid_angle_per_area(const ProjectionLight& l, Vec2 uv);
// Intensity toward the world direction w at the wavelengths.
Spectrum light_intensity(const GoniometricLight& l, Vec3 w, const Wavelengths& wl);
Spectrum light_intensity(const ProjectionLight& l, Vec3 w, const Wavelengths& wl);

// Diffuse emission from one primitive of an object (a triangle, a full sphere or disk, or a
// cylinder).
struct AreaLight {
  int object = 0;
  int primitive = 0;
  SpectrumCurve radiance;
  bool two_sided = false;
  float area = 0;
  // pbrt-v4's image area lights ("filename"): the radiance at surface coordinates (u, v) is the
  // image bilinearly filtered at (u, 1 - v), an illuminant RGB, times image_scale.
  std::shared_ptr<const TexImage> image;
  float image_scale = 1;
  Rgb image_mean;  // mean texel, for the light's power
};

using Light = std::variant<PointLight, SpotLight, GoniometricLight, ProjectionLight, DistantLight,
                           UniformInfiniteLight, ImageInfiniteLight, AreaLight>;

struct LightLiSample {
  Spectrum radiance;          // arriving at the reference point along -wi
  Vec3 wi;                    // unit, toward the light
  Vec3 p_light;               // point on the light (for shadow rays); far away for distant lights
  Vec3 n_light;               // surface normal there (zero for lights without a surface)
  float p_light_error = 0;    // p_light's error bound (SurfacePoint::error)
  float pdf_solid_angle = 0;  // 1 for delta lights
  bool is_delta = false;
  bool is_infinite = false;
};

struct SceneBoundsInfo {
  Vec3 center;
  float radius = 1;
};

// A photon leaving a light (pbrt-v4's SampleLe): origin, direction, and the flux weight
// Le |cos| / (pdf_area * pdf_solid_angle), whose expectation over samples is light_power().
struct LightLeSample {
  Vec3 origin;
  Vec3 direction;          // unit
  Vec3 n_light;            // surface normal at the origin (zero for lights without a surface)
  float origin_error = 0;  // the origin's error bound (SurfacePoint::error)
  Spectrum flux;
};

bool light_is_delta(const Light& l);
bool light_is_infinite(const Light& l);
// Lights that a ray escaping the scene sees (uniform and image infinite lights).
bool light_is_environment(const Light& l);
// The radiance an environment light sends along -w toward the scene (w: unit, world space, the
// direction the escaping ray travels); zero for other lights.
Spectrum environment_radiance(const Light& l, Vec3 w, const Wavelengths& wl);

// The shape is needed only for area lights (pass the object's shape). `spectrum` as for
// light_sample_le.
std::optional<LightLiSample> light_sample_li(const Light& l, const Shape* shape, Vec3 p_ref, Vec2 u,
                                             const SceneBoundsInfo& bounds, const Wavelengths& wl,
                                             const Spectrum* spectrum = nullptr);
// Solid-angle density of light_sample_li choosing direction wi that reaches the light at
// p_light (area lights) or escapes (infinite lights).
float light_pdf_li(const Light& l, const Shape* shape, Vec3 p_ref, Vec3 wi, Vec3 p_light,
                   Vec3 n_light);
// Radiance leaving an area light at a point with geometric normal n and surface coordinates uv
// toward w. `spectrum`: the light's radiance spectrum at wl when the caller evaluated it ahead
// (WavelengthMaterials::light_spectrum; ignored for an image light).
Spectrum area_light_radiance(const AreaLight& l, Vec3 n, Vec2 uv, Vec3 w, const Wavelengths& wl,
                             const Spectrum* spectrum = nullptr);
// A point on a light drawn without regard to where it is seen from (equiangular sampling along a
// ray in a medium, integrator/direct_light.h): an area light's uniformly by area, a point-like
// light's own position. None for distant and infinite lights.
struct LightPoint {
  Vec3 p;
  Vec3 n;  // surface normal (zero for a point-like light)
  Vec2 uv;
  float error = 0;     // p's error bound (SurfacePoint::error)
  float pdf_area = 1;  // 1 for a point-like light (a delta)
  bool is_delta = true;
};
std::optional<LightPoint> light_sample_point(const Light& l, const Shape* shape, Vec2 u);
// Samples an emitted photon; u_pos picks the point, u_dir the direction. `spectrum`, when given,
// is an area light's (without an image) radiance spectrum at wl, evaluated once by the caller for
// many photons; other lights ignore it.
std::optional<LightLeSample> light_sample_le(const Light& l, const Shape* shape, Vec2 u_pos,
                                             Vec2 u_dir, const SceneBoundsInfo& bounds,
                                             const Wavelengths& wl,
                                             const Spectrum* spectrum = nullptr);
// The solid-angle density with which light_sample_le sends a point-like light's photon (point,
// spot, goniometric, projection) along the unit world direction w, its position being a delta;
// nullopt for lights that are not point-like.
std::optional<float> point_light_pdf_le(const Light& l, Vec3 w);
// Total emitted power as a colour (the light's RGB times its geometric factor), used by the
// power light sampler.
Rgb light_power(const Light& l, const SceneBoundsInfo& bounds);

// pbrt-v4's smoothstep falloff of spot lights.
float spot_falloff(const SpotLight& l, Vec3 w_light_local);

// Area of one primitive of a shape in world space.
float primitive_area(const Shape& shape, int prim);

}  // namespace bpm
