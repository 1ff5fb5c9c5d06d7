#include "ctid/io/file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>
#include <sys/stat.h>
#include <unistd.h>

#include "ctid/core/check.hpp"

namespace ctid {

namespace {
const char* kind_of(mode_t m) {
  if (S_ISDIR(m)) return "a directory";
  if (S_ISCHR(m)) return "a character device";
  if (S_ISBLK(m)) return "a block device";
  if (S_ISFIFO(m)) return "a FIFO (named pipe)";
  if (S_ISSOCK(m)) return "a socket";
  return "not a regular file";
}
}  // namespace

void require_readable_regular_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw FileError(detail::format("cannot open '{}': {}", path, std::strerror(errno)));
  if (!S_ISREG(st.st_mode))
    throw FileError(detail::format("cannot read '{}': it is {}, not a data file", path, kind_of(st.st_mode)));
  if (static_cast<std::uintmax_t>(st.st_size) > kMaxInputFileBytes)
    throw FileError(detail::format("cannot read '{}': it has {} bytes, more than the limit of {} bytes (1 GiB)", path,
                                   static_cast<std::uintmax_t>(st.st_size), kMaxInputFileBytes));
  if (::access(path.c_str(), R_OK) != 0) throw FileError(detail::format("cannot open '{}': {}", path, std::strerror(errno)));
}

std::string resolve_output_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::string target = path;
  if (fs::is_symlink(fs::symlink_status(path, ec))) {
    const fs::path t = fs::weakly_canonical(path, ec);
    if (ec) throw FileError(detail::format("cannot write '{}': cannot resolve the link ({})", path, ec.message()));
    target = t.string();
  }
  struct stat st {};
  if (::stat(target.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw FileError(detail::format("refusing to write '{}': it is {}, not a regular file", path, kind_of(st.st_mode)));
  return target;
}

void check_output_files(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs, bool overwrite,
                        const std::string& overwrite_flag) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<std::pair<fs::path, std::string>> lands;  // where each output lands, and its name as given
  for (const auto& out : outputs) {
    if (out.empty()) continue;
    std::string target;
    try {
      target = resolve_output_file(out);
    } catch (const FileError& e) {
      throw InvalidArgument(e.what());
    }
    const fs::path abs = fs::weakly_canonical(fs::absolute(target, ec), ec);
    for (const auto& [where, name] : lands)
      if (where == abs) throw InvalidArgument(detail::format("two outputs of this command name the same file '{}' (and '{}')", out, name));
    lands.emplace_back(abs, out);
    for (const auto& in : inputs)
      if (!in.empty() && fs::exists(in, ec) && fs::exists(target, ec) && fs::equivalent(in, target, ec))
        throw InvalidArgument(detail::format("refusing to write '{}': it is the input file '{}'", out, in));
    if (fs::exists(target, ec) && !overwrite)
      throw InvalidArgument(detail::format("'{}' exists; use {} to overwrite it", out, overwrite_flag));
    const fs::path dir = abs.has_parent_path() ? abs.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec))
      throw InvalidArgument(detail::format("cannot write '{}': the directory '{}' does not exist", out, dir.string()));
    if (::access(dir.c_str(), W_OK) != 0)
      throw InvalidArgument(detail::format("cannot write '{}': the directory '{}' is not writable", out, dir.string()));
  }
}

void write_text_file(const std::string& out, const std::string& content) {
  const std::string path = resolve_output_file(out);
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw FileError(detail::format("cannot write '{}': {}", out, std::strerror(errno)));
    f << content;
    f.flush();
    if (!f) {
      std::remove(tmp.c_str());
      throw FileError(detail::format("cannot write '{}': write failed", out));
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    std::remove(tmp.c_str());
    throw FileError(detail::format("cannot write '{}': {}", out, why));
  }
}

std::string read_text_file(const std::string& path) {
  require_readable_regular_file(path);
  std::ifstream f(path, std::ios::binary);
  if (!f) throw FileError(detail::format("cannot open '{}': {}", path, std::strerror(errno)));
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace ctid
