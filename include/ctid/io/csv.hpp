// ctid — delimited text tables (CSV and whitespace-separated .dat files).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

namespace ctid {

enum class CsvHeader { Auto, Yes, No };

struct CsvReadOptions {
  char delimiter = 0;                  ///< 0: detect (',' then ';' then tab/space runs)
  CsvHeader header = CsvHeader::Auto;  ///< Auto: a first row that is not all numbers is a header
  std::string comment_chars = "#%";    ///< lines starting with one of these are skipped
};

/// A numeric table. Without a header row the columns are named "1", "2", ...
struct CsvTable {
  std::vector<std::string> names;
  Eigen::MatrixXd values;          ///< rows x columns
  std::vector<int> line_numbers;   ///< source line (1-based) of each row
  std::string source;              ///< the path it was read from
  /// Column by name, or by 1-based position given as a number ("3"). Throws
  /// InvalidArgument listing the known names.
  int column(const std::string& name_or_position) const;
};

/// Read a table. Throws FileError (path:line: what) for a missing file, a row with the
/// wrong number of fields, a cell that is not a number, a NaN/Inf cell, or no data rows.
/// Trailing delimiters at the end of a line are ignored.
CsvTable read_csv(const std::string& path, const CsvReadOptions& options = {});
/// Parse text already in memory; `source` names it in messages.
CsvTable parse_csv(const std::string& text, const std::string& source, const CsvReadOptions& options = {});

/// Write a comma-separated table with a header row, atomically (all or nothing);
/// values at full precision (17 significant digits). Throws FileError.
void write_csv(const std::string& path, const std::vector<std::string>& names, const Eigen::MatrixXd& values);

class FsfModel;
/// The responses of an FSF model with their standard deviations (ctid fit --responses PREFIX): PREFIX_time.csv
/// (t, step, step_std, impulse, impulse_std on 501 points over [0, T]) and PREFIX_freq.csv (w, re, im, re_std,
/// im_std, mag, phase_deg on the model's default frequency grid, model_frequency_grid). Throws FileError.
void write_fsf_responses(const std::string& prefix, const FsfModel& model);

}  // namespace ctid
