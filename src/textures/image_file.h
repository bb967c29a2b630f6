// Reading image files (PNG, JPEG, TGA, EXR, PFM, HDR, TIFF, ...) and drawing text (the legends of
// false-colour pictures) through OpenImageIO.
//
// OpenImageIO brings about 250 shared libraries with it, and loading them costs every process
// about 0.2 s before main, whether it reads an image or not. So bpm does not link it: the reader
// is a small module built beside the programs (libbpm_image_reader.so, from image_file_oiio.cpp)
// and loaded the first time a scene needs an image.
#pragma once
#include <string>
#include <vector>

namespace bpm {

// An image's values as floats, width * height * channels, rows from the top.
struct ImageFile {
  int width = 0, height = 0, channels = 0;
  bool is_float = false;  // stored as half, float or double (linear) rather than integers
  std::vector<float> values;
};

// Reads the first subimage of the file. Images with more than max_values values are refused
// before anything is allocated. Throws Error naming the file when it cannot be read, and when
// the reader module cannot be found or loaded.
ImageFile read_image_file(const std::string& path, double max_values);

// The module's name, and its entry point (extern "C", so that dlsym finds it by this name). The
// entry's name carries a version: change it with ImageFile or the signature, so that a module
// left from another build is refused rather than called with the wrong layout.
inline constexpr const char* kImageReaderModule = "libbpm_image_reader.so";
using ReadImageFileFn = bool(const char* path, double max_values, ImageFile* out,
                             std::string* error);
inline constexpr const char* kImageReaderEntry = "bpm_read_image_file_v1";

// Draws one line of `text` onto an RGB float image (width * height * 3, rows from the top), its
// baseline at y, starting at x (align 0), centred on x (1) or ending at x (2), `size` pixels high,
// in `colour`, with Debian's DejaVu Sans (fonts-dejavu-core) or else OpenImageIO's default font.
// Returns false with the reason when it cannot (the module or a font missing).
bool draw_text(float* rgb, int width, int height, int x, int y, const std::string& text, int size,
               const float colour[3], int align, std::string* error);
using DrawTextFn = bool(float* rgb, int width, int height, int x, int y, const char* text, int size,
                        const float* colour, int align, std::string* error);
inline constexpr const char* kDrawTextEntry = "bpm_draw_text_v1";

}  // namespace bpm
