#include "textures/image_file.h"

#include <dlfcn.h>

#include <filesystem>
#include <mutex>

#include "base/error.h"

namespace bpm {
namespace {

namespace fs = std::filesystem;

// The module's entry point, loaded once; null with the reason when it cannot be. It is looked for
// beside the running program (bpm, its tests and benchmarks are built into one folder), then in
// the folder it was built in, so a copied bpm still finds it while its build folder exists.
struct Reader {
  ReadImageFileFn* read = nullptr;
  std::string why_not;
};

Reader load_reader() {
  Reader r;
  std::vector<fs::path> places;
  std::error_code ec;
  const fs::path program = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) places.push_back(program.parent_path() / kImageReaderModule);
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
    if (r.read) return r;
    r.why_not += "\n  " + place.string() + ": has no " + kImageReaderEntry +
                 " (a module of another bpm version)";
    ::dlclose(module);
  }
  return r;
}

}  // namespace

ImageFile read_image_file(const std::string& path, double max_values) {
  static const Reader reader = load_reader();  // thread-safe, once per process
  if (!reader.read)
    throw Error("cannot read image \"" + path + "\": bpm's image reader (" + kImageReaderModule +
                ", built with bpm) was not found or not loaded:" + reader.why_not);
  ImageFile img;
  std::string error;
  if (!reader.read(path.c_str(), max_values, &img, &error)) throw Error(error);
  return img;
}

}  // namespace bpm
