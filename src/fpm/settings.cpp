#include "fpm/settings.h"

namespace bpm {

FpmSettings fpm_settings_from_file(const SceneEntity& in) {
  FpmSettings f;
  if (in.name != "fpm") return f;
  read_photon_settings(in, &f);
  f.final_gather = in.params.get_bool("finalgather", false);
  f.knn = in.params.get_int("knn", 0);
  in.params.require("knn", f.knn >= 0, "must not be negative", in.loc);
  return f;
}

nlohmann::json settings_json(const FpmSettings& s) {
  return {{"k0", s.k0},
          {"k1", s.k1},
          {"radius_policy", to_string(s.radius_policy)},
          {"alpha", s.alpha},
          {"photons_per_iteration", s.photons_per_iteration},
          {"final_gather", s.final_gather},
          {"knn", s.knn},
          {"normal_cos", s.normal_cos},
          {"disc_probes", s.disc_probes},
          {"debias", s.debias},
          {"bias_model", to_string(s.bias_model)}};
}

}  // namespace bpm
