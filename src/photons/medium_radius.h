// The spheres of the photon methods' eye paths in scattering media (bpm's backward photons there,
// fpm's volume gathers) follow the surfaces' radius rule, k pixel footprints at the path's length,
// but never fall below k footprints at the median distance of the surfaces the camera sees. A
// point in a medium can lie next to the camera, where k footprints shrink to nothing: its sphere
// then gathers a beam or photon rarely and with the weight 1 / (pi r^2), which grows without
// bound. Over points whose density does not vanish at the camera the variance is the integral of
// 1 / d^2 there, which diverges: single pixels take the whole image's error. With the floor a
// sphere is never smaller than the backward photons on the surfaces the camera sees, the
// smallest detail the image resolves there.
#pragma once
#include <algorithm>
#include <vector>

#include "camera/camera.h"
#include "scene/render_scene.h"

namespace bpm {

// The median distance to the first surface along 16 x 16 camera rays through the image (of
// width x height pixels) that meet one; the scene's bounding radius where none does.
inline float median_surface_distance(const RenderScene& scene, const Camera& camera, int width,
                                     int height) {
  constexpr int n = 16;
  std::vector<float> d;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const CameraRay r = camera.generate_ray(
          {(float(i) + 0.5f) * float(width) / n, (float(j) + 0.5f) * float(height) / n},
          {0.5f, 0.5f});
      Hit hit;
      if (r.weight > 0 && scene.intersect(r.ray, &hit)) d.push_back(hit.t * length(r.ray.d));
    }
  if (d.empty()) return scene.bounds_info.radius;
  std::nth_element(d.begin(), d.begin() + long(d.size() / 2), d.end());
  return d[d.size() / 2];
}

}  // namespace bpm
