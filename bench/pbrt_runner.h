// Running pbrt-v4 beside bpm in a benchmark: where its binary is, a copy of a scene file with some
// directives replaced (the integrator, the film's resolution), and a timed run.
#pragma once
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>

#include "film/image_io.h"

namespace bpm {

// ../shared/tools/pbrt-v4/pbrt beside the source tree, or "" when it is not there.
inline std::string default_pbrt_path() {
  const std::filesystem::path p =
      std::filesystem::path(BPM_SOURCE_DIR) / ".." / "shared" / "tools" / "pbrt-v4" / "pbrt";
  return std::filesystem::exists(p) ? p.lexically_normal().string() : std::string();
}

// The lines of the scene file, with each directive's parameters (which may go on over further
// lines) kept with it: calls line(name, text) for every line, name being the directive the line
// belongs to ("" before the first).
// A line whose first non-blank character is a capital letter starts a directive (its name is the
// letters that follow); any other line (parameters, brackets, comments, blank lines) belongs to
// the directive before it. Enough for scene files that put one directive on a line.
template <class Line>
void for_each_directive_line(const std::string& path, const Line& line) {
  std::ifstream in(path);
  std::string name;
  for (std::string l; std::getline(in, l);) {
    const size_t first = l.find_first_not_of(" \t");
    if (first != std::string::npos && std::isupper(static_cast<unsigned char>(l[first]))) {
      size_t end = first;
      while (end < l.size() && std::isalpha(static_cast<unsigned char>(l[end]))) ++end;
      name = l.substr(first, end - first);
    }
    line(name, l);
  }
}

// The scene file's Film directive with its resolution set to w x h, everything else kept.
inline std::string film_at_resolution(const std::string& path, int w, int h) {
  std::string film;
  for_each_directive_line(path, [&](const std::string& name, const std::string& l) {
    if (name == "Film") film += l + "\n";
  });
  if (film.empty()) film = "Film \"rgb\"\n";
  static const std::regex resolution(
      R"re("integer\s+[xy]resolution"\s*(\[\s*[-+0-9]+\s*\]|[-+0-9]+))re");
  return std::regex_replace(film, resolution, "") + "    \"integer xresolution\" [ " +
         std::to_string(w) + " ] \"integer yresolution\" [ " + std::to_string(h) + " ]";
}

// A copy of the scene file beside it (so that relative paths still resolve), named with `tag` and
// the process id, in which each directive named in `lines` (for example "Integrator" or "Film")
// is dropped and the given text is put before WorldBegin instead. The caller removes it. Returns
// "" (and writes nothing) when the file has no WorldBegin.
inline std::string scene_copy_with(const std::string& path,
                                   const std::map<std::string, std::string>& lines,
                                   const std::string& tag) {
  std::string out;
  bool placed = false;
  for_each_directive_line(path, [&](const std::string& name, const std::string& l) {
    if (!placed && name == "WorldBegin") {
      for (const auto& [directive, replacement] : lines) out += replacement + "\n";
      placed = true;
    }
    if (!lines.count(name)) out += l + "\n";
  });
  if (!placed) return "";
  const std::string copy = (std::filesystem::path(path).parent_path() /
                            ("." + tag + "_" + std::to_string(::getpid()) + ".pbrt"))
                               .string();
  write_text_atomic(copy, out);
  return copy;
}

// Runs pbrt-v4 with `threads` threads and `spp` samples (iterations for sppm); returns its wall
// time, or a negative value when it failed (how it ended and its last output line then go to
// stderr). With `stats`, pbrt-v4's statistics (--stats) of a run that succeeded are appended to
// *stats.
inline double run_pbrt(const std::string& pbrt, const std::string& scene, int spp,
                       const std::string& out, int threads, std::string* stats = nullptr) {
  auto quoted = [](const std::string& p) { return "'" + p + "'"; };
  const std::string cmd = quoted(pbrt) + " --quiet --nthreads " + std::to_string(threads) +
                          " --seed 7 --spp " + std::to_string(spp) + " --outfile " + quoted(out) +
                          (stats ? " --stats " : " ") + quoted(scene) + " 2>&1";
  const auto t = std::chrono::steady_clock::now();
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return -1;
  char buf[4096];
  std::string output;
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) output.append(buf, n);
  const int rc = ::pclose(p);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  if (rc == 0) {
    if (stats) stats->append(output);
    return s;
  }
  // pclose gives a wait status: an exit code, or the signal that ended pbrt-v4 (9: out of memory).
  char how[64];
  if (rc == -1)
    std::snprintf(how, sizeof how, "pclose failed");
  else if (WIFEXITED(rc))
    std::snprintf(how, sizeof how, "exit %d", WEXITSTATUS(rc));
  else if (WIFSIGNALED(rc))
    std::snprintf(how, sizeof how, "signal %d", WTERMSIG(rc));
  else
    std::snprintf(how, sizeof how, "status %d", rc);
  while (!output.empty() && std::isspace(static_cast<unsigned char>(output.back())))
    output.pop_back();
  const size_t line = output.rfind('\n');
  const std::string last =
      output.empty() ? "(no output)" : output.substr(line == std::string::npos ? 0 : line + 1);
  std::fprintf(stderr, "pbrt-v4 failed (%s, %d spp, %s): %s\n", how, spp, scene.c_str(),
               last.c_str());
  return -1;
}

// The number after `label` in pbrt-v4's statistics (the last one on its line), or -1.
inline double pbrt_stat(const std::string& stats, const std::string& label) {
  const size_t at = stats.find(label);
  if (at == std::string::npos) return -1;
  const size_t end = stats.find('\n', at);
  std::istringstream line(stats.substr(at + label.size(), end - at - label.size()));
  double v = -1;
  for (std::string word; line >> word;) {
    char* rest = nullptr;
    const double x = std::strtod(word.c_str(), &rest);
    if (rest && *rest == '\0') v = x;
  }
  return v;
}

}  // namespace bpm
