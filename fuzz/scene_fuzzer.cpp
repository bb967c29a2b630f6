// libFuzzer target: scene files through the parser (Include, Import) and flattening, with the
// files they name (PLY meshes, images) read from the same folder. The input is one or more files:
// the first is main.pbrt, and a line "#file NAME" starts the next one, named NAME (a plain file
// name). A bad input must end in bpm::Error; anything else (a crash, another exception, a
// sanitizer report, a leak, a hang) is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "base/color.h"
#include "base/error.h"
#include "scene/flatten.h"
#include "scene/parsed_scene.h"

namespace fs = std::filesystem;

namespace {

// A folder of this process's own, emptied for each input.
const fs::path& work_dir() {
  static const fs::path dir =
      fs::temp_directory_path() / ("bpm-scene-fuzz-" + std::to_string(::getpid()));
  return dir;
}

bool plain_name(const std::string& name) {
  return !name.empty() && name.size() < 64 && name.find('/') == std::string::npos &&
         name != "." && name != "..";
}

}  // namespace

// The table of texel spectra is built once, before the inputs, as the command line builds it while
// loading the first image (under the sanitizers it takes longer than a hang's timeout).
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  bpm::prepare_texel_spectra();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const fs::path& dir = work_dir();
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::create_directories(dir);
  const std::string input(reinterpret_cast<const char*>(data), size);
  std::string name = "main.pbrt";
  size_t start = 0;
  while (true) {
    size_t marker = input.find("\n#file ", start);
    size_t end = marker == std::string::npos ? input.size() : marker + 1;
    if (plain_name(name)) std::ofstream(dir / name, std::ios::binary) << input.substr(start, end - start);
    if (marker == std::string::npos) break;
    size_t line_end = input.find('\n', marker + 7);
    if (line_end == std::string::npos) break;
    name = input.substr(marker + 7, line_end - marker - 7);
    start = line_end + 1;
  }
  try {
    bpm::LoadedScene ls = bpm::flatten_scene(bpm::parse_scene_file((dir / "main.pbrt").string()));
  } catch (const bpm::Error&) {
  }
  return 0;
}
