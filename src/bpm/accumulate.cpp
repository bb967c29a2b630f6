#include "bpm/accumulate.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "integrator/progressive.h"

namespace bpm {

void accumulate_iteration(const BackwardMaps& maps, const std::vector<Spectrum>& flux,
                          const std::vector<Spectrum>& flux_inner, uint64_t emitted,
                          const EyePixels& eye, const Wavelengths& wl, float max_component_value,
                          bool debias, Film* film, std::vector<double>* estimates,
                          std::vector<uint32_t>* counts) {
  const int w = film->width(), h = film->height();
  std::vector<Spectrum> photon_L(size_t(w) * size_t(h)), bias(size_t(w) * size_t(h));
  for (size_t g = 0; g < maps.photons.size(); ++g) {
    const BackwardPhoton& bp = maps.photons[g];
    if (flux[g].is_black()) continue;
    // eq. (2): L = tau * sum f dPhi / (pi r^2), with dPhi = flux / N emitted.
    const float norm = float(1.0 / (kPi * double(bp.radius) * bp.radius * double(emitted)));
    const Spectrum L = bp.tau * flux[g] * norm, L_inner = bp.tau * flux_inner[g] * (2 * norm);
    photon_L[bp.pixel] += L;
    // The bias of a density estimate over a smooth density grows as r^2 (its leading term), so
    // L(r) - L(r / sqrt 2) is half of L(r)'s bias.
    bias[bp.pixel] += (L - L_inner) * 2.0f;
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y < r.end(); ++y)
      for (int x = 0; x < w; ++x) {
        uint32_t p = uint32_t(y) * uint32_t(w) + uint32_t(x);
        if (!eye.sampled[p]) continue;
        Spectrum L = eye.radiance[p] + photon_L[p];
        if (debias)
          L -= bias[p];
        else if (bias[p].is_finite() && eye.filter_weight[p] != 0 && recordable(L))
          film->add_bias(x, y, spectrum_to_rgb(bias[p], wl));
        record_pass(film, p, L, wl, eye.filter_weight[p], max_component_value, debias);
        if (estimates && L.is_finite()) {
          (*estimates)[p] += L.average();
          ++(*counts)[p];
        }
      }
  });
}

}  // namespace bpm
