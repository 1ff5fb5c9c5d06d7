// ctid — provenance of a result (io/provenance.hpp).
#include "ctid/io/provenance.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>

#include "ctid/core/error.hpp"
#include "ctid/io/json.hpp"

namespace ctid {

std::vector<std::pair<std::string, std::string>> Provenance::rows() const {
  std::vector<std::pair<std::string, std::string>> r;
  std::string pre;
  for (const auto& p : preprocessing) pre += (pre.empty() ? "" : " | ") + p;
  if (!pre.empty()) r.emplace_back("preprocessing", pre);
  if (!command_line.empty()) r.emplace_back("command", command_line);
  for (const auto& f : data)
    r.emplace_back("data", f.path + ": " + std::to_string(f.rows) + " rows, " + f.content_hash);
  return r;
}

std::string Provenance::made_by() const {
  std::string s = "ctid " + version;
  if (!commit.empty()) s += " (commit " + commit.substr(0, 12) + (commit.ends_with("-dirty") ? "-dirty" : "") + ")";
  return s;
}

void Provenance::add_data_file(const std::string& path, int rows) {
  if (std::any_of(data.begin(), data.end(), [&](const DataFileProvenance& f) { return f.path == path; })) return;
  data.push_back({path, file_content_hash(path), rows});
}

Provenance make_provenance(std::string command_line) {
  Provenance p;
  p.command_line = std::move(command_line);
  p.version = ctid::version();
  p.commit = build_commit();
  return p;
}

std::string file_content_hash(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw FileError("cannot read " + path);
  std::uint64_t h = 14695981039346656037ULL;  // FNV-1a offset basis and prime (64 bit)
  char buf[1 << 16];
  while (f.read(buf, sizeof buf) || f.gcount() > 0) {
    for (std::streamsize i = 0; i < f.gcount(); ++i) {
      h ^= static_cast<unsigned char>(buf[i]);
      h *= 1099511628211ULL;
    }
    if (!f) break;
  }
  char out[32];
  std::snprintf(out, sizeof out, "fnv1a64:%016llx", static_cast<unsigned long long>(h));
  return out;
}

}  // namespace ctid
