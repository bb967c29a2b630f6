#include "film/image_io.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "base/error.h"

namespace bpm {

std::string temporary_path(const std::string& path) {
  return path + ".tmp" + std::to_string(::getpid());
}

namespace {

void commit_file(const std::string& tmp, const std::string& path) {
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw Error("cannot write \"" + path + "\": " + ec.message());
  }
}

uint8_t to_srgb8(float v) {
  v = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
  float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1 / 2.4f) - 0.055f;
  return uint8_t(std::lround(s * 255));
}

void write_png_bytes(const std::string& path, int w, int h, const std::vector<uint8_t>& rgb8) {
  std::string tmp = temporary_path(path);
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw Error("cannot write \"" + path + "\": cannot create " + tmp);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    std::remove(tmp.c_str());
    throw Error("cannot write PNG \"" + path + "\"");
  }
  png_init_io(png, f);
  png_set_IHDR(png, info, w, h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  // The fastest deflate: a rendered image's noise compresses little better at higher levels, and
  // a large image took seconds.
  png_set_compression_level(png, 1);
  png_write_info(png, info);
  for (int y = 0; y < h; ++y)
    png_write_row(png, const_cast<uint8_t*>(rgb8.data() + size_t(y) * w * 3));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fclose(f) != 0) {
    std::remove(tmp.c_str());
    throw Error("cannot write \"" + path + "\"");
  }
  commit_file(tmp, path);
}

}  // namespace

void set_exr_threads(int threads) { Imf::setGlobalThreadCount(std::max(threads, 0)); }

void write_exr(const std::string& path, const Image& img, const std::vector<ExtraChannel>& extra,
               const std::vector<std::pair<std::string, std::string>>& attributes) {
  std::string tmp = temporary_path(path);
  try {
    // A crop keeps its place in the full image: OpenEXR's data window within the display window.
    const DisplayWindow& w = img.window;
    const int x0 = w.width > 0 ? w.x0 : 0, y0 = w.width > 0 ? w.y0 : 0;
    const Imath::Box2i display(Imath::V2i(0, 0), w.width > 0
                                                     ? Imath::V2i(w.width - 1, w.height - 1)
                                                     : Imath::V2i(img.width - 1, img.height - 1));
    const Imath::Box2i data(Imath::V2i(x0, y0),
                            Imath::V2i(x0 + img.width - 1, y0 + img.height - 1));
    Imf::Header header(display, data);
    header.compression() = Imf::ZIP_COMPRESSION;
    header.zipCompressionLevel() = 1;  // the fastest deflate: float noise compresses little more
    for (const auto& [name, value] : attributes) header.insert(name, Imf::StringAttribute(value));
    const char* names[3] = {"R", "G", "B"};
    for (const char* n : names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
    for (const ExtraChannel& e : extra) header.channels().insert(e.name, Imf::Channel(Imf::FLOAT));
    Imf::FrameBuffer fb;
    // Slices address pixel (x, y) of the data window from (0, 0).
    const ptrdiff_t origin = ptrdiff_t(x0) + ptrdiff_t(y0) * img.width;
    for (int c = 0; c < 3; ++c)
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)(img.rgb.data() + c - 3 * origin),
                                     3 * sizeof(float), 3 * sizeof(float) * img.width));
    for (const ExtraChannel& e : extra)
      fb.insert(e.name, Imf::Slice(Imf::FLOAT, (char*)(e.values->data() - origin), sizeof(float),
                                   sizeof(float) * img.width));
    Imf::OutputFile file(tmp.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(img.height);
  } catch (const std::exception& e) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw Error("cannot write \"" + path + "\": " + e.what());
  }
  commit_file(tmp, path);
}

void write_png(const std::string& path, const Image& img, float exposure) {
  std::vector<uint8_t> rgb8(img.rgb.size());
  for (size_t i = 0; i < img.rgb.size(); ++i) rgb8[i] = to_srgb8(img.rgb[i] * exposure);
  write_png_bytes(path, img.width, img.height, rgb8);
}

void write_png_display(const std::string& path, const Image& display) {
  std::vector<uint8_t> rgb8(display.rgb.size());
  for (size_t i = 0; i < display.rgb.size(); ++i)
    rgb8[i] = uint8_t(std::lround(std::clamp(display.rgb[i], 0.0f, 1.0f) * 255));
  write_png_bytes(path, display.width, display.height, rgb8);
}

Image read_exr(const std::string& path) {
  try {
    Imf::InputFile file(path.c_str());
    Imath::Box2i dw = file.header().dataWindow();
    Image img;
    img.width = dw.max.x - dw.min.x + 1;
    img.height = dw.max.y - dw.min.y + 1;
    img.rgb.assign(size_t(img.width) * img.height * 3, 0.0f);
    const Imath::Box2i display = file.header().displayWindow();
    if (display != dw)
      img.window = {dw.min.x - display.min.x, dw.min.y - display.min.y,
                    display.max.x - display.min.x + 1, display.max.y - display.min.y + 1};
    Imf::FrameBuffer fb;
    const char* names[3] = {"R", "G", "B"};
    char* base = (char*)(img.rgb.data()) -
                 (size_t(dw.min.x) + size_t(dw.min.y) * img.width) * 3 * sizeof(float);
    for (int c = 0; c < 3; ++c)
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), 3 * sizeof(float),
                                     3 * sizeof(float) * img.width));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return img;
  } catch (const std::exception& e) {
    throw Error("cannot read OpenEXR file \"" + path + "\": " + e.what());
  }
}

void write_text_atomic(const std::string& path, const std::string& text) {
  write_bytes_atomic(path, text.data(), text.size());
}

void write_bytes_atomic(const std::string& path, const void* data, size_t size) {
  std::string tmp = temporary_path(path);
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw Error("cannot write \"" + path + "\"");
    out.write(static_cast<const char*>(data), std::streamsize(size));
    out.flush();
    if (!out) {
      std::filesystem::remove(tmp);
      throw Error("cannot write \"" + path + "\"");
    }
  }
  commit_file(tmp, path);
}

}  // namespace bpm
