// Distributed rendering, measured: iterations per second of `mpirun -n P bpm render ... --threads
// T` for every P x T up to the cores given, and the efficiency against one process with one
// thread (rate / (P T rate_1x1)). Prints figures; never fails.
//   scaling [--scene FILE] [--integrator bpm] [--iterations N] [--res WxH] [--cores C]
//           [--oversubscribe]
// The figure docs/MEASUREMENTS.md quotes on 2 cores is 2 processes x 1 thread against 1 process x 2
// threads. Each configuration runs the same iterations with the same seed, so every run renders
// the same image; the rate is iterations over the JSON's render seconds (start-up and writing the
// outputs left out). Rounds (integrator/control.h) of one pass at first keep the other processes
// idle for the first eight passes: longer renders share out better.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace {

struct Config {
  int processes, threads;
};

// Runs one configuration; returns iterations per second (0 when the run failed).
double run(const std::string& base, const Config& c, bool oversubscribe, int iterations,
           const std::string& out) {
  std::string cmd;
  if (c.processes > 1)
    cmd = std::string("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun ") +
          (oversubscribe ? "--oversubscribe " : "") + "-n " + std::to_string(c.processes) + " ";
  cmd += base + " --threads " + std::to_string(c.threads) + " -o " + out + " > /dev/null 2>&1";
  if (std::system(cmd.c_str()) != 0) return 0;
  std::ifstream in(std::filesystem::path(out).replace_extension(".json"));
  const nlohmann::json rec = nlohmann::json::parse(in);
  const double s = rec["stages_s"]["render"].get<double>();
  return s > 0 ? iterations / s : 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::string scene = std::string(BPM_SOURCE_DIR) + "/scenes/caustic-sphere.pbrt";
  std::string integrator = "bpm", res = "160x120";
  int iterations = 200, cores = 2;
  bool oversubscribe = false;
  for (int i = 1; i < argc; ++i) {
    auto next = [&] { return i + 1 < argc ? std::string(argv[++i]) : std::string(); };
    if (!std::strcmp(argv[i], "--scene"))
      scene = next();
    else if (!std::strcmp(argv[i], "--integrator"))
      integrator = next();
    else if (!std::strcmp(argv[i], "--iterations"))
      iterations = std::atoi(next().c_str());
    else if (!std::strcmp(argv[i], "--res"))
      res = next();
    else if (!std::strcmp(argv[i], "--cores"))
      cores = std::atoi(next().c_str());
    else if (!std::strcmp(argv[i], "--oversubscribe"))
      oversubscribe = true;
    else {
      std::fprintf(stderr,
                   "usage: scaling [--scene FILE] [--integrator I] [--iterations N] [--res WxH] "
                   "[--cores C] [--oversubscribe]\n");
      return 2;
    }
  }
  if (std::system("command -v mpirun > /dev/null 2>&1") != 0) {
    std::printf("scaling: mpirun is not installed; nothing to measure\n");
    return 0;
  }
  const std::string out_dir = std::filesystem::temp_directory_path() / "bpm_scaling";
  std::filesystem::create_directories(out_dir);
  const std::string base = std::string(BPM_BINARY) + " render " + scene + " -q --integrator " +
                           integrator + " --iterations " + std::to_string(iterations) +
                           " --resolution " + res + " --seed 1";
  std::vector<Config> configs;
  for (int p = 1; p <= cores; p *= 2)
    for (int t = 1; p * t <= cores; t *= 2) configs.push_back({p, t});
  std::printf("== %s, %s, %s, %d iterations, up to %d cores ==\n", scene.c_str(),
              integrator.c_str(), res.c_str(), iterations, cores);
  std::printf("%9s %8s %14s %11s\n", "processes", "threads", "iterations/s", "efficiency");
  double one = 0, procs = 0, threads = 0;
  for (const Config& c : configs) {
    const double rate = run(
        base, c, oversubscribe, iterations,
        out_dir + "/p" + std::to_string(c.processes) + "t" + std::to_string(c.threads) + ".exr");
    if (c.processes == 1 && c.threads == 1) one = rate;
    if (c.processes == cores && c.threads == 1) procs = rate;
    if (c.processes == 1 && c.threads == cores) threads = rate;
    std::printf("%9d %8d %14.3f %10.0f%%\n", c.processes, c.threads, rate,
                one > 0 ? 100 * rate / (one * c.processes * c.threads) : 0.0);
  }
  if (procs > 0 && threads > 0)
    std::printf("%d processes x 1 thread / 1 process x %d threads: %.2f\n", cores, cores,
                procs / threads);
  std::filesystem::remove_all(out_dir);
  return 0;
}
