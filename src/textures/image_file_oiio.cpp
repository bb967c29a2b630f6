// The image reader module (see image_file.h): OpenImageIO behind two C entry points, reading an
// image and drawing text. Built as libbpm_image_reader.so, not into bpmcore.
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <type_traits>

#include "textures/image_file.h"

extern "C" bool bpm_read_image_file_v1(const char* path, double max_values, bpm::ImageFile* out,
                                       std::string* error) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    *error = "cannot read image \"" + std::string(path) + "\": " + OIIO::geterror();
    return false;
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth != 1) {
    *error = "image \"" + std::string(path) + "\" has no usable pixels";
    return false;
  }
  // A header can claim any size: a huge one is refused, not allocated.
  if (double(spec.width) * spec.height * spec.nchannels > max_values) {
    *error = "image \"" + std::string(path) + "\" is too large (" + std::to_string(spec.width) +
             " x " + std::to_string(spec.height) + " x " + std::to_string(spec.nchannels) + ")";
    return false;
  }
  out->width = spec.width;
  out->height = spec.height;
  out->channels = spec.nchannels;
  out->is_float = spec.format.basetype == OIIO::TypeDesc::FLOAT ||
                  spec.format.basetype == OIIO::TypeDesc::HALF ||
                  spec.format.basetype == OIIO::TypeDesc::DOUBLE;
  out->values.resize(size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, out->values.data())) {
    *error = "cannot read image \"" + std::string(path) + "\": " + in->geterror();
    return false;
  }
  in->close();
  return true;
}

// The declaration in image_file.h must match the definition.
static_assert(std::is_same_v<decltype(bpm_read_image_file_v1), bpm::ReadImageFileFn>);

extern "C" bool bpm_draw_text_v1(float* rgb, int width, int height, int x, int y, const char* text,
                                 int size, const float* colour, int align, std::string* error) {
  // Debian's fonts-dejavu-core; else OpenImageIO's own search for a default font.
  static const char* const kFont = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
  std::error_code ec;
  const std::string font = std::filesystem::exists(kFont, ec) ? kFont : "";
  OIIO::ImageBuf buf(OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::FLOAT), rgb);
  const OIIO::ImageBufAlgo::TextAlignX x_align =
      align == 0 ? OIIO::ImageBufAlgo::TextAlignX::Left
                 : (align == 1 ? OIIO::ImageBufAlgo::TextAlignX::Center
                               : OIIO::ImageBufAlgo::TextAlignX::Right);
  if (OIIO::ImageBufAlgo::render_text(buf, x, y, text, size, font, {colour, 3}, x_align))
    return true;
  *error = buf.geterror();
  if (error->empty()) *error = "OpenImageIO could not draw text (no font found)";
  return false;
}
