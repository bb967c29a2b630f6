// Reading the text files bpm takes besides scenes' own tokens (photometric files, sensor files)
// and the scene file itself: the whole file, its words with their columns, strict numbers.
#pragma once
#include <string>
#include <vector>

#include "base/error.h"

namespace bpm {

// The whole file. Throws Error "cannot open WHAT \"PATH\"" (or "error reading ..."), located at
// `from` when it is given (an Include's line).
std::string read_text_file(const std::string& path, const std::string& what,
                           const FileLoc& from = {});

// A word of a line and its 1-based column.
struct Word {
  std::string text;
  int column = 0;
};
// The words of a line, split at white space and at any character of `separators`.
std::vector<Word> split_words(const std::string& line, const std::string& separators = "");

// The whole of `text` as a finite number.
bool parse_number(const std::string& text, double* value);

}  // namespace bpm
