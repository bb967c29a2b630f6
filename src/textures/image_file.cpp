#include "textures/image_file.h"

#include <dlfcn.h>

#include <filesystem>
#include <mutex>

#include "base/error.h"

namespace bpm {
namespace {

namespace fs = std::filesystem;

// The module's entry point, loaded once; null with the reason when it cannot be. It is looked for
// beside the running program (bpm, its tests and benchmarks are built into one folder), beside the
// shared object this code is linked into (the Python module, which Python runs), then in the folder
// it was built in, so a copied bpm still finds it while its build folder exists.
struct Reader {
  ReadImageFileFn* read = nullptr;
  DrawTextFn* draw_text = nullptr;
  std::string why_not;
};

Reader load_reader() {
  Reader r;
  std::vector<fs::path> places;
  std::error_code ec;
  const fs::path program = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) places.push_back(program.parent_path() / kImageReaderModule);
  Dl_info self{};
  if (::dladdr(reinterpret_cast<void*>(&load_reader), &self) && self.dli_fname) {
    const fs::path here = fs::path(self.dli_fname).parent_path() / kImageReaderModule;
    if (places.empty() || fs::weakly_canonical(here, ec) != fs::weakly_canonical(places[0], ec))
      places.push_back(here);
  }
#ifdef BPM_MODULE_DIR
  const fs::path built = fs::path(BPM_MODULE_DIR) / kImageReaderModule;
  if (places.empty() || fs::weakly_canonical(built, ec) != fs::weakly_canonical(places[0], ec))
    places.push_back(built);
#endif
  for (const fs::path& place : places) {
    if (!fs::exists(place, ec)) {
      r.why_not += "\n  " + place.string() + ": " + (ec ? ec.message() : "not there");
      continue;
    }
    void* module = ::dlopen(place.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!module) {
      const char* e = ::dlerror();
      r.why_not += "\n  " + place.string() + ": " + (e ? e : "cannot be loaded");
      continue;
    }
    r.read = reinterpret_cast<ReadImageFileFn*>(::dlsym(module, kImageReaderEntry));
    r.draw_text = reinterpret_cast<DrawTextFn*>(::dlsym(module, kDrawTextEntry));
    if (r.read && r.draw_text) return r;
    r.why_not += "\n  " + place.string() + ": has no " + kImageReaderEntry + " or " +
                 kDrawTextEntry + " (a module of another bpm version)";
    r.read = nullptr;
    r.draw_text = nullptr;
    ::dlclose(module);
  }
  return r;
}

const Reader& reader_module() {
  static const Reader reader = load_reader();  // thread-safe, once per process
  return reader;
}

}  // namespace

ImageFile read_image_file(const std::string& path, double max_values) {
  const Reader& reader = reader_module();
  if (!reader.read)
    throw Error("cannot read image \"" + path + "\": bpm's image reader (" + kImageReaderModule +
                ", built with bpm) was not found or not loaded:" + reader.why_not);
  ImageFile img;
  std::string error;
  if (!reader.read(path.c_str(), max_values, &img, &error)) throw Error(error);
  return img;
}

bool draw_text(float* rgb, int width, int height, int x, int y, const std::string& text, int size,
               const float colour[3], int align, std::string* error) {
  const Reader& reader = reader_module();
  if (!reader.draw_text) {
    *error = std::string("bpm's image module (") + kImageReaderModule +
             ") was not found or not loaded:" + reader.why_not;
    return false;
  }
  return reader.draw_text(rgb, width, height, x, y, text.c_str(), size, colour, align, error);
}

}  // namespace bpm
