// One exception type for user-facing failures (bad scene files, bad flags, unwritable outputs).
// It carries the scene-file location when there is one; main() prints it and exits non-zero.
#pragma once
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace bpm {

struct FileLoc {
  std::string file;
  int line = 0;
  int column = 0;
  std::string str() const;
};

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
  Error(const FileLoc& loc, const std::string& message)
      : std::runtime_error(loc.str() + ": " + message), loc_(loc) {}
  const FileLoc& loc() const { return loc_; }

 private:
  FileLoc loc_;
};

// Warnings go to stderr once each; tests can count them.
void warning(const FileLoc& loc, const std::string& message);
int warning_count();

[[noreturn]] void check_failed(const char* expr, const char* file, int line);

}  // namespace bpm

// Internal invariant, kept in release builds (use only where it is cheap).
#define BPM_CHECK(expr)                                          \
  do {                                                           \
    if (!(expr)) ::bpm::check_failed(#expr, __FILE__, __LINE__); \
  } while (0)
