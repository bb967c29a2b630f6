// The per-type halves of the light interface in light.h: each light family's file
// (point_lights.cpp, infinite_lights.cpp, area_light.cpp) defines these overloads for its light
// structs, and light.cpp dispatches to them with one std::visit per operation.
#pragma once
#include <optional>
#include <type_traits>

#include "lights/light.h"

namespace bpm {

template <class T>
constexpr bool kDeltaLight = std::is_same_v<T, PointLight> || std::is_same_v<T, SpotLight> ||
                             std::is_same_v<T, GoniometricLight> ||
                             std::is_same_v<T, ProjectionLight> || std::is_same_v<T, DistantLight>;
// Lights that a ray escaping the scene sees.
template <class T>
constexpr bool kEnvironmentLight =
    std::is_same_v<T, UniformInfiniteLight> || std::is_same_v<T, ImageInfiniteLight>;
template <class T>
constexpr bool kInfiniteLight = std::is_same_v<T, DistantLight> || kEnvironmentLight<T>;

// An image light's texel (negative values clamped) as an illuminant spectrum times scale.
inline Spectrum illuminant_texel(Rgb rgb, float scale, const Wavelengths& wl) {
  rgb = rgb.clamped_zero();
  if (rgb.max_component() == 0) return {};
  return rgb_texel_spectrum(rgb, SpectrumKind::kIlluminant, wl) * scale;
}

// ---- point_lights.cpp ----
std::optional<LightLiSample> sample_li_of(const PointLight& l, const Shape* shape, Vec3 p_ref,
                                          Vec2 u, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl);
std::optional<LightLiSample> sample_li_of(const SpotLight& l, const Shape* shape, Vec3 p_ref,
                                          Vec2 u, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl);
std::optional<LightLiSample> sample_li_of(const GoniometricLight& l, const Shape* shape, Vec3 p_ref,
                                          Vec2 u, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl);
std::optional<LightLiSample> sample_li_of(const ProjectionLight& l, const Shape* shape, Vec3 p_ref,
                                          Vec2 u, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl);
std::optional<LightLeSample> sample_le_of(const PointLight& l, const Shape* shape, Vec2 u_pos,
                                          Vec2 u_dir, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl);
std::optional<LightLeSample> sample_le_of(const SpotLight& l, const Shape* shape, Vec2 u_pos,
                                          Vec2 u_dir, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl);
std::optional<LightLeSample> sample_le_of(const GoniometricLight& l, const Shape* shape, Vec2 u_pos,
                                          Vec2 u_dir, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl);
std::optional<LightLeSample> sample_le_of(const ProjectionLight& l, const Shape* shape, Vec2 u_pos,
                                          Vec2 u_dir, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl);
Rgb power_of(const PointLight& l, const SceneBoundsInfo& bounds);
Rgb power_of(const SpotLight& l, const SceneBoundsInfo& bounds);
Rgb power_of(const GoniometricLight& l, const SceneBoundsInfo& bounds);
Rgb power_of(const ProjectionLight& l, const SceneBoundsInfo& bounds);

// ---- infinite_lights.cpp ----
std::optional<LightLiSample> sample_li_of(const DistantLight& l, const Shape* shape, Vec3 p_ref,
                                          Vec2 u, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl);
std::optional<LightLiSample> sample_li_of(const UniformInfiniteLight& l, const Shape* shape,
                                          Vec3 p_ref, Vec2 u, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl);
std::optional<LightLiSample> sample_li_of(const ImageInfiniteLight& l, const Shape* shape,
                                          Vec3 p_ref, Vec2 u, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl);
float pdf_li_of(const UniformInfiniteLight& l, const Shape* shape, Vec3 p_ref, Vec3 wi,
                Vec3 p_light, Vec3 n_light);
float pdf_li_of(const ImageInfiniteLight& l, const Shape* shape, Vec3 p_ref, Vec3 wi, Vec3 p_light,
                Vec3 n_light);
std::optional<LightLeSample> sample_le_of(const DistantLight& l, const Shape* shape, Vec2 u_pos,
                                          Vec2 u_dir, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl);
std::optional<LightLeSample> sample_le_of(const UniformInfiniteLight& l, const Shape* shape,
                                          Vec2 u_pos, Vec2 u_dir, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl);
std::optional<LightLeSample> sample_le_of(const ImageInfiniteLight& l, const Shape* shape,
                                          Vec2 u_pos, Vec2 u_dir, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl);
Rgb power_of(const DistantLight& l, const SceneBoundsInfo& bounds);
Rgb power_of(const UniformInfiniteLight& l, const SceneBoundsInfo& bounds);
Rgb power_of(const ImageInfiniteLight& l, const SceneBoundsInfo& bounds);
// Radiance of the environment lights (kEnvironmentLight) along -w.
Spectrum environment_radiance_of(const UniformInfiniteLight& l, Vec3 w, const Wavelengths& wl);
Spectrum environment_radiance_of(const ImageInfiniteLight& l, Vec3 w, const Wavelengths& wl);

// ---- area_light.cpp ----
std::optional<LightLiSample> sample_li_of(const AreaLight& l, const Shape* shape, Vec3 p_ref,
                                          Vec2 u, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl,
                                          const Spectrum* spectrum = nullptr);
float pdf_li_of(const AreaLight& l, const Shape* shape, Vec3 p_ref, Vec3 wi, Vec3 p_light,
                Vec3 n_light);
std::optional<LightLeSample> sample_le_of(const AreaLight& l, const Shape* shape, Vec2 u_pos,
                                          Vec2 u_dir, const SceneBoundsInfo& bounds,
                                          const Wavelengths& wl,
                                          const Spectrum* spectrum = nullptr);
Rgb power_of(const AreaLight& l, const SceneBoundsInfo& bounds);
LightPoint sample_point_of(const AreaLight& l, const Shape& shape, Vec2 u);

}  // namespace bpm
