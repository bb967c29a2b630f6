#include "bpm/accumulate.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "integrator/progressive.h"
#include "photons/density.h"

namespace bpm {

void accumulate_iteration(const BackwardMaps& maps, const LightPassResult& light,
                          const EyePixels& eye, const Wavelengths& wl, float max_component_value,
                          const PhotonSettings& settings, Film* film, PixelSums* sums,
                          std::vector<double>* estimates) {
  const int w = film->width(), h = film->height();
  std::vector<Spectrum>& photon_L = sums->photon_L;
  std::vector<Spectrum>& bias = sums->bias;
  photon_L.assign(size_t(w) * size_t(h), Spectrum());
  bias.assign(size_t(w) * size_t(h), Spectrum());
  for (size_t g = 0; g < maps.photons.size(); ++g) {
    const BackwardPhoton& bp = maps.photons[g];
    if (!light.reached[g] || light.flux[g].is_black()) continue;
    // eq. (2): L = tau * sum f dPhi / (pi r^2), with dPhi = flux / N emitted.
    const float norm = float(1.0 / (kPi * double(bp.radius) * bp.radius * double(light.emitted)));
    const NestedSums nested{light.flux[g], light.flux_inner[g], light.flux_quarter[g]};
    photon_L[bp.pixel] += bp.tau * nested.all * norm;
    bias[bp.pixel] += bp.tau * radius_bias(nested, norm, settings.bias_model);
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y < r.end(); ++y)
      for (int x = 0; x < w; ++x) {
        uint32_t p = uint32_t(y) * uint32_t(w) + uint32_t(x);
        if (!eye.sampled[p]) continue;
        Spectrum L = eye.radiance[p] + photon_L[p];
        if (settings.debias)
          L -= bias[p];
        else if (bias[p].is_finite() && eye.filter_weight[p] != 0 && recordable(L))
          film->add_bias(x, y, spectrum_to_rgb(bias[p], wl));
        record_pass(film, p, L, wl, eye.filter_weight[p], max_component_value, settings.debias);
        if (estimates && L.is_finite()) {
          (*estimates)[2 * size_t(p)] += L.average();
          (*estimates)[2 * size_t(p) + 1] += 1;
        }
      }
  });
}

}  // namespace bpm
