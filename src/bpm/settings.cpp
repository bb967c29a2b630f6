#include "bpm/settings.h"

#include <cmath>
#include <string>

namespace bpm {

const char* to_string(ConnectionMode m) {
  switch (m) {
    case ConnectionMode::kOff:
      return "off";
    case ConnectionMode::kOn:
      return "on";
    case ConnectionMode::kAlone:
      return "alone";
  }
  return "?";
}

std::optional<ConnectionMode> parse_connection_mode(const std::string& s) {
  for (ConnectionMode m : {ConnectionMode::kOff, ConnectionMode::kOn, ConnectionMode::kAlone})
    if (s == to_string(m)) return m;
  return std::nullopt;
}

BpmSettings bpm_settings_from_file(const SceneEntity& in) {
  BpmSettings b;
  const ParamSet& ps = in.params;
  if (in.name != "bpm" && in.name != "fpm" && in.name != "sppm") return b;
  b.radius = ps.get_float("radius", b.radius);
  ps.require("radius", b.radius >= 0 && std::isfinite(b.radius), "must not be negative", in.loc);
  if (in.name == "sppm") {
    // pbrt-v4's sppm: its radius is a world-space initial radius; its photons per iteration
    // default to the pixel count (-1), ours to about 1.5 per pixel (photons_for).
    b.diffuse_depth = 0;
    const int photons = ps.get_int("photonsperiteration", -1);
    if (photons > 0) b.photons_per_iteration = photons;
    return b;
  }
  b.diffuse_depth = ps.get_int("diffusedepth", b.diffuse_depth);
  ps.require("diffusedepth", b.diffuse_depth >= 0 && b.diffuse_depth <= 3, "must be in 0..3",
             in.loc);
  read_photon_settings(in, &b);
  std::string tree = ps.get_string("tree", "spheres");
  b.centre_tree = tree == "centres";
  ps.require("tree", b.centre_tree || tree == "spheres", "must be \"spheres\" or \"centres\"",
             in.loc);
  b.guide_emission = ps.get_bool("guideemission", b.guide_emission);
  b.split_in_media = ps.get_bool("splitinmedia", b.split_in_media);
  const std::string estimators = ps.get_string("estimators", to_string(b.combine));
  ps.require("estimators", parse_combine_at(estimators).has_value(),
             "must be \"partition\", \"glossy\", \"combined\" or \"auto\"", in.loc);
  b.combine = *parse_combine_at(estimators);
  b.split_coats = ps.get_bool("splitcoats", b.split_coats);
  const std::string connections =
      ps.get_string("cameraconnections", to_string(b.camera_connections));
  ps.require("cameraconnections", parse_connection_mode(connections).has_value(),
             "must be \"on\", \"off\" or \"alone\"", in.loc);
  b.camera_connections = *parse_connection_mode(connections);
  const std::string vertex = ps.get_string("vertexconnections", to_string(b.vertex_connections));
  ps.require("vertexconnections", parse_connection_mode(vertex).has_value(),
             "must be \"on\", \"off\" or \"alone\"", in.loc);
  b.vertex_connections = *parse_connection_mode(vertex);
  b.emission_samples = ps.get_int("emissionsamples", b.emission_samples);
  ps.require("emissionsamples", b.emission_samples >= 1 && b.emission_samples <= 1024,
             "must be in 1..1024", in.loc);
  b.direct_samples = ps.get_int("directsamples", b.direct_samples);
  ps.require("directsamples", b.direct_samples >= 1 && b.direct_samples <= 1024,
             "must be in 1..1024", in.loc);
  return b;
}

nlohmann::json settings_json(const BpmSettings& s) {
  return {{"diffuse_depth", s.diffuse_depth},
          {"k0", s.k0},
          {"k1", s.k1},
          {"radius", s.radius},
          {"radius_policy", to_string(s.radius_policy)},
          {"alpha", s.alpha},
          {"photons_per_iteration", s.photons_per_iteration},
          {"normal_cos", s.normal_cos},
          {"debias", s.debias},
          {"bias_model", to_string(s.bias_model)},
          {"tree", s.centre_tree ? "centres" : "spheres"},
          {"guide_emission", s.guide_emission},
          {"disc_probes", s.disc_probes},
          {"emission_samples", s.emission_samples},
          {"direct_samples", s.direct_samples},
          {"split_in_media", s.split_in_media},
          {"estimators", to_string(s.combine)},
          {"split_coats", s.split_coats},
          {"camera_connections", to_string(s.camera_connections)},
          {"vertex_connections", to_string(s.vertex_connections)}};
}

}  // namespace bpm
