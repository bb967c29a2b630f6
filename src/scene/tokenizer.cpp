#include "scene/tokenizer.h"

#include "base/text.h"

namespace bpm {

std::string Token::unquoted() const {
  std::string out;
  std::string_view body = text.substr(1, text.size() - 2);
  for (size_t i = 0; i < body.size(); ++i) {
    if (body[i] == '\\' && i + 1 < body.size()) {
      char c = body[++i];
      switch (c) {
        case 'n':
          out += '\n';
          break;
        case 't':
          out += '\t';
          break;
        default:
          out += c;
          break;
      }
    } else {
      out += body[i];
    }
  }
  return out;
}

std::unique_ptr<Tokenizer> Tokenizer::from_file(const std::string& path, const FileLoc& from) {
  return std::unique_ptr<Tokenizer>(new Tokenizer(read_text_file(path, "scene file", from), path));
}

std::unique_ptr<Tokenizer> Tokenizer::from_string(std::string text, std::string name) {
  return std::unique_ptr<Tokenizer>(new Tokenizer(std::move(text), std::move(name)));
}

std::optional<Token> Tokenizer::next() {
  auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (pos_ < text_.size()) {
    char c = text_[pos_];
    if (c == '\n') {
      ++pos_;
      ++line_;
      line_start_ = pos_;
      continue;
    }
    if (is_space(c)) {
      ++pos_;
      continue;
    }
    if (c == '#') {
      while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
      continue;
    }
    size_t start = pos_;
    FileLoc loc{name_, line_, int(pos_ - line_start_) + 1};
    if (c == '"') {
      ++pos_;
      while (pos_ < text_.size() && text_[pos_] != '"') {
        if (text_[pos_] == '\n') throw Error(loc, "unterminated string (newline inside quotes)");
        if (text_[pos_] == '\\') {
          ++pos_;
          if (pos_ < text_.size() && text_[pos_] == '\n')
            throw Error(loc, "unterminated string (newline inside quotes)");
        }
        ++pos_;
      }
      if (pos_ >= text_.size()) throw Error(loc, "unterminated string at end of file");
      ++pos_;
      return Token{std::string_view(text_).substr(start, pos_ - start), loc};
    }
    if (c == '[' || c == ']') {
      ++pos_;
      return Token{std::string_view(text_).substr(start, 1), loc};
    }
    while (pos_ < text_.size() && !is_space(text_[pos_]) && text_[pos_] != '"' &&
           text_[pos_] != '[' && text_[pos_] != ']' && text_[pos_] != '#')
      ++pos_;
    return Token{std::string_view(text_).substr(start, pos_ - start), loc};
  }
  return std::nullopt;
}

}  // namespace bpm
