// ctid — the rows of a batch of fits, one per record, and the file they are written to as they arrive.
//
// Both batch engines — `ctid batch` (threads in the CLI) and Python's ctid.batch.fit_many / monte_carlo (threads
// or a Dask cluster) — make their rows with batch_row() and write them with BatchFile, so that either reads and
// resumes the other's file.
#pragma once

#include <cstdint>
#include <set>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "ctid/core/types.hpp"
#include "ctid/model/any_model.hpp"

namespace ctid {

/// One cell: text, a number (NaN: none), a whole number (e.g. a Monte Carlo run's seed) or yes/no.
using BatchCell = std::variant<std::string, double, std::int64_t, bool>;
/// One row: named cells in column order.
using BatchRow = std::vector<std::pair<std::string, BatchCell>>;

/// The columns every row has, in this order: id, method, model, orders, fit_percent, termination, usable, seconds,
/// error. A row of a fit then has NAME and NAME_std for each parameter NAME.
const std::vector<std::string>& batch_columns();

/// The row of record `id` fitted by `method` (its registry name). With a result: its model type, orders (nb= nf=
/// [delay=] per channel, nx= for state space, "" otherwise), fit (%), termination, usability, seconds (the fit's own)
/// and error = why it is not usable ("" when usable), then each parameter and its standard deviation. Without one
/// (the record could not be read or fitted): `error` (made one line) and `seconds`, the rest empty or NaN.
BatchRow batch_row(const std::string& id, const std::string& method, const Result<AnyModel>* result,
                   const std::string& error, double seconds);

/// The cell named `column` of a row; nullptr when the row has none.
const BatchCell* batch_cell(const BatchRow& row, const std::string& column);

/// A batch's rows file: CSV (.csv; a header, then one line per row, RFC 4180 quoting; numbers as their shortest
/// round-trip text, usable as True/False) or JSON lines (.jsonl, .json, .ndjson; one object per row, NaN as null).
/// Each row is written and flushed as it is added, so an interrupted batch keeps every row it finished; a CSV row
/// with new columns (other parameter names) rewrites the file once with the wider header (temporary file, then
/// rename). With `resume` the rows of an existing file are read first (their ids are then not fitted again).
/// Throws InvalidArgument for another file extension, FileError for a file that cannot be read, parsed or written.
class BatchFile {
 public:
  BatchFile(std::string path, bool resume);
  const std::string& path() const { return path_; }
  /// Every row: those read (resume) and those added, in order.
  const std::vector<BatchRow>& rows() const { return rows_; }
  bool contains(const std::string& id) const { return ids_.count(id) > 0; }
  /// The rows whose usable cell is true.
  std::size_t usable() const;
  void add(BatchRow row);

 private:
  void read();
  void append(const std::string& line) const;
  std::string csv_line(const BatchRow& row) const;

  std::string path_;
  bool jsonl_ = false;
  std::vector<std::string> columns_;
  std::vector<BatchRow> rows_;
  std::set<std::string> ids_;
};

}  // namespace ctid
