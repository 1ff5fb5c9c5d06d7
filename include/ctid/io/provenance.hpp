// ctid — where a result came from: the command, the library build, the data files and what was done to them.
//
// A Provenance value is made by the front end that runs a job (the CLI from its command line) and passed
// explicitly to what records it: the HTML report's summary and the result file's "provenance" member.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace ctid {

/// One data file a result was computed from.
struct DataFileProvenance {
  std::string path;          ///< as given
  std::string content_hash;  ///< "fnv1a64:<16 hex digits>" of the file's bytes (file_content_hash)
  int rows = 0;              ///< the data rows in the file (before any selection)
};

struct Provenance {
  std::string command_line;  ///< the command that made the result, as typed ("" when not made by a command)
  std::string version;       ///< the ctid version (version())
  std::string commit;  ///< the git commit the library was built from, "-dirty" appended when the checkout had changes
  std::vector<DataFileProvenance> data;     ///< the data files, in the order they were read
  std::vector<std::string> preprocessing;   ///< what was done to the data before the fit, one entry per record
  /// The table rows a report shows: "preprocessing" (the records' entries joined by " | ") and "command" when
  /// given, one "data" row per file (path, rows, hash). The "made by" row (version, commit, time) is the report's.
  std::vector<std::pair<std::string, std::string>> rows() const;
  /// "ctid 0.1.0", or with the build's commit "ctid 0.1.0 (commit 1a2b3c4d5e6f)".
  std::string made_by() const;
  /// Records a data file that was read: its content hash and row count (nothing twice for one path).
  void add_data_file(const std::string& path, int rows);
};

/// A provenance with the library's version and build commit, and `command_line`.
Provenance make_provenance(std::string command_line = "");
/// The git commit the library was built from, "" when unknown.
const char* build_commit();
/// A fingerprint of a file's bytes: "fnv1a64:" and 16 hex digits (FNV-1a, 64 bit: detects a changed file, not an
/// adversary). Throws FileError when the file cannot be read.
std::string file_content_hash(const std::string& path);

}  // namespace ctid
