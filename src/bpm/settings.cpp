#include "bpm/settings.h"

#include <string>

namespace bpm {

BpmSettings bpm_settings_from_file(const SceneEntity& in) {
  BpmSettings b;
  if (in.name != "bpm" && in.name != "fpm") return b;
  const ParamSet& ps = in.params;
  b.diffuse_depth = ps.get_int("diffusedepth", b.diffuse_depth);
  ps.require("diffusedepth", b.diffuse_depth >= 0 && b.diffuse_depth <= 3, "must be in 0..3",
             in.loc);
  read_photon_settings(in, &b);
  std::string tree = ps.get_string("tree", "spheres");
  b.centre_tree = tree == "centres";
  ps.require("tree", b.centre_tree || tree == "spheres", "must be \"spheres\" or \"centres\"",
             in.loc);
  b.guide_emission = ps.get_bool("guideemission", b.guide_emission);
  b.emission_samples = ps.get_int("emissionsamples", b.emission_samples);
  ps.require("emissionsamples", b.emission_samples >= 1 && b.emission_samples <= 1024,
             "must be in 1..1024", in.loc);
  return b;
}

}  // namespace bpm
