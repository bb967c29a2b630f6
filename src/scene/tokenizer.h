// Splits pbrt-v4 scene text into tokens, each with its file:line:column.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "base/error.h"

namespace bpm {

struct Token {
  std::string_view text;  // quoted strings keep their quotes
  FileLoc loc;
  bool is_string() const { return text.size() >= 2 && text.front() == '"'; }
  bool is(std::string_view s) const { return text == s; }
  // The text of a quoted string without its quotes (escapes resolved).
  std::string unquoted() const;
};

class Tokenizer {
 public:
  // Reads the whole file; throws Error when it cannot be read.
  static std::unique_ptr<Tokenizer> from_file(const std::string& path,
                                              const FileLoc& included_from);
  static std::unique_ptr<Tokenizer> from_string(std::string text, std::string name = "<string>");

  // Next token, or nullopt at the end of input. Throws on an unterminated string.
  std::optional<Token> next();
  const std::string& file_name() const { return name_; }

 private:
  Tokenizer(std::string text, std::string name) : text_(std::move(text)), name_(std::move(name)) {}
  std::string text_;
  std::string name_;
  size_t pos_ = 0;
  int line_ = 1;
  size_t line_start_ = 0;
};

}  // namespace bpm
