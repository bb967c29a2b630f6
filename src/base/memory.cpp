#include "base/memory.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "base/error.h"

namespace bpm {
namespace {

// The cgroup v2 limit ("max" when there is none), else cgroup v1's; 0 when neither says.
uint64_t cgroup_limit_bytes() {
  for (const char* path :
       {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(path);
    std::string s;
    if (!(in >> s) || s.empty() || !std::isdigit(static_cast<unsigned char>(s[0]))) continue;
    try {
      return std::stoull(s);
    } catch (const std::exception&) {
    }
  }
  return 0;
}

}  // namespace

uint64_t machine_memory_bytes() {
  long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  uint64_t physical = pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : 0;
  uint64_t cgroup = cgroup_limit_bytes();
  if (physical == 0) return cgroup;
  return cgroup > 0 ? std::min(physical, cgroup) : physical;
}

uint64_t default_memory_budget() { return machine_memory_bytes() / 4 * 3; }

uint64_t parse_memory_size(const std::string& text) {
  const std::string bad =
      "--memory must be a size such as 512M, 8G or 1.5GiB; got \"" + text + "\"";
  size_t end = 0;
  double value = 0;
  try {
    value = std::stod(text, &end);
  } catch (const std::exception&) {
    throw Error(bad);
  }
  std::string unit = text.substr(end);
  for (char& c : unit) c = char(std::toupper(static_cast<unsigned char>(c)));
  if (unit.size() > 1 && unit.back() == 'B') unit.pop_back();  // "GB", "GIB"
  if (unit.size() > 1 && unit.back() == 'I') unit.pop_back();  // "GI"
  double scale = 0;
  if (unit.empty() || unit == "M")
    scale = 1024.0 * 1024;
  else if (unit == "K")
    scale = 1024.0;
  else if (unit == "G")
    scale = 1024.0 * 1024 * 1024;
  else if (unit == "T")
    scale = 1024.0 * 1024 * 1024 * 1024;
  if (scale == 0 || !std::isfinite(value) || value <= 0) throw Error(bad);
  const double bytes = value * scale;
  if (bytes < 1024.0 * 1024) throw Error(bad + " (at least 1M)");
  if (bytes > 0x1p62) throw Error(bad + " (too large)");
  return uint64_t(bytes);
}

std::string format_bytes(double bytes) {
  const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB"};
  int u = 0;
  while (bytes >= 1024 && u < 5) {
    bytes /= 1024;
    ++u;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.3g %s", bytes, units[u]);
  return buf;
}

void check_memory(const std::string& what, double needed, uint64_t budget,
                  const std::string& advice) {
  if (budget == 0 || needed <= double(budget)) return;
  throw Error(what + " needs " + format_bytes(needed) + ", more than the memory budget of " +
              format_bytes(double(budget)) + " (--memory; default 3/4 of this machine's " +
              format_bytes(double(machine_memory_bytes())) + "); " + advice);
}

}  // namespace bpm
