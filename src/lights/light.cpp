// Dispatch of the light interface (light.h) over the Light variant; the per-type functions are in
// point_lights.cpp, infinite_lights.cpp and area_light.cpp (declared in light_types.h).
#include "lights/light.h"

#include <variant>

#include "lights/light_types.h"

namespace bpm {

bool light_is_delta(const Light& l) {
  return std::visit([](const auto& x) { return kDeltaLight<std::decay_t<decltype(x)>>; }, l);
}
bool light_is_infinite(const Light& l) {
  return std::visit([](const auto& x) { return kInfiniteLight<std::decay_t<decltype(x)>>; }, l);
}
bool light_is_environment(const Light& l) {
  return std::visit([](const auto& x) { return kEnvironmentLight<std::decay_t<decltype(x)>>; }, l);
}

Spectrum environment_radiance(const Light& light, Vec3 w, const Wavelengths& wl) {
  return std::visit(
      [&](const auto& x) {
        if constexpr (kEnvironmentLight<std::decay_t<decltype(x)>>)
          return environment_radiance_of(x, w, wl);
        else
          return Spectrum();
      },
      light);
}

std::optional<LightLiSample> light_sample_li(const Light& light, const Shape* shape, Vec3 p_ref,
                                             Vec2 u, const SceneBoundsInfo& bounds,
                                             const Wavelengths& wl, const Spectrum* spectrum) {
  if (const auto* area = std::get_if<AreaLight>(&light))
    return sample_li_of(*area, shape, p_ref, u, bounds, wl, spectrum);
  return std::visit([&](const auto& x) { return sample_li_of(x, shape, p_ref, u, bounds, wl); },
                    light);
}

// Delta lights are never hit by a sampled direction.
float light_pdf_li(const Light& light, const Shape* shape, Vec3 p_ref, Vec3 wi, Vec3 p_light,
                   Vec3 n_light) {
  return std::visit(
      [&](const auto& x) {
        if constexpr (kDeltaLight<std::decay_t<decltype(x)>>)
          return 0.0f;
        else
          return pdf_li_of(x, shape, p_ref, wi, p_light, n_light);
      },
      light);
}

std::optional<LightLeSample> light_sample_le(const Light& light, const Shape* shape, Vec2 u_pos,
                                             Vec2 u_dir, const SceneBoundsInfo& bounds,
                                             const Wavelengths& wl, const Spectrum* spectrum) {
  if (const auto* area = std::get_if<AreaLight>(&light))
    return sample_le_of(*area, shape, u_pos, u_dir, bounds, wl, spectrum);
  return std::visit([&](const auto& x) { return sample_le_of(x, shape, u_pos, u_dir, bounds, wl); },
                    light);
}

std::optional<LightPoint> light_sample_point(const Light& light, const Shape* shape, Vec2 u) {
  if (const auto* area = std::get_if<AreaLight>(&light)) return sample_point_of(*area, *shape, u);
  LightPoint lp;
  if (const auto* l = std::get_if<PointLight>(&light))
    lp.p = l->position;
  else if (const auto* l = std::get_if<SpotLight>(&light))
    lp.p = l->position;
  else if (const auto* l = std::get_if<GoniometricLight>(&light))
    lp.p = l->world_from_light.point(Vec3(0, 0, 0));
  else if (const auto* l = std::get_if<ProjectionLight>(&light))
    lp.p = l->world_from_light.point(Vec3(0, 0, 0));
  else
    return std::nullopt;
  return lp;
}

Rgb light_power(const Light& light, const SceneBoundsInfo& bounds) {
  return std::visit([&](const auto& x) { return power_of(x, bounds); }, light);
}

}  // namespace bpm
