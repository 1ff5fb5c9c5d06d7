// ctid — load an experiment (IdData) from a CSV/.dat table or a .mat file.
#pragma once

#include <string>
#include <vector>

#include "ctid/data/iddata.hpp"
#include "ctid/io/csv.hpp"

namespace ctid {

/// Which columns (CSV: names or 1-based positions; .mat: variable names, each a
/// vector) make the experiment. Exactly one of `time` and `ts` gives the time axis.
struct DataSpec {
  std::vector<std::string> inputs;   ///< empty: no inputs (time series)
  std::vector<std::string> outputs;  ///< at least one
  std::string time;                  ///< time column / variable; strictly increasing
  double ts = 0.0;                   ///< sampling period (s) when there is no time column
  Intersample intersample = Intersample::Zoh;
  CsvReadOptions csv;                ///< delimiter, header and comment handling
};

/// Whether `path` ends in .mat (any letter case): such files are read with libmatio, others as text.
bool is_mat_file(const std::string& path);

/// Load by extension (.mat -> libmatio, anything else -> delimited text). Throws
/// FileError for file problems (path:line) and for a non-increasing time column;
/// InvalidArgument for an unknown column or a bad spec (no output, no time axis, a column selected twice
/// among the inputs or among the outputs, the time column selected as an input or output).
IdData load_iddata(const std::string& path, const DataSpec& spec);
/// Build from an already-read table.
IdData iddata_from_table(const CsvTable& table, const DataSpec& spec);

}  // namespace ctid
