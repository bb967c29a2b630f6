#include "bpm/statistics.h"

#include <algorithm>

namespace bpm {

void BpmTotals::add_maps(const BackwardMaps& maps) {
  peak_photon_bytes = std::max(peak_photon_bytes, maps.photon_bytes());
  peak_tree_bytes = std::max(peak_tree_bytes, maps.tree_bytes());
  if (maps.centre_tree) return;
  size_t in = 0, stored = 0;
  for (size_t o = 0; o + 1 < maps.object_begin.size(); ++o) {
    in += maps.object_begin[o + 1] - maps.object_begin[o];
    stored +=
        maps.sphere_trees[2 * o].reference_count() + maps.sphere_trees[2 * o + 1].reference_count();
  }
  if (in) {
    duplication_sum += double(stored) / double(in);
    ++duplication_n;
  }
}

void BpmTotals::add_light_pass_time(const LightPassResult& r) {
  light_trace_s += r.trace_s;
  light_gather_s += r.gather_s;
  light_apply_s += r.apply_s;
}

void BpmTotals::add_light_pass(const LightPassResult& r) {
  batches += uint64_t(r.batches);
  peak_entry_bytes = std::max(peak_entry_bytes, r.peak_entry_bytes);
  coverage_sum += r.coverage;
  emitted += r.emitted;
  if (r.cut) ++iterations_cut;
  last_coverage = r.coverage;
}

namespace {

double ratio(double a, double b) { return b > 0 ? a / b : 0.0; }

nlohmann::json eye_json(const BpmTotals& t, int iterations, size_t pixels) {
  uint64_t backward_rays = t.eye.rays.camera_rays + t.eye.rays.bounce_rays;
  double backward_photons = double(t.eye.backward_photons);
  return {
      {"camera_rays", t.eye.rays.camera_rays},
      {"bounce_rays", t.eye.rays.bounce_rays},
      {"shadow_rays", t.eye.rays.shadow_rays},
      {"probe_rays", t.eye.rays.probe_rays},
      // The extra camera samples of emission (EyePixels::emission_samples) and their rays
      // (counted among the camera, bounce and shadow rays).
      {"emission_samples", t.eye.emission_samples},
      {"emission_sample_rays", t.eye.emission_rays},
      // The samples of direct light beyond the first at last vertices
      // (EyePixels::direct_samples) and their rays (among the bounce and shadow rays).
      {"direct_samples", t.eye.direct_samples},
      {"direct_sample_rays", t.eye.direct_rays},
      // Eye paths that went on past their last diffuse vertex (--estimators combined) and
      // their rays (among the bounce and shadow rays).
      {"continued_paths", t.eye.continued},
      {"continuation_rays", t.eye.continuation_rays},
      // The vertices with traced lobes only (glass, mirrors) that continuations went through.
      {"continued_traced_vertices", t.eye.continued_traced},
      // The points in media where they scattered.
      {"continued_medium_vertices", t.eye.continued_in_media},
      // Their rays and shadow rays (with light to count) that got across a scattering medium.
      {"continued_through_media", t.eye.continued_through_media},
      {"continue_probability_mean", t.continue_probability},
      {"radius_scale_mean",
       {{"small", t.small_scale_mean}, {"large", t.large_scale_mean}, {"shared", t.shared_scale}}},
      {"backward_photons", t.eye.backward_photons},
      // The paper's Table 1 counts per ray traced from the camera with all its continuations
      // (an eye path); per segment counts every camera and bounce ray.
      {"backward_photons_per_backward_ray",
       ratio(backward_photons, double(t.eye.rays.camera_rays))},
      {"backward_photons_per_backward_segment", ratio(backward_photons, double(backward_rays))},
      {"backward_photons_per_pixel_iteration",
       ratio(backward_photons, double(iterations) * double(pixels))},
      // The probes run after the light pass (disc_shares.h): their time with the eye pass's.
      {"rays_per_second", ratio(double(t.eye.rays.total()), t.eye_s + t.probe_s)}};
}

nlohmann::json light_json(const BpmTotals& t, int iterations) {
  double light_s = t.light_trace_s + t.light_gather_s + t.light_apply_s;
  return {
      {"photons", t.light.photons},
      {"photons_kept", t.emitted},
      {"iterations_cut", t.iterations_cut},
      {"light_rays", t.light.light_rays},
      {"diffuse_hits", t.light.diffuse_hits},
      {"queries", t.light.queries},
      // A query descends to its leaf while the photon is traced, and is answered in the gather.
      {"queries_per_second", ratio(double(t.light.queries), t.light_trace_s + t.light_gather_s)},
      {"entries", t.light.entries},
      {"beams", t.light.beams},
      {"cut_off_rays", t.light.cut_off_rays},
      {"camera_connections", t.camera_connections},
      {"camera_rays", t.light.camera_rays},
      {"camera_hits", t.light.camera_hits},
      {"vertex_connections", t.vertex_connections},
      {"vertex_rays", t.light.vertex_rays},
      {"vertex_hits", t.light.vertex_hits},
      {"photons_per_iteration_last", t.photons_last},
      // bpm/photon_count.h: the relative variance of an iteration and of its light pass alone
      // (means over pixels), the light pass's share, and the balanced photon count N*.
      {"iteration_variance", t.variance},
      {"photon_variance", t.photon_variance},
      {"photon_variance_share", t.photon_share},
      {"photons_balance", t.photons_best},
      {"batches", t.batches},
      {"batches_per_iteration", ratio(double(t.batches), iterations)},
      {"coverage_mean", ratio(t.coverage_sum, iterations)},
      {"coverage_last", t.last_coverage},
      {"guide_moved", t.guide_moved},
      {"rays_per_second", ratio(double(t.light.light_rays), light_s)}};
}

}  // namespace

nlohmann::json to_json(const BpmTotals& t, const BpmSettings& s, int iterations, size_t pixels) {
  return {
      {"settings", settings_json(s)},
      {"eye", eye_json(t, iterations, pixels)},
      {"maps",
       {{"peak_photon_bytes", t.peak_photon_bytes},
        {"peak_tree_bytes", t.peak_tree_bytes},
        {"peak_entry_bytes", t.peak_entry_bytes},
        {"backward_photon_bytes_each", sizeof(BackwardPhoton)},
        {"tree_build_s", t.build_s},
        {"mean_sphere_duplication", ratio(t.duplication_sum, t.duplication_n)}}},
      {"light", light_json(t, iterations)},
      {"stages_s",
       {{"eye", t.eye_s},
        {"tree_build", t.build_s},
        {"light_trace", t.light_trace_s},
        {"light_gather", t.light_gather_s},
        {"light_apply", t.light_apply_s},
        {"disc_probes", t.probe_s},
        {"accumulate", t.accumulate_s}}},
  };
}

}  // namespace bpm
