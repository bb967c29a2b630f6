#include "render/checkpoint.h"

#include <cstdio>
#include <fstream>
#include <iterator>

#include "base/bytes.h"
#include "base/error.h"
#include "film/filter.h"

namespace bpm {
namespace {

constexpr char kMagic[8] = {'B', 'P', 'M', 'C', 'K', 'P', 'T', '\n'};
// 2: bpm keeps emission statistics per pixel; 3: the film keeps the luminance and the sensors;
// 4: and the sensors' bias estimates; 7: bpm keeps its photon count and what it is chosen from;
// 9: bpm's pixel statistics keep what its continuations brought; 12: and its second moments at
// every probability of going on.
constexpr uint32_t kVersion = 12;

std::string read_file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot read \"" + path + "\"");
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// What an identity field is called in an error message.
std::string field_name(const std::string& key) {
  if (key == "scene_fingerprint") return "scene (the contents of its files)";
  if (key == "scene_stats") return "scene (objects, triangles, lights, materials)";
  if (key == "integrator_settings") return "integrator settings";
  if (key == "max_depth") return "maxdepth";
  if (key == "m_images") return "M-images (--m-images)";
  if (key == "equiangular") return "equiangular sampling (--no-equiangular)";
  return key;
}

}  // namespace

nlohmann::json render_identity(const std::vector<std::string>& scene_files, const LoadedScene& ls,
                               const RenderOptions& opt, int m_images) {
  uint64_t h = fnv1a64(nullptr, 0);
  for (const auto* files : {&scene_files, &ls.data_files})
    for (const std::string& f : *files) {
      const std::string bytes = read_file_bytes(f);
      h = fnv1a64(bytes.data(), bytes.size(), h);
    }
  char fingerprint[17];
  std::snprintf(fingerprint, sizeof fingerprint, "%016llx", (unsigned long long)h);
  // The photon methods' settings with the photons per iteration resolved for this resolution;
  // bpm's automatic count is chosen as the render goes (bpm/photon_count.h), so it differs from
  // the same starting count set by hand.
  const size_t pixels = size_t(ls.film.width) * size_t(ls.film.height);
  nlohmann::json settings;
  if (opt.integrator == "bpm") {
    BpmSettings s = opt.bpm;
    s.photons_per_iteration = photons_for(s, pixels);
    settings = settings_json(s);
    settings["photons_chosen_by_the_render"] = opt.bpm.photons_per_iteration == 0;
  }
  if (opt.integrator == "fpm") {
    FpmSettings s = opt.fpm;
    s.photons_per_iteration = photons_for(s, pixels);
    s.radius_policy = fpm_radius_policy(s.radius_policy);
    settings = settings_json(s);
  }
  return {{"scene", scene_files.empty() ? "" : scene_files.front()},
          {"scene_fingerprint", fingerprint},
          {"scene_stats",
           {ls.scene.objects.size(), ls.scene.triangle_count(), ls.scene.lights.size(),
            ls.scene.materials.size()}},
          {"resolution", std::to_string(ls.film.width) + "x" + std::to_string(ls.film.height)},
          {"integrator", opt.integrator},
          {"integrator_settings", settings},
          {"seed", opt.seed},
          {"max_depth", opt.max_depth},
          {"equiangular", opt.equiangular},
          {"filter", Filter(ls.filter).name()},
          {"filter_radius", {ls.filter.radius.x, ls.filter.radius.y}},
          {"adaptive", opt.adaptive},
          {"adaptive_floor", opt.adaptive_floor},
          {"m_images", m_images}};
}

std::vector<uint8_t> encode_checkpoint(const nlohmann::json& identity, const Film& film,
                                       const RenderState& state) {
  const std::string id = identity.dump();
  ByteWriter w;
  w.reserve(film.bytes() + id.size() + state.control.size() + state.integrator.size() + 4096);
  for (char ch : kMagic) w.put(ch);
  w.put(kVersion);
  w.put_vector(std::vector<char>(id.begin(), id.end()));
  // The film's bytes as one vector (its length first), written in place.
  w.put(uint64_t(0));
  const size_t film_at = w.bytes().size();
  film.save(w);
  w.patch(film_at - sizeof(uint64_t), uint64_t(w.bytes().size() - film_at));
  w.put(int32_t(state.passes));
  w.put_vector(state.control);
  w.put_vector(state.integrator);
  w.put(fnv1a64(w.bytes().data(), w.bytes().size()));
  return w.take();
}

Checkpoint read_checkpoint(const std::string& path) {
  const std::string bytes = read_file_bytes(path);
  const std::string what = "checkpoint \"" + path + "\"";
  if (bytes.size() < sizeof kMagic || bytes.compare(0, sizeof kMagic, kMagic, sizeof kMagic) != 0)
    throw Error(what + " is not a bpm checkpoint");
  if (bytes.size() < sizeof kMagic + sizeof(uint32_t) + sizeof(uint64_t))
    throw Error(what + " is truncated or corrupt");
  const auto* data = reinterpret_cast<const uint8_t*>(bytes.data());
  const size_t body = bytes.size() - sizeof(uint64_t);
  uint64_t sum;
  std::memcpy(&sum, data + body, sizeof sum);
  ByteReader r(data + sizeof kMagic, body - sizeof kMagic, what);
  const uint32_t version = r.get<uint32_t>();
  if (version != kVersion)
    throw Error(what + " has format version " + std::to_string(version) + "; this bpm reads " +
                std::to_string(kVersion));
  if (sum != fnv1a64(data, body)) throw Error(what + " is truncated or corrupt (checksum)");
  Checkpoint c;
  const std::vector<char> id = r.get_vector<char>();
  c.identity = nlohmann::json::parse(id.begin(), id.end(), nullptr, false);
  if (c.identity.is_discarded() || !c.identity.is_object())
    throw Error(what + " is corrupt (identity)");
  c.film = r.get_vector<uint8_t>();
  c.state.passes = r.get<int32_t>();
  c.state.control = r.get_vector<uint8_t>();
  c.state.integrator = r.get_vector<uint8_t>();
  if (!r.at_end() || c.state.passes < 0) throw Error(what + " is corrupt");
  return c;
}

void check_identity(const nlohmann::json& saved, const nlohmann::json& current,
                    const std::string& path) {
  std::string diffs;
  for (const auto& [key, value] : current.items()) {
    if (key == "scene") continue;  // the files' contents decide, not where they lie
    const nlohmann::json was = saved.contains(key) ? saved[key] : nlohmann::json();
    if (was == value) continue;
    auto say = [&](const std::string& name, const nlohmann::json& a, const nlohmann::json& b) {
      diffs += "\n  " + name + ": " + (a.is_null() ? "none" : a.dump()) + " in the checkpoint, " +
               (b.is_null() ? "none" : b.dump()) + " in this render";
    };
    if (key == "integrator_settings" && was.is_object() && value.is_object() &&
        saved.value("integrator", "") == current.value("integrator", "")) {
      for (const auto& [k, v] : value.items())
        if (!was.contains(k) || was[k] != v) say(k, was.contains(k) ? was[k] : nlohmann::json(), v);
      continue;
    }
    if (key == "integrator_settings") continue;  // another integrator: said once, above or below
    say(field_name(key), was, value);
  }
  if (diffs.empty()) return;
  throw Error("checkpoint \"" + path + "\" (of " + saved.value("scene", std::string("?")) +
              ") does not match this render:" + diffs);
}

}  // namespace bpm
