// What a bpm render reports: rays and backward
// photons of the eye pass with the paper's Table 1 measures, bytes of maps, trees and entries,
// photons, queries and batches of the light pass, and time per stage.
#pragma once
#include <nlohmann/json.hpp>

#include "bpm/backward_maps.h"
#include "bpm/eye_pass.h"
#include "bpm/light_pass.h"
#include "bpm/settings.h"

namespace bpm {

struct BpmTotals {
  EyeCounters eye;
  LightCounters light;
  size_t peak_photon_bytes = 0, peak_tree_bytes = 0, peak_entry_bytes = 0;
  double eye_s = 0, build_s = 0, light_trace_s = 0, light_gather_s = 0, light_apply_s = 0,
         probe_s = 0, accumulate_s = 0;
  uint64_t batches = 0;
  // Photons kept in the estimates (N of eq. 2 summed over iterations; a cut pass traces a few it
  // does not keep), and the iterations whose light pass a stop request cut short.
  uint64_t emitted = 0;
  int iterations_cut = 0;
  double coverage_sum = 0, last_coverage = 0;
  double duplication_sum = 0;
  int duplication_n = 0;
  double guide_moved = 0;  // share of photons the emission guide moved, at the end
  // The photon count of the last iterations, the light pass's share of an iteration's variance
  // and the balance N* (bpm/photon_count.h; a fixed count does not follow it).
  int photons_last = 0;
  // With --estimators auto: the mean over the pixels of their probability of going on from a last
  // vertex that is not glossy (EyePixels::continue_level; -1 otherwise).
  double continue_probability = -1;
  // With --radius-policy perpixel: the means of the small and the other discs' radius scales at
  // the last iteration with the shares of the render's end (DiscScales) over the pixels whose discs
  // of the kind received photons (-1 where none did, or under another policy), beside the shared
  // schedule's.
  double small_scale_mean = -1, large_scale_mean = -1, shared_scale = -1;
  double photon_share = -1, photons_best = 0, variance = 0, photon_variance = 0;
  // Whether caustic photons were joined to the camera (camera_connections.h): the setting, where
  // the camera and the scene allow it.
  bool camera_connections = false;
  // Whether photons' vertices were joined to eye vertices (vertex_connections.h).
  bool vertex_connections = false;

  // Sizes of one iteration's maps and, for sphere trees, how often a sphere is stored.
  void add_maps(const BackwardMaps& maps);
  // The stage times of every light pass run, and the rest of the passes kept in the image.
  void add_light_pass_time(const LightPassResult& r);
  void add_light_pass(const LightPassResult& r);
};

nlohmann::json to_json(const BpmTotals& t, const BpmSettings& s, int iterations, size_t pixels);

}  // namespace bpm
