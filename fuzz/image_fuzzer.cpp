// libFuzzer target: image textures through OpenImageIO and bpm's conversion to texels. The first
// byte of the input picks the file's extension (so OpenImageIO tries that format first), the rest
// is the file. A bad file must end in bpm::Error; anything else is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "base/error.h"
#include "textures/texture.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const char* const kExtensions[] = {"png", "tga", "exr", "pfm", "hdr", "jpg", "tif", "ppm"};
  const std::string path =
      (std::filesystem::temp_directory_path() / ("bpm-image-fuzz-" + std::to_string(::getpid()) +
                                                 "." + kExtensions[data[0] % 8]))
          .string();
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(data + 1), long(size - 1));
  try {
    for (auto kind : {bpm::TexEncoding::Kind::kSrgb, bpm::TexEncoding::Kind::kGamma})
      bpm::read_texture_image(path, bpm::TexEncoding{kind, 2.2f});
  } catch (const bpm::Error&) {
  }
  std::filesystem::remove(path);
  return 0;
}
