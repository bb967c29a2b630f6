#include "base/error.h"

#include <atomic>
#include <iostream>
#include <mutex>

namespace bpm {

std::string FileLoc::str() const {
  if (file.empty()) return "<input>";
  if (line <= 0) return file;
  return file + ":" + std::to_string(line) + ":" + std::to_string(column);
}

namespace {
std::atomic<int> g_warnings{0};
std::mutex g_warning_mutex;
}  // namespace

void warning(const FileLoc& loc, const std::string& message) {
  ++g_warnings;
  std::lock_guard<std::mutex> lock(g_warning_mutex);
  std::cerr << loc.str() << ": warning: " << message << "\n";
}

int warning_count() { return g_warnings.load(); }

void check_failed(const char* expr, const char* file, int line) {
  std::fprintf(stderr, "internal error: check failed: %s at %s:%d\n", expr, file, line);
  std::abort();
}

}  // namespace bpm
