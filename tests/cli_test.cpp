// End-to-end tests of the bpm program: outputs, bad input, interruption.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "film/image_io.h"

namespace bpm {
namespace {

namespace fs = std::filesystem;

struct CliRun {
  int exit_code;
  std::string err;
};

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("bpm_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  CliRun run(const std::string& args) {
    std::string err = (dir_ / "stderr.txt").string();
    std::string cmd = std::string(BPM_BINARY) + " " + args + " > /dev/null 2> " + err;
    int status = std::system(cmd.c_str());
    std::ifstream in(err);
    std::stringstream ss;
    ss << in.rdbuf();
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
  }
  std::string write(const std::string& name, const std::string& text) {
    fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  // Only the input files and the captured stderr: no output, not even a temporary one.
  std::vector<std::string> outputs() const {
    std::vector<std::string> out;
    for (auto& e : fs::directory_iterator(dir_)) {
      std::string n = e.path().filename().string();
      if (n != "stderr.txt" && e.path().extension() != ".pbrt") out.push_back(n);
    }
    return out;
  }
  fs::path dir_;
};

const char* kTinyScene = R"(
LookAt 0 0 -3  0 0 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 32 "integer yresolution" 24
Sampler "independent" "integer pixelsamples" 4
WorldBegin
LightSource "point" "rgb I" [5 5 5] "point3 from" [0 2 -2]
Material "diffuse"
Shape "sphere" "float radius" 1
)";

TEST_F(Cli, RendersAllOutputs) {
  std::string scene = write("s.pbrt", kTinyScene);
  CliRun r = run("render " + scene + " -q --spp 3 --seed 5 -o " + (dir_ / "out.exr").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"out.exr", "out.png", "out.luminance.png", "out.error.png", "out.json"})
    EXPECT_TRUE(fs::exists(dir_ / f)) << f;
  Image img = read_exr((dir_ / "out.exr").string());
  EXPECT_EQ(img.width, 32);
  EXPECT_EQ(img.height, 24);
  auto rec = nlohmann::json::parse(std::ifstream(dir_ / "out.json"));
  EXPECT_EQ(rec["result"]["passes"], 3);
  EXPECT_EQ(rec["settings"]["seed"], 5);
  EXPECT_EQ(rec["result"]["stop_reason"], "samples");
  EXPECT_GT(rec["rays"]["total"].get<uint64_t>(), 32u * 24u * 3u);
}

// Sensors: the CSV with its units in the header, the picture of a grid (gone again when a later
// render of the same name has no grid), with an image and without one, by every integrator.
TEST_F(Cli, SensorOutputs) {
  std::string scene = write("s.pbrt", kTinyScene);
  const std::string grid = write("grid.txt", "grid -1 -1 -1.2  2 0 0  0 2 0  4 3\n");
  const std::string point = write("point.txt", "0 0 -1.2  0 0 -1\n");
  const std::string out = (dir_ / "out.exr").string();
  for (const char* integrator : {"path", "bpm", "fpm"}) {
    CliRun r = run("render " + scene + " -q --spp 2 --integrator " + integrator + " --sensors " +
                   grid + " -o " + out);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir_ / "out.sensors.png")) << integrator;
    std::ifstream csv(dir_ / "out.sensors.csv");
    std::string header;
    std::getline(csv, header);
    EXPECT_EQ(header,
              "x,y,z,nx,ny,nz,illuminance_lux,standard_error_lux,bias_lux,total_error_lux,passes");
    auto rec = nlohmann::json::parse(std::ifstream(dir_ / "out.json"));
    EXPECT_EQ(rec["outputs"]["sensors_png"], (dir_ / "out.sensors.png").string());
    EXPECT_EQ(rec["sensors"]["count"], 12);
  }
  CliRun r = run("render " + scene + " -q --spp 2 --integrator bpm --no-image --sensors " + point +
                 " -o " + out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.sensors.png"));
  auto rec = nlohmann::json::parse(std::ifstream(dir_ / "out.json"));
  EXPECT_EQ(rec["sensors"]["count"], 1);
  EXPECT_FALSE(rec["outputs"].contains("sensors_png"));
}

// OpenImageIO (about 250 libraries, 0.2 s at every start) is loaded only when a scene reads an
// image (textures/image_file.h): the program does not need it, and still reads image textures.
TEST_F(Cli, StartsWithoutOpenImageIOAndStillReadsImages) {
  // The dynamic loader lists the libraries the program needs, and exits (what ldd does).
  const std::string listed = (dir_ / "libraries.txt").string();
  ASSERT_EQ(std::system(
                ("LD_TRACE_LOADED_OBJECTS=1 " + std::string(BPM_BINARY) + " > " + listed).c_str()),
            0);
  std::stringstream libraries;
  libraries << std::ifstream(listed).rdbuf();
  EXPECT_NE(libraries.str().find("libembree3"), std::string::npos) << libraries.str();
  EXPECT_EQ(libraries.str().find("OpenImageIO"), std::string::npos) << libraries.str();
  // A sphere textured with a white image renders brighter than one with a black image.
  double mean[2];
  for (int white = 0; white < 2; ++white) {
    Image texture{2, 2, std::vector<float>(12, float(white)), {}};
    const std::string name = white ? "white" : "black";
    const std::string png = (dir_ / (name + ".png")).string();
    write_png(png, texture);
    const std::string plain = "Material \"diffuse\"";
    std::string scene = kTinyScene;
    scene.replace(scene.find(plain), plain.size(),
                  "Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"" + png + "\"\n" +
                      plain + " \"texture reflectance\" \"t\"");
    const std::string out = (dir_ / (name + ".exr")).string();
    CliRun r = run("render " + write("textured.pbrt", scene) + " -q -o " + out);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    Image img = read_exr(out);
    mean[white] = 0;
    for (float v : img.rgb) mean[white] += v / double(img.rgb.size());
  }
  EXPECT_EQ(mean[0], 0);
  EXPECT_GT(mean[1], 0.01);
}

TEST_F(Cli, ResolutionFlagOverridesTheFile) {
  std::string scene = write("s.pbrt", kTinyScene);
  CliRun r =
      run("render " + scene + " -q --spp 1 --resolution 20x10 -o " + (dir_ / "out.exr").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Image img = read_exr((dir_ / "out.exr").string());
  EXPECT_EQ(img.width, 20);
  EXPECT_EQ(img.height, 10);
}

TEST_F(Cli, SceneErrorNamesFileLineAndWritesNothing) {
  std::string scene = write("bad.pbrt", "WorldBegin\nShape \"sphere\" \"float radius\" [ -1 ]\n");
  CliRun r = run("render " + scene + " -q -o " + (dir_ / "out.exr").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("bad.pbrt:2:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("radius"), std::string::npos) << r.err;
  EXPECT_TRUE(outputs().empty());
}

TEST_F(Cli, TruncatedFileIsAnError) {
  std::string scene =
      write("cut.pbrt", "WorldBegin\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0");
  CliRun r = run("render " + scene + " -q -o " + (dir_ / "out.exr").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("cut.pbrt:2:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("end of file"), std::string::npos) << r.err;
  EXPECT_TRUE(outputs().empty());
}

TEST_F(Cli, MissingSceneFileIsAnError) {
  CliRun r = run("render " + (dir_ / "nope.pbrt").string() + " -q");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("nope.pbrt"), std::string::npos) << r.err;
}

TEST_F(Cli, BadFlagsAreErrors) {
  std::string scene = write("s.pbrt", kTinyScene);
  EXPECT_NE(run("render " + scene + " --spp 0").exit_code, 0);
  EXPECT_NE(run("render " + scene + " --resolution 12").exit_code, 0);
  EXPECT_NE(run("render " + scene + " --integrator magic").exit_code, 0);
  EXPECT_NE(run("render " + scene + " -o out.png").exit_code, 0);
  EXPECT_NE(run("render " + scene + " -o " + (dir_ / "no/such/dir/x.exr").string()).exit_code, 0);
  EXPECT_NE(run("frobnicate").exit_code, 0);
  // CLI11's ranges let NaN through; the floats are checked to be finite first.
  for (const char* flag : {"--time", "--k0", "--k1", "--alpha", "--accuracy", "--radius"}) {
    const auto r = run("render " + scene + " " + flag + " nan");
    EXPECT_NE(r.exit_code, 0) << flag;
    EXPECT_NE(r.err.find("finite"), std::string::npos) << flag << ": " << r.err;
  }
  EXPECT_NE(run("render " + scene + " --time inf").exit_code, 0);
  EXPECT_TRUE(outputs().empty());
}

// A render that cannot fit the memory budget stops before allocating, says what it needed, and
// writes nothing; the JSON of a render that fits records the budget.
TEST_F(Cli, MemoryBudgetIsCheckedBeforeAllocating) {
  std::string scene = write("s.pbrt", kTinyScene), out = (dir_ / "out.exr").string();
  for (const char* integrator : {"path", "bpm", "fpm"}) {
    CliRun r = run("render " + scene + " -q --integrator " + integrator +
                   " --resolution 60000x60000 --memory 512M -o " + out);
    EXPECT_EQ(r.exit_code, 1) << integrator;
    EXPECT_NE(r.err.find("memory budget of 512 MiB"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--resolution"), std::string::npos) << r.err;
  }
  CliRun big = run("render " + scene + " -q --integrator bpm --k1 3 --photons 1000 --maxdepth 3 " +
                   "--iterations 1 --memory 800M --resolution 1000x1000 -o " + out);
  EXPECT_EQ(big.exit_code, 1);
  EXPECT_NE(big.err.find("backward photons per pixel"), std::string::npos) << big.err;
  EXPECT_NE(run("render " + scene + " --memory lots -o " + out).exit_code, 0);
  EXPECT_NE(run("render " + scene + " --memory 10K -o " + out).exit_code, 0);
  EXPECT_TRUE(outputs().empty());

  CliRun ok = run("render " + scene + " -q --integrator bpm --iterations 2 --memory 64M -o " + out);
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  std::ifstream in(dir_ / "out.json");
  nlohmann::json rec = nlohmann::json::parse(in);
  EXPECT_EQ(rec["settings"]["memory_budget_bytes"].get<uint64_t>(), uint64_t(64) << 20);
}

// --bias-model reaches both photon methods and their JSON; an unknown model is refused.
TEST_F(Cli, BiasModelIsChosenAndRecorded) {
  std::string scene = write("s.pbrt", kTinyScene), out = (dir_ / "out.exr").string();
  EXPECT_NE(run("render " + scene + " --integrator bpm --bias-model r3 -o " + out).exit_code, 0);
  EXPECT_TRUE(outputs().empty());
  for (const char* integrator : {"bpm", "fpm"}) {
    CliRun r = run("render " + scene + " -q --integrator " + integrator +
                   " --iterations 2 --photons 2000 --bias-model r2+r -o " + out);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto rec = nlohmann::json::parse(std::ifstream(dir_ / "out.json"));
    EXPECT_EQ(rec[integrator]["settings"]["bias_model"], "r2+r") << integrator;
    EXPECT_TRUE(rec["result"].contains("relative_error_delta_bias")) << integrator;
  }
}

TEST_F(Cli, BpmWritesItsStatistics) {
  std::string scene = write("s.pbrt", kTinyScene);
  CliRun r = run("render " + scene +
                 " --integrator bpm --iterations 2 --photons 2000 --diffuse-depth 0 "
                 "--k1 2 --radius-policy fixed --tree centres -o " +
                 (dir_ / "out.exr").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("backward photons"), std::string::npos) << r.err;
  auto rec = nlohmann::json::parse(std::ifstream(dir_ / "out.json"));
  EXPECT_EQ(rec["settings"]["integrator"], "bpm");
  EXPECT_EQ(rec["result"]["iterations"], 2);
  const auto& b = rec["bpm"];
  EXPECT_EQ(b["settings"]["diffuse_depth"], 0);
  EXPECT_EQ(b["settings"]["k1"], 2.0);
  EXPECT_EQ(b["settings"]["radius_policy"], "fixed");
  EXPECT_EQ(b["settings"]["tree"], "centres");
  EXPECT_GT(b["eye"]["backward_photons"].get<uint64_t>(), 0u);
  EXPECT_EQ(b["light"]["photons"].get<uint64_t>(), 4000u);
  EXPECT_GT(rec["rays"]["light"].get<uint64_t>(), 0u);
  for (const char* f : {"out.exr", "out.png", "out.error.png", "out.bias.png"})
    EXPECT_TRUE(fs::exists(dir_ / f)) << f;
  // The bias estimate beside the noise: the total is at least the noise, and what --accuracy
  // bounds.
  const auto& res = rec["result"];
  EXPECT_GE(res["relative_error_delta_bias"].get<double>(), 0.0);
  EXPECT_GE(res["relative_error_delta_total"].get<double>(),
            res["relative_error_delta"].get<double>());
  EXPECT_EQ(rec["outputs"]["bias_png"], (dir_ / "out.bias.png").string());
}

TEST_F(Cli, FpmWritesItsStatistics) {
  std::string scene = write("s.pbrt", kTinyScene);
  CliRun r = run("render " + scene +
                 " --integrator fpm --iterations 2 --photons 2000 --final-gather --knn 8 -o " +
                 (dir_ / "out.exr").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("per photon path"), std::string::npos) << r.err;
  auto rec = nlohmann::json::parse(std::ifstream(dir_ / "out.json"));
  EXPECT_EQ(rec["settings"]["integrator"], "fpm");
  const auto& f = rec["fpm"];
  EXPECT_EQ(f["settings"]["final_gather"], true);
  EXPECT_EQ(f["settings"]["knn"], 8);
  EXPECT_EQ(f["light"]["photons"].get<uint64_t>(), 4000u);
  EXPECT_GT(f["light"]["photons_stored"].get<uint64_t>(), 0u);
  EXPECT_GT(f["light"]["photons_per_forward_ray"].get<double>(), 0.0);
}

TEST_F(Cli, BpmSettingsComeFromTheSceneFileAndFlagsOverrideThem) {
  std::string text = kTinyScene;
  text.replace(text.find("WorldBegin"), 0,
               "Integrator \"bpm\" \"integer diffusedepth\" 2 \"float k0\" 0.5 \"integer "
               "photonsperiteration\" 1500 \"integer emissionsamples\" 3 \"string "
               "vertexconnections\" \"on\"\n");
  std::string scene = write("s.pbrt", text);
  CliRun r = run("render " + scene + " -q --spp 1 --k0 0.75 -o " + (dir_ / "out.exr").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto rec = nlohmann::json::parse(std::ifstream(dir_ / "out.json"));
  EXPECT_EQ(rec["settings"]["integrator"], "bpm");
  EXPECT_EQ(rec["bpm"]["settings"]["diffuse_depth"], 2);
  EXPECT_EQ(rec["bpm"]["settings"]["k0"], 0.75);
  EXPECT_EQ(rec["bpm"]["settings"]["photons_per_iteration"], 1500);
  EXPECT_EQ(rec["bpm"]["settings"]["emission_samples"], 3);
  EXPECT_EQ(rec["bpm"]["settings"]["vertex_connections"], "on");
  EXPECT_EQ(rec["bpm"]["light"]["photons"].get<uint64_t>(), 1500u);
}

// A spot light whose whole cone falls on a glass sphere: the floor is lit only through the glass,
// which a path tracer cannot reach. Whatever integrator of pbrt-v4's that carries light from the
// lights' side the file names, the render is bpm's and has the caustic; the note saying so is
// printed only when the file decides, not when --integrator does.
TEST_F(Cli, FileIntegratorsThatReachCausticsRenderWithBpm) {
  auto scene_naming = [](const std::string& integrator) {
    return "LookAt 0 2.5 -3  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n"
           "Film \"rgb\" \"integer xresolution\" 24 \"integer yresolution\" 16\n"
           "Sampler \"independent\" \"integer pixelsamples\" 6\n"
           "Integrator " +
           integrator +
           "\nWorldBegin\n"
           "LightSource \"spot\" \"rgb I\" [50 50 50] \"point3 from\" [0 3 0] \"point3 to\" [0 0 "
           "0] "
           "\"float coneangle\" 12 \"float conedeltaangle\" 2\n"
           "AttributeBegin\nMaterial \"dielectric\" \"float eta\" 1.5\nTranslate 0 1 0\n"
           "Shape \"sphere\" \"float radius\" 0.5\nAttributeEnd\n"
           "Material \"diffuse\"\nShape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] "
           "\"point3 P\" [-3 0 -3  -3 0 3  3 0 3  3 0 -3]\n";
  };
  auto mean = [](const std::string& exr) {
    Image img = read_exr(exr);
    double m = 0;
    for (float v : img.rgb) m += v;
    return m / double(img.rgb.size());
  };
  const std::string out = (dir_ / "out.exr").string();
  std::string path_scene = write("path.pbrt", scene_naming("\"path\""));
  CliRun p = run("render " + path_scene + " --photons 20000 -o " + out);
  ASSERT_EQ(p.exit_code, 0) << p.err;
  const double without_caustic = mean(out);
  EXPECT_EQ(p.err.find("rendered with"), std::string::npos) << p.err;
  for (const std::string name :
       {"\"bdpt\"", "\"mlt\"", "\"lightpath\"", "\"sppm\" \"float radius\" 0.05"}) {
    std::string scene = write("s.pbrt", scene_naming(name));
    CliRun r = run("render " + scene + " --photons 20000 -o " + out);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("s.pbrt:5:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("rendered with backward photon mapping"), std::string::npos) << r.err;
    auto rec = nlohmann::json::parse(std::ifstream(dir_ / "out.json"));
    EXPECT_EQ(rec["settings"]["integrator"], "bpm") << name;
    const double with_caustic = mean(out);
    EXPECT_GT(with_caustic, 0.01) << name;
    EXPECT_GT(with_caustic, 20 * without_caustic) << name;
    if (name.find("sppm") != std::string::npos) {
      EXPECT_EQ(rec["bpm"]["settings"]["diffuse_depth"], 0);
      EXPECT_FLOAT_EQ(rec["bpm"]["settings"]["radius"].get<float>(), 0.05f);
    }
    CliRun chosen = run("render " + scene + " --integrator bpm --photons 20000 -q -o " + out);
    ASSERT_EQ(chosen.exit_code, 0) << chosen.err;
    EXPECT_EQ(chosen.err.find("rendered with"), std::string::npos) << chosen.err;
  }
}

TEST_F(Cli, BadBpmSettingsAreErrors) {
  std::string text = kTinyScene;
  text.replace(text.find("WorldBegin"), 0, "Integrator \"bpm\"\n  \"integer diffusedepth\" 5\n");
  std::string scene = write("bad.pbrt", text);
  CliRun r = run("render " + scene + " -q -o " + (dir_ / "out.exr").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("bad.pbrt:7:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("diffusedepth"), std::string::npos) << r.err;
  std::string good = write("s.pbrt", kTinyScene);
  EXPECT_NE(run("render " + good + " --integrator bpm --diffuse-depth 4").exit_code, 0);
  EXPECT_NE(run("render " + good + " --integrator bpm --k1 0").exit_code, 0);
  EXPECT_NE(run("render " + good + " --integrator bpm --radius-policy wild").exit_code, 0);
  EXPECT_NE(run("render " + good + " --integrator bpm --photons 0").exit_code, 0);
  EXPECT_NE(run("render " + good + " --integrator bpm --emission-samples 0").exit_code, 0);
  EXPECT_NE(run("render " + good + " --integrator bpm --vertex-connections maybe").exit_code, 0);
  text = kTinyScene;
  text.replace(text.find("WorldBegin"), 0,
               "Integrator \"bpm\" \"string vertexconnections\" \"sometimes\"\n");
  r = run("render " + write("bad2.pbrt", text) + " -q -o " + (dir_ / "out.exr").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("vertexconnections"), std::string::npos) << r.err;
  // The photon methods' error estimate needs whole streams of iterations in each M-image.
  r = run("render " + good + " -q --integrator fpm --m-images 3 -o " + (dir_ / "m.exr").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--m-images 3"), std::string::npos) << r.err;
  EXPECT_TRUE(outputs().empty());
}

// The progress piped into a reader that quits after its first byte (as `| head` does): the
// render goes on and writes every output.
TEST_F(Cli, AReaderThatQuitsDoesNotEndTheRender) {
  std::string scene = write("s.pbrt", kTinyScene);
  std::string cmd = std::string(BPM_BINARY) + " render " + scene + " --time 1.5 -o " +
                    (dir_ / "out.exr").string() + " 2>&1 | head -c 1 > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  for (const char* f : {"out.exr", "out.png", "out.error.png", "out.json"})
    EXPECT_TRUE(fs::exists(dir_ / f)) << f;
}

TEST_F(Cli, SigintAndSigtermStillWriteEveryOutput) {
  std::string scene = write("s.pbrt", kTinyScene);
  for (const char* integrator : {"path", "bpm", "fpm"}) {
    std::string out = (dir_ / (std::string(integrator) + ".exr")).string();
    pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      int devnull = ::open("/dev/null", 1);
      dup2(devnull, 2);
      execl(BPM_BINARY, BPM_BINARY, "render", scene.c_str(), "-q", "--integrator", integrator,
            "--spp", "10000000", "--photons", "5000", "--write-every", "0.1", "-o", out.c_str(),
            nullptr);
      _exit(127);
    }
    // The signal goes once the render has begun (its first checkpoint is written), however
    // loaded the machine.
    const fs::path checkpoint = dir_ / (std::string(integrator) + ".checkpoint");
    for (int i = 0; i < 12000 && !fs::exists(checkpoint); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    EXPECT_TRUE(fs::exists(checkpoint)) << integrator << ": no checkpoint in a minute";
    kill(pid, std::string(integrator) == "bpm" ? SIGINT : SIGTERM);  // Ctrl-C and SIGTERM alike
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFEXITED(status)) << integrator;
    EXPECT_EQ(WEXITSTATUS(status), 130) << integrator;
    ASSERT_TRUE(fs::exists(out)) << integrator;
    EXPECT_TRUE(fs::exists(dir_ / (std::string(integrator) + ".png"))) << integrator;
    Image img = read_exr(out);
    EXPECT_EQ(img.width, 32);
    auto rec = nlohmann::json::parse(std::ifstream(dir_ / (std::string(integrator) + ".json")));
    EXPECT_EQ(rec["result"]["stop_reason"], "interrupted") << integrator;
    EXPECT_GT(rec["result"]["passes"].get<int>(), 0) << integrator;
  }
}

TEST_F(Cli, WriteEveryLeavesIntermediateOutputs) {
  std::string scene = write("s.pbrt", kTinyScene);
  std::string out = (dir_ / "out.exr").string();
  pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    int devnull = ::open("/dev/null", 1);
    dup2(devnull, 2);
    execl(BPM_BINARY, BPM_BINARY, "render", scene.c_str(), "-q", "--integrator", "bpm", "--spp",
          "10000000", "--photons", "5000", "--write-every", "0.2", "-o", out.c_str(), nullptr);
    _exit(127);
  }
  for (int i = 0; i < 12000 && !(fs::exists(out) && fs::exists(dir_ / "out.json")); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_TRUE(fs::exists(out));
  auto mid = nlohmann::json::parse(std::ifstream(dir_ / "out.json"));
  EXPECT_EQ(mid["result"]["stop_reason"], "running");
  EXPECT_EQ(read_exr(out).width, 32);
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  EXPECT_EQ(WEXITSTATUS(status), 130);
  auto rec = nlohmann::json::parse(std::ifstream(dir_ / "out.json"));
  EXPECT_EQ(rec["result"]["stop_reason"], "interrupted");
  EXPECT_EQ(rec["settings"]["adaptive"], true);
}

// A render killed (SIGKILL: no chance to write anything more) after it wrote a checkpoint, then
// resumed from it with the same command line, ends with the image of a render never stopped.
TEST_F(Cli, KilledRenderResumesToTheSameImage) {
  std::string scene = write("s.pbrt", kTinyScene);
  for (auto [integrator, passes] : {std::pair{"path", "800"}, {"bpm", "250"}, {"fpm", "300"}}) {
    const std::string name(integrator), straight = (dir_ / (name + "_straight.exr")).string(),
                                        killed = (dir_ / (name + ".exr")).string();
    const std::string common =
        "render " + scene + " -q --integrator " + name + " --spp " + passes + " --photons 5000 ";
    ASSERT_EQ(run(common + "-o " + straight).exit_code, 0) << integrator;

    const fs::path checkpoint = dir_ / (name + ".checkpoint");
    pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      int devnull = ::open("/dev/null", 1);
      dup2(devnull, 2);
      execl(BPM_BINARY, BPM_BINARY, "render", scene.c_str(), "-q", "--integrator", integrator,
            "--spp", passes, "--photons", "5000", "--write-every", "0.1", "-o", killed.c_str(),
            nullptr);
      _exit(127);
    }
    for (int i = 0; i < 2000 && !fs::exists(checkpoint); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(fs::exists(checkpoint)) << integrator;

    CliRun r = run(common + "--resume " + checkpoint.string() + " -o " + killed);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto rec = nlohmann::json::parse(std::ifstream(dir_ / (name + ".json")));
    EXPECT_EQ(rec["result"]["passes"], std::stoi(passes)) << integrator;
    EXPECT_GT(rec["resumed"]["passes_before"].get<int>(), 0) << integrator;
    EXPECT_EQ(read_exr(killed).rgb, read_exr(straight).rgb) << integrator;
  }
}

// A checkpoint is refused, before anything is written, when it is of another render (naming what
// differs), cut short, or not a checkpoint at all.
TEST_F(Cli, ResumeRefusesAnotherRendersCheckpoint) {
  std::string scene = write("s.pbrt", kTinyScene), out = (dir_ / "a.exr").string();
  ASSERT_EQ(run("render " + scene +
                " -q --integrator bpm --spp 3 --photons 2000 --write-every 100 "
                "-o " +
                out)
                .exit_code,
            0);
  const std::string checkpoint = (dir_ / "a.checkpoint").string();
  ASSERT_TRUE(fs::exists(checkpoint));
  std::string other = write("other.pbrt", std::string(kTinyScene) + "Translate 0 0 1\n" +
                                              "Shape \"sphere\" \"float radius\" 0.2\n");
  const std::string b = (dir_ / "b.exr").string();
  auto refused = [&](const std::string& args, const std::string& says) {
    CliRun r = run("render " + args + " -q --spp 6 --photons 2000 -o " + b);
    EXPECT_EQ(r.exit_code, 1) << args;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(b)) << args;
  };
  refused(other + " --integrator bpm --resume " + checkpoint, "scene");
  refused(scene + " --integrator fpm --resume " + checkpoint, "integrator");
  refused(scene + " --integrator bpm --resolution 16x12 --resume " + checkpoint, "resolution");
  refused(scene + " --integrator bpm --k1 5 --resume " + checkpoint, "k1");
  {
    std::ifstream in(checkpoint, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(dir_ / "cut.checkpoint", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  refused(scene + " --integrator bpm --resume " + (dir_ / "cut.checkpoint").string(), "corrupt");
  refused(scene + " --integrator bpm --resume " + out, "not a bpm checkpoint");
  // The same render goes on.
  EXPECT_EQ(run("render " + scene + " -q --integrator bpm --spp 6 --photons 2000 --resume " +
                checkpoint + " -o " + b)
                .exit_code,
            0);
  // A count bpm chooses as it goes is another setting than its starting count fixed by hand.
  const std::string c = (dir_ / "c.exr").string();
  ASSERT_EQ(
      run("render " + scene + " -q --integrator bpm --spp 3 --write-every 100 -o " + c).exit_code,
      0);
  CliRun fixed = run("render " + scene + " -q --integrator bpm --spp 6 --photons 100000 --resume " +
                     (dir_ / "c.checkpoint").string() + " -o " + (dir_ / "d.exr").string());
  EXPECT_EQ(fixed.exit_code, 1);
  EXPECT_NE(fixed.err.find("photons_chosen_by_the_render"), std::string::npos) << fixed.err;
}

// The data a scene reads from other files (a PLY mesh, a spectrum file) is part of the render's
// identity as much as the scene file: a checkpoint is refused when one changed since.
TEST_F(Cli, ResumeRefusesACheckpointWhoseDataFilesChanged) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
      "float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n-1 -1 0\n1 "
      "-1 0\n0 1 0\n3 0 1 2\n";
  const std::string spd = "400 0.5\n700 0.5\n";
  write("m.ply", ply);
  write("grey.spd", spd);
  std::string scene = write("s.pbrt", R"(
LookAt 0 0 -3  0 0 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 16 "integer yresolution" 12
WorldBegin
LightSource "point" "rgb I" [5 5 5] "point3 from" [0 2 -2]
Material "diffuse" "spectrum reflectance" "grey.spd"
Shape "plymesh" "string filename" "m.ply"
)");
  const std::string out = (dir_ / "a.exr").string(), b = (dir_ / "b.exr").string();
  ASSERT_EQ(run("render " + scene + " -q --spp 2 --write-every 100 -o " + out).exit_code, 0);
  const std::string resume =
      "render " + scene + " -q --spp 4 --resume " + (dir_ / "a.checkpoint").string() + " -o " + b;
  const std::vector<std::pair<std::string, std::string>> changes = {
      {"m.ply", ply + "\n"}, {"grey.spd", "400 0.6\n700 0.5\n"}};
  for (const auto& [file, changed] : changes) {
    write(file, changed);
    CliRun r = run(resume);
    EXPECT_EQ(r.exit_code, 1) << file;
    EXPECT_NE(r.err.find("contents of its files"), std::string::npos) << file << ": " << r.err;
    EXPECT_FALSE(fs::exists(b)) << file;
  }
  write("m.ply", ply);
  write("grey.spd", spd);
  CliRun r = run(resume);
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST_F(Cli, AccuracyFlagStopsAtTheRequestedDelta) {
  std::string scene = write("s.pbrt", kTinyScene);
  CliRun r = run("render " + scene + " -q --accuracy 0.05 -o " + (dir_ / "out.exr").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto rec = nlohmann::json::parse(std::ifstream(dir_ / "out.json"));
  EXPECT_EQ(rec["result"]["stop_reason"], "accuracy");
  EXPECT_LE(rec["result"]["relative_error_delta"].get<double>(), 0.05);
  EXPECT_GT(rec["result"]["relative_error_delta_m_images"].get<double>(), 0.0);
  EXPECT_EQ(rec["result"]["m_images"], 8);
}

TEST_F(Cli, CompareReportsMeans) {
  std::string scene = write("s.pbrt", kTinyScene);
  std::string out = (dir_ / "out.exr").string();
  ASSERT_EQ(run("render " + scene + " -q --spp 1 -o " + out).exit_code, 0);
  CliRun r = run("compare " + out + " " + out);
  EXPECT_EQ(r.exit_code, 0);
}

}  // namespace
}  // namespace bpm
