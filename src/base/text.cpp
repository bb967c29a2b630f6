#include "base/text.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace bpm {

std::string read_text_file(const std::string& path, const std::string& what, const FileLoc& from) {
  auto fail = [&](const std::string& message) {
    return from.file.empty() ? Error(message) : Error(from, message);
  };
  std::ifstream in(path, std::ios::binary);
  if (!in) throw fail("cannot open " + what + " \"" + path + "\"");
  std::stringstream s;
  s << in.rdbuf();
  if (in.bad()) throw fail("error reading " + what + " \"" + path + "\"");
  return s.str();
}

std::vector<Word> split_words(const std::string& line, const std::string& separators) {
  auto separates = [&](char c) {
    return std::isspace(static_cast<unsigned char>(c)) || separators.find(c) != std::string::npos;
  };
  std::vector<Word> words;
  size_t k = 0;
  while (k < line.size()) {
    while (k < line.size() && separates(line[k])) ++k;
    const size_t start = k;
    while (k < line.size() && !separates(line[k])) ++k;
    if (k > start) words.push_back({line.substr(start, k - start), int(start + 1)});
  }
  return words;
}

bool parse_number(const std::string& text, double* value) {
  if (text.empty()) return false;
  char* end = nullptr;
  *value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(*value);
}

}  // namespace bpm
