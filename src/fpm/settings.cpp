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

}  // namespace bpm
