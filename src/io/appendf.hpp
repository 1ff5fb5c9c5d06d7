// ctid — printf into a string: the one formatter of the library's text reports (io/text_report.hpp,
// io/tool_text.hpp), so that what the CLI prints and Python's repr shows are written with the same format strings.
#pragma once

#include <cstdarg>
#include <cstdio>
#include <string>

namespace ctid::io_detail {

[[gnu::format(printf, 2, 3)]] inline void appendf(std::string& out, const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list again;
  va_copy(again, args);
  const int n = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  if (n > 0) {
    const std::size_t at = out.size();
    out.resize(at + static_cast<std::size_t>(n) + 1);
    std::vsnprintf(out.data() + at, static_cast<std::size_t>(n) + 1, format, again);
    out.resize(at + static_cast<std::size_t>(n));
  }
  va_end(again);
}

}  // namespace ctid::io_detail
