// ctid — whole-file I/O that never leaves a partial file behind and reads only regular files of bounded size.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace ctid {

/// The largest file ctid reads (1 GiB): a data, model or result file beyond it is refused with FileError
/// rather than read into memory (a CSV of that size holds about 40 million numbers).
inline constexpr std::uintmax_t kMaxInputFileBytes = std::uintmax_t{1} << 30;
/// The longest line of a text table (1 MiB): a longer one is refused (a binary file read as text).
inline constexpr std::size_t kMaxLineBytes = std::size_t{1} << 20;

/// Throws FileError unless `path` names an existing regular file (symlinks followed) that is readable and at
/// most kMaxInputFileBytes long: a directory, a device (/dev/zero), a FIFO or a socket is refused by name.
void require_readable_regular_file(const std::string& path);

/// Where a write to `path` lands: `path` itself, or the final target when `path` is a symlink (a write goes
/// through the link and leaves it in place). Throws FileError when that target exists and is not a regular
/// file (a device such as /dev/null, a FIFO, a directory): ctid never replaces such a file.
std::string resolve_output_file(const std::string& path);

/// The guard a command runs on its output files before computing anything, so that nothing the user gave is lost:
/// refuses (InvalidArgument naming the file) an output that is one of `inputs` (compared after resolving symlinks),
/// two outputs that name the same file, an existing file unless `overwrite` (the message names `overwrite_flag`, the
/// front end's way to allow it), a target that is not a regular file even with `overwrite` (resolve_output_file),
/// and a directory that does not exist or is not writable. Empty names are skipped.
void check_output_files(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs, bool overwrite,
                        const std::string& overwrite_flag = "--force");

/// Write `content` to a temporary file beside the target of `path` (resolve_output_file), then rename it over
/// the target. On failure nothing is left behind and FileError names the path and the reason.
void write_text_file(const std::string& path, const std::string& content);

/// Read a whole file (require_readable_regular_file first); FileError naming the path otherwise.
std::string read_text_file(const std::string& path);

}  // namespace ctid
