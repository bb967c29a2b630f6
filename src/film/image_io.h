// Image files. Every writer writes to a temporary file beside the target and renames it, so a
// reader never sees a half-written image.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "film/film.h"

namespace bpm {

struct ExtraChannel {
  std::string name;
  const std::vector<float>* values;  // width * height
};

// Threads that compress an OpenEXR file's blocks (OpenEXR's own pool; 0: the calling thread
// alone, the default). The file's bytes do not depend on them.
void set_exr_threads(int threads);
// Linear float OpenEXR with R, G, B, optional extra channels and string attributes (name,
// value). Throws Error on failure.
void write_exr(const std::string& path, const Image& img,
               const std::vector<ExtraChannel>& extra = {},
               const std::vector<std::pair<std::string, std::string>>& attributes = {});
// 8-bit sRGB PNG of the image times exposure, clamped. Throws Error on failure.
void write_png(const std::string& path, const Image& img, float exposure = 1);
// 8-bit PNG of an RGB image already in display values [0,1].
void write_png_display(const std::string& path, const Image& display);
// Reads R, G, B of an OpenEXR file. Throws Error on failure.
Image read_exr(const std::string& path);
// Writes text atomically.
void write_text_atomic(const std::string& path, const std::string& text);
void write_bytes_atomic(const std::string& path, const void* data, size_t size);

// Temporary name beside path, unique per process.
std::string temporary_path(const std::string& path);

}  // namespace bpm
