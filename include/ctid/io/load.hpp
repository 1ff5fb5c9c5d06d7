// ctid — load an experiment (IdData) from a CSV/.dat table or a .mat file.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "ctid/data/frequency_data.hpp"
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

/// The name of channel j (0-based) of a record (IdData::input_names / output_names): its name, or its 1-based
/// position when it has none.
std::string channel_name(const std::vector<std::string>& names, int j);

/// A record chosen from a file with the defaults `ctid fit` and Python's ctid.load share when columns are left out.
struct RecordChoice {
  std::vector<std::string> inputs;   ///< names or 1-based positions; empty: the columns that are not the time axis
                                     ///< or the output (without an output: the first such column)
  /// Empty (need_output): the last column that is not the time axis — when the inputs are given, or when the file
  /// has exactly two such columns (more, with neither given: ColumnSelectionError, the output is not guessed).
  std::vector<std::string> outputs;
  std::string time;                  ///< time column; "" with ts = 0: the one column named t or time (any case)
  double ts = 0.0;                   ///< sampling period (s) when there is no time column
  Intersample intersample = Intersample::Zoh;
  bool need_output = true;           ///< false: inputs only (a signal); the record's output is its first input
  /// Rows "A:B" of the file, 1-based and inclusive, either end may be left out ("1:500", "501:"); "": all.
  std::string rows;
  std::string rows_name = "rows";    ///< what the messages call `rows` (the command line: "--samples")
  std::optional<Detrend> detrend;    ///< removed after the rows are taken; nullopt: nothing removed
};

struct ChosenRecord {
  IdData data;                ///< the chosen columns and rows, detrended
  int file_rows = 0;          ///< the rows of the file
  int first_row = 1, last_row = 0;  ///< the rows used, 1-based and inclusive
  std::string time_column;    ///< the time axis when it was found by its name ("" when given, or ts given)
  TrendInfo removed;          ///< what detrending removed (empty without)
  std::string removed_text;   ///< the same as text: "input u 4.994, output y 4.84337" (linear: "o + s (t - t_ref)")
  /// What was done to the file's data: "all 1000 rows; no detrending", "rows 1..500 of 1000; means removed (input u
  /// 4.994, output y 4.84337)".
  std::string preprocessing;
  /// What a user should be told about the reading (a front end shows each as a note): the time axis found by its
  /// name; sample times read as uniform although they deviate from the grid (by how much).
  std::vector<std::string> notes;
};

/// Loads `path` (load_iddata) with the defaults of RecordChoice, takes the rows and detrends. Throws FileError for
/// the file, ColumnSelectionError for a choice the file cannot satisfy (a column it does not have, one chosen twice
/// or as input and output, no column left for the input or the output, two columns or none that could be the time
/// axis), InvalidOptions for bad rows or a negative or non-finite ts, InvalidArgument for the file's content.
ChosenRecord choose_record(const std::string& path, const RecordChoice& choice);

/// The channels of d whose mean exceeds half their standard deviation, one line each naming the channel, its mean and
/// the ratio: a linear model through the origin cannot follow such an offset (remove the means or trends first).
std::vector<std::string> offset_warnings(const IdData& d);

/// The columns of a frequency-response table: the frequencies (rad/s) with the real and imaginary parts of G(jw),
/// or, when any of the spectra columns is named, with the input and output spectra (all four needed).
struct FrequencyColumns {
  std::string w = "w", re = "re", im = "im";
  std::string u_re, u_im, y_re, y_im;
};

/// A frequency-response table (CSV/.dat) as FrequencyData: G(jw) from re and im, or Y/U from the spectra
/// (FrequencyData::from_spectra); `rows` (not null) gets the file's rows. Throws FileError for the file,
/// ColumnSelectionError for a column it does not have, InvalidOptions for spectra named incompletely,
/// InvalidArgument naming the file for its content (frequencies not positive and increasing, a zero input spectrum).
FrequencyData load_frequency_data(const std::string& path, const FrequencyColumns& columns, int* rows = nullptr);

}  // namespace ctid
