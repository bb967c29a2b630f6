// Distributed rendering through the command line: `mpirun --oversubscribe -n 2 bpm render ...`
// against one process. Skipped where bpm was built without MPI or mpirun is missing.
//
// The bound: a pass is the same computation in whichever process renders it (random streams are
// keyed by (seed, pass), and what the passes learn changes only at round ends, from sums rounded
// to float precision), so only the order in which the film's double sums are added differs. Every
// pixel and channel must agree within 1e-5 of its value (plus 1e-7 absolute): orders of
// magnitude above a float image's rounding from double sums, far below any change of a pass.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "film/image_io.h"
#include "test_util.h"

namespace bpm {
namespace {

namespace fs = std::filesystem;

// The scene of resume_test.cpp.
const std::string kScene = test::glass_corner_scene(32, 24);

// mpirun refuses to run as root without these (CI machines run as root). In the sanitizer build
// the processes run without LeakSanitizer: Open MPI's plugins keep memory they never free, and
// report it from modules already unloaded, where no suppression can name them.
#ifdef __SANITIZE_ADDRESS__
#define BPM_MPI_ENV "ASAN_OPTIONS=detect_leaks=0 "
#define BPM_MPI_FORWARD "-x ASAN_OPTIONS "
#else
#define BPM_MPI_ENV ""
#define BPM_MPI_FORWARD ""
#endif
const char* kMpirun =
    BPM_MPI_ENV "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun " BPM_MPI_FORWARD
                "--oversubscribe -n 2 ";

class Distributed : public ::testing::Test {
 protected:
  void SetUp() override {
#ifndef BPM_HAVE_MPI
    GTEST_SKIP() << "bpm was built without MPI";
#endif
    if (std::system("command -v mpirun > /dev/null 2>&1") != 0)
      GTEST_SKIP() << "mpirun is not installed";
    dir_ = fs::temp_directory_path() /
           ("bpm_mpi_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    scene_ = (dir_ / "s.pbrt").string();
    std::ofstream(scene_) << kScene;
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  // Runs `prefix bpm args`; returns the exit status.
  int run(const std::string& prefix, const std::string& args) {
    const std::string cmd = prefix + BPM_BINARY + std::string(" ") + args + " > " +
                            (dir_ / "out.txt").string() + " 2>&1";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  nlohmann::json record(const std::string& name) const {
    return nlohmann::json::parse(std::ifstream(dir_ / name));
  }
  fs::path dir_;
  std::string scene_;
};

void expect_same_image(const std::string& a_path, const std::string& b_path,
                       const std::string& what) {
  const Image a = read_exr(a_path), b = read_exr(b_path);
  ASSERT_EQ(a.rgb.size(), b.rgb.size()) << what;
  int off = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i)
    off += std::fabs(a.rgb[i] - b.rgb[i]) > 1e-5 * std::fabs(b.rgb[i]) + 1e-7;
  EXPECT_EQ(off, 0) << what << ": pixel channels beyond the bound";
}

TEST_F(Distributed, TwoProcessesRenderTheOneProcessImage) {
  for (auto [integrator, passes] : {std::pair{"path", "40"}, {"bpm", "30"}, {"fpm", "30"}}) {
    const std::string name(integrator), args = "render " + scene_ + " -q --integrator " + name +
                                               " --spp " + passes +
                                               " --photons 5000 --threads 1 -o ";
    ASSERT_EQ(run("", args + path(name + "_1.exr")), 0) << integrator;
    ASSERT_EQ(run(kMpirun, args + path(name + "_2.exr")), 0) << integrator;
    expect_same_image(path(name + "_2.exr"), path(name + "_1.exr"), name);
    const nlohmann::json rec = record(name + "_2.json");
    EXPECT_EQ(rec["settings"]["processes"], 2) << integrator;
    ASSERT_EQ(rec["processes"].size(), 2u) << integrator;
    // Each process rendered some of the passes. (Not asked of path: its passes here take well
    // under a millisecond, and process 0 may take a whole round before it answers the other.)
    int sum = 0;
    for (const auto& p : rec["processes"]) {
      if (name != "path") {
        EXPECT_GT(p["passes"].get<int>(), 0) << name << ": a process did nothing";
      }
      sum += p["passes"].get<int>();
    }
    EXPECT_EQ(sum, std::stoi(passes)) << integrator;
    EXPECT_EQ(rec["result"]["passes"], std::stoi(passes)) << integrator;
  }
}

// One process under mpirun is one process: the very same image, bit for bit.
TEST_F(Distributed, OneProcessUnderMpirunIsTheSameRender) {
  const std::string args =
      "render " + scene_ + " -q --integrator bpm --spp 12 --photons 5000 --threads 1 -o ";
  ASSERT_EQ(run("", args + path("plain.exr")), 0);
  ASSERT_EQ(run(BPM_MPI_ENV "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
                            "mpirun " BPM_MPI_FORWARD "-n 1 ",
                args + path("mpi1.exr")),
            0);
  EXPECT_EQ(read_exr(path("mpi1.exr")).rgb, read_exr(path("plain.exr")).rgb);
}

// A job that ends inside a round (20 passes: the round runs from 18 to 22) and is extended to 40
// by another job from its final checkpoint gives one process's 40-pass image: the final
// checkpoint keeps what every process learnt in the unfinished round, and the extending job
// counts it once.
TEST_F(Distributed, JobEndingInsideARoundExtendsExactly) {
  const std::string args = "render " + scene_ + " -q --integrator bpm --photons 5000 --threads 1 ";
  ASSERT_EQ(run("", args + "--spp 40 -o " + path("long.exr")), 0);
  ASSERT_EQ(run(kMpirun, args + "--spp 20 --write-every 1000 -o " + path("job.exr")), 0);
  ASSERT_EQ(
      run(kMpirun, args + "--spp 40 --resume " + path("job.checkpoint") + " -o " + path("job.exr")),
      0);
  EXPECT_EQ(record("job.json")["resumed"]["passes_before"], 20);
  expect_same_image(path("job.exr"), path("long.exr"), "extended job");
}

// Budgets and signals as in one process: --time ends the job with every output written
// (stop_reason "time"), and SIGTERM to mpirun reaches every process, whose passes end, and
// process 0 still writes every output (stop_reason "interrupted").
TEST_F(Distributed, TimeBudgetAndSigtermEndTheJobWithItsOutputs) {
  const std::string args = "render " + scene_ + " -q --integrator bpm --photons 5000 --threads 1 ";
  ASSERT_EQ(run(kMpirun, args + "--time 1 -o " + path("timed.exr")), 0);
  nlohmann::json rec = record("timed.json");
  EXPECT_EQ(rec["result"]["stop_reason"], "time");
  EXPECT_GT(rec["result"]["passes"].get<int>(), 0);
  EXPECT_TRUE(fs::exists(path("timed.png")));

  pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const std::string cmd = std::string("exec env ") + kMpirun + BPM_BINARY + " " + args +
                            "--spp 1000000 --write-every 0.1 -o " + path("stopped.exr") +
                            " > /dev/null 2>&1";
    execl("/bin/sh", "sh", "-c", cmd.c_str(), nullptr);
    _exit(127);
  }
  // The signal goes once the job renders (its first checkpoint is written), not after a fixed
  // time: on a loaded machine mpirun may take seconds to start its processes, and a signal
  // before they render ends them with nothing to write.
  const fs::path checkpoint = dir_ / "stopped.checkpoint";
  for (int i = 0; i < 12000 && !fs::exists(checkpoint); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  if (fs::exists(checkpoint)) std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_TRUE(fs::exists(checkpoint)) << "the job wrote no checkpoint in a minute";
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(fs::exists(path("stopped.json")));
  rec = record("stopped.json");
  EXPECT_EQ(rec["result"]["stop_reason"], "interrupted");
  EXPECT_GT(rec["result"]["passes"].get<int>(), 0);
  EXPECT_EQ(read_exr(path("stopped.exr")).width, 32);
}

// Sends SIGKILL to every process whose command line mentions `text` (mpirun may start its
// processes in groups of their own).
void kill_all_mentioning(const std::string& text) {
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(e.path() / "cmdline", std::ios::binary);
    std::string cmdline((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (cmdline.find(text) != std::string::npos && std::stoi(name) != ::getpid())
      kill(std::stoi(name), SIGKILL);
  }
}

// A whole job killed (SIGKILL to mpirun and its processes) after a checkpoint, then resumed by
// another job, ends with the image of one process never stopped.
TEST_F(Distributed, KilledJobResumesToTheSameImage) {
  const std::string args =
      "render " + scene_ + " -q --integrator bpm --spp 120 --photons 5000 --threads 1 -o ";
  ASSERT_EQ(run("", args + path("straight.exr")), 0);
  const fs::path checkpoint = dir_ / "job.checkpoint";
  pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    setpgid(0, 0);  // the job in a group of its own, to kill it whole
    const std::string cmd = std::string(kMpirun) + BPM_BINARY + " " + args + path("job.exr") +
                            " --write-every 0.1 > /dev/null 2>&1";
    execl("/bin/sh", "sh", "-c", cmd.c_str(), nullptr);
    _exit(127);
  }
  setpgid(pid, pid);
  for (int i = 0; i < 4000 && !fs::exists(checkpoint); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  kill_all_mentioning(path("job.exr"));
  kill(-pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(fs::exists(checkpoint));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the group's last writes
  ASSERT_EQ(run(kMpirun, args + path("job.exr") + " --resume " + checkpoint.string()), 0);
  const nlohmann::json rec = record("job.json");
  EXPECT_EQ(rec["result"]["passes"], 120);
  EXPECT_GT(rec["resumed"]["passes_before"].get<int>(), 0);
  EXPECT_LT(rec["resumed"]["passes_before"].get<int>(), 120) << "the job ended before the kill";
  expect_same_image(path("job.exr"), path("straight.exr"), "resumed job");
}

}  // namespace
}  // namespace bpm
