// ctid internal — write a file completely or not at all.
#pragma once

#include <string>

namespace ctid::internal {

/// Write `content` to a temporary file beside `path`, then rename it over `path`.
/// On failure nothing is left behind and FileError names the path and the reason.
void write_file_atomic(const std::string& path, const std::string& content);

/// Read a whole file; FileError when it cannot be opened.
std::string read_file(const std::string& path);

}  // namespace ctid::internal
