// ctid — check macros for the error tiers (docs/architecture.md, "Errors").
//
//   CTID_REQUIRE(cond, "fmt {}", args...)          tier 1: throws ctid::InvalidArgument
//   CTID_REQUIRE_OPTION(cond, "fmt {}", args...)   tier 1: throws ctid::InvalidOptions
//   CTID_ASSERT(cond)                              tier 3: internal invariant; aborts
//                                                  with file:line (active in every build)
// Messages are formatted with std::format-like "{}" placeholders (a minimal
// formatter is provided here so the public headers do not depend on fmt).
#pragma once

#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>

#include "ctid/core/error.hpp"

namespace ctid::detail {

inline void format_into(std::ostringstream& os, std::string_view f) { os << f; }

template <class T, class... Rest>
void format_into(std::ostringstream& os, std::string_view f, const T& first, const Rest&... rest) {
  const auto pos = f.find("{}");
  if (pos == std::string_view::npos) {
    os << f;
    return;
  }
  os << f.substr(0, pos) << first;
  format_into(os, f.substr(pos + 2), rest...);
}

/// Replace each "{}" in `f` by the next argument (streamed with operator<<).
template <class... Args>
std::string format(std::string_view f, const Args&... args) {
  std::ostringstream os;
  os.precision(10);
  format_into(os, f, args...);
  return os.str();
}

/// `v` to `digits` significant digits ("1.365", "16.57", "8.523") — for numbers in prose (automatic choices).
inline std::string significant(double v, int digits = 4) {
  std::ostringstream os;
  os.precision(digits);
  os << v;
  return os.str();
}

/// The shortest text that reads back as exactly `v` ("0.1", "1e-300", "inf", "nan").
inline std::string round_trip(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

[[noreturn]] inline void assert_fail(const char* cond, const char* file, int line) {
  std::fprintf(stderr, "ctid internal error: assertion '%s' failed at %s:%d\n", cond, file, line);
  std::abort();
}

}  // namespace ctid::detail

#define CTID_REQUIRE(cond, ...)                                              \
  do {                                                                       \
    if (!(cond)) throw ::ctid::InvalidArgument(::ctid::detail::format(__VA_ARGS__)); \
  } while (0)

#define CTID_REQUIRE_OPTION(cond, ...)                                       \
  do {                                                                       \
    if (!(cond)) throw ::ctid::InvalidOptions(::ctid::detail::format(__VA_ARGS__)); \
  } while (0)

#define CTID_ASSERT(cond)                                                    \
  do {                                                                       \
    if (!(cond)) ::ctid::detail::assert_fail(#cond, __FILE__, __LINE__);     \
  } while (0)
