// ctid internal — the cursor the two expression parsers of model/ share (physical_model.cpp: transfer-function
// expressions in s; expression.cpp: the grey-box model language): whitespace, one-character tokens, and errors
// that name the expression and the column.
#pragma once

#include <cctype>
#include <cstdlib>
#include <optional>
#include <string>

#include "ctid/core/check.hpp"
#include "ctid/core/error.hpp"

namespace ctid::model_detail {

struct TextCursor {
  const std::string& text;
  std::size_t pos = 0;

  [[noreturn]] void fail(const std::string& what) const {
    throw InvalidArgument(detail::format("expression \"{}\": {} at column {}", text, what, pos + 1));
  }
  void skip() {
    while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
  }
  bool accept(char c) {
    skip();
    if (pos < text.size() && text[pos] == c) {
      ++pos;
      return true;
    }
    return false;
  }
  // The number at the cursor (digits, '.', exponent), or nullopt when the next character does not start one.
  std::optional<double> number() {
    skip();
    if (pos >= text.size() || !(std::isdigit(static_cast<unsigned char>(text[pos])) || text[pos] == '.'))
      return std::nullopt;
    const char* begin = text.c_str() + pos;
    char* end = nullptr;
    const double v = std::strtod(begin, &end);
    if (end == begin) fail("malformed number");
    pos += static_cast<std::size_t>(end - begin);
    return v;
  }
};

}  // namespace ctid::model_detail
