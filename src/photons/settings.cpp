#include "photons/settings.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace bpm {

namespace {

// The squared progressive scales of iterations 0..last: r_(i+1)^2 = r_i^2 (i + alpha) / (i + 1),
// i counted from 1 (Knaus & Zwicker 2011, eq. 20). The products so far are kept (per thread, for
// the last alpha asked), so that a render's iterations do not each multiply from the first; the
// same products in the same order.
const std::vector<double>& squared_scales(float alpha, int last) {
  thread_local float table_alpha = -1;
  thread_local std::vector<double> r2{1.0};
  if (alpha != table_alpha) {
    table_alpha = alpha;
    r2.assign(1, 1.0);
  }
  while (int(r2.size()) <= last) {
    const int i = int(r2.size());
    r2.push_back(r2.back() * ((i + double(alpha)) / (i + 1)));
  }
  return r2;
}

}  // namespace

float radius_scale(const PhotonSettings& s, int iteration) {
  if (s.radius_policy == RadiusPolicy::kFixed) return 1;
  return float(std::sqrt(squared_scales(s.alpha, iteration)[size_t(iteration)]));
}

float radius_scale_at(const PhotonSettings& s, double t) {
  if (!(t > 0)) return 1;
  const int i = int(std::min(std::floor(t), double(1 << 30)));
  const std::vector<double>& r2 = squared_scales(s.alpha, i + 1);
  const double f = std::min(t - i, 1.0);
  return float(std::sqrt(r2[size_t(i)] + f * (r2[size_t(i) + 1] - r2[size_t(i)])));
}

int photons_for(const PhotonSettings& s, size_t pixels) {
  if (s.photons_per_iteration != 0) return s.photons_per_iteration;
  constexpr double kPerPixel = 100000.0 / (256 * 256);
  return int(std::clamp(std::round(double(pixels) * kPerPixel), 100000.0, double(1 << 30)));
}

void read_photon_settings(const SceneEntity& in, PhotonSettings* s) {
  const ParamSet& ps = in.params;
  s->k0 = ps.get_float("k0", s->k0);
  ps.require("k0", s->k0 > 0 && s->k0 < 1e4f, "must be positive", in.loc);
  s->k1 = ps.get_float("k1", s->k1);
  ps.require("k1", s->k1 > 0 && s->k1 < 1e4f, "must be positive", in.loc);
  const std::optional<RadiusPolicy> policy =
      parse_radius_policy(ps.get_string("radiuspolicy", to_string(s->radius_policy)));
  ps.require("radiuspolicy", policy.has_value(),
             "must be \"fixed\", \"progressive\" or \"perpixel\"", in.loc);
  s->radius_policy = *policy;
  s->alpha = ps.get_float("alpha", s->alpha);
  ps.require("alpha", s->alpha > 0 && s->alpha < 1, "must be in (0, 1)", in.loc);
  s->disc_probes = ps.get_bool("discprobes", s->disc_probes);
  if (ps.find_any("photonsperiteration")) {
    s->photons_per_iteration = ps.get_int("photonsperiteration", 0);
    ps.require("photonsperiteration", s->photons_per_iteration > 0, "must be positive", in.loc);
  }
}

}  // namespace bpm
