// ctid — whole-file text I/O that never leaves a partial file behind.
#pragma once

#include <string>

namespace ctid {

/// Write `content` to a temporary file beside `path`, then rename it over `path`.
/// On failure nothing is left behind and FileError names the path and the reason.
void write_text_file(const std::string& path, const std::string& content);

/// Read a whole file; FileError naming the path when it cannot be opened.
std::string read_text_file(const std::string& path);

}  // namespace ctid
