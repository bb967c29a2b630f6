// Tests of image files: an OpenEXR file is the same, byte for byte, whatever threads compress it,
// and reads back to the values written.
#include "film/image_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

namespace bpm {
namespace {

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(ImageIo, ExrBytesDoNotDependOnTheCompressingThreads) {
  Image img;
  img.width = 97;  // not a multiple of OpenEXR's blocks of 16 scanlines
  img.height = 131;
  img.rgb.resize(size_t(img.width) * img.height * 3);
  for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = float((i * 7919) % 1000) / 997.0f;
  std::vector<float> extra(size_t(img.width) * img.height, 0.25f);
  std::string name = "bpm_image_io_test_";
  name += std::to_string(::getpid());
  const auto dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::create_directories(dir);
  std::string bytes[2];
  for (int k = 0; k < 2; ++k) {
    set_exr_threads(k == 0 ? 0 : 4);
    const std::string path = (dir / (k == 0 ? "one_thread.exr" : "four_threads.exr")).string();
    write_exr(path, img, {{"extra", &extra}});
    bytes[k] = file_bytes(path);
    EXPECT_EQ(read_exr(path).rgb, img.rgb);
  }
  set_exr_threads(0);
  std::filesystem::remove_all(dir);
  EXPECT_FALSE(bytes[0].empty());
  EXPECT_EQ(bytes[0], bytes[1]);
}

}  // namespace
}  // namespace bpm
