// libFuzzer target: the PLY reader (ASCII and binary, any properties and faces). A bad file must
// end in bpm::Error; anything else is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "base/error.h"
#include "scene/ply.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = (std::filesystem::temp_directory_path() /
                                   ("bpm-ply-fuzz-" + std::to_string(::getpid()) + ".ply"))
                                      .string();
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(data), long(size));
  try {
    bpm::PlyMesh mesh = bpm::read_ply(path, bpm::FileLoc{});
  } catch (const bpm::Error&) {
  }
  return 0;
}
