#include "ctid/io/load.hpp"

#include <algorithm>
#include <cctype>
#include <complex>
#include <cmath>
#include <cstdio>
#include <optional>

#include "ctid/core/check.hpp"
#include "io/appendf.hpp"
#include "ctid/io/mat.hpp"

namespace ctid {

namespace {

void check_spec(const DataSpec& s, const std::string& source) {
  CTID_REQUIRE(!s.outputs.empty(), "{}: no output column selected", source);
  CTID_REQUIRE(s.time.empty() != (s.ts == 0.0), "{}: give either a time column or a sampling period Ts (not {})", source,
               s.time.empty() ? "neither" : "both");
  CTID_REQUIRE(!(s.ts < 0) && std::isfinite(s.ts), "{}: the sampling period must be positive (got Ts = {})", source, s.ts);
}

IdData assemble(const Eigen::MatrixXd& u, const Eigen::MatrixXd& y, const Eigen::VectorXd* t, const DataSpec& s,
                const std::string& source, const std::vector<int>* lines) {
  IdData d;
  if (t) {
    for (Eigen::Index k = 1; k < t->size(); ++k)
      if (!((*t)(k) > (*t)(k - 1))) {
        const std::string where = lines ? detail::format("{}:{}", source, (*lines)[k]) : detail::format("{}: sample {}", source, k);
        throw FileError(detail::format("{}: time column '{}' is not strictly increasing ({} after {})", where, s.time,
                                       (*t)(k), (*t)(k - 1)));
      }
    d = IdData::from_times(u, y, *t);
  } else {
    d = IdData(u, y, s.ts);
  }
  d.set_intersample(s.intersample);
  d.set_input_names(s.inputs);
  d.set_output_names(s.outputs);
  return d;
}

}  // namespace

namespace {
// The same column selected twice (by name or position) would fit a spurious channel: refused. Inputs among
// themselves, outputs among themselves, and the time column against both.
template <class Key>
void check_distinct(const DataSpec& s, const std::string& source, Key key) {
  auto twice = [&](const std::vector<std::string>& v, const char* what) {
    for (std::size_t i = 0; i < v.size(); ++i)
      for (std::size_t k = 0; k < i; ++k)
        if (key(v[i]) == key(v[k]))
          throw ColumnSelectionError(
              detail::format("{}: {} '{}' and '{}' are the same column; select each once", source, what, v[k], v[i]));
  };
  twice(s.inputs, "inputs");
  twice(s.outputs, "outputs");
  if (s.time.empty()) return;
  for (const auto* v : {&s.inputs, &s.outputs})
    for (const auto& n : *v)
      if (key(n) == key(s.time))
        throw ColumnSelectionError(
            detail::format("{}: '{}' is the time column; it cannot also be an input or output", source, n));
}
}  // namespace

bool is_mat_file(const std::string& path) {
  if (path.size() <= 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".mat";
}

IdData iddata_from_table(const CsvTable& tab, const DataSpec& s) {
  check_spec(s, tab.source);
  check_distinct(s, tab.source, [&](const std::string& n) { return tab.column(n); });
  const Eigen::Index N = tab.values.rows();
  // Empty cells are NaN in the table; a used column must have none.
  std::vector<std::string> used = s.inputs;
  used.insert(used.end(), s.outputs.begin(), s.outputs.end());
  if (!s.time.empty()) used.push_back(s.time);
  {
    for (const auto& name : used) {
      const int c = tab.column(name);
      for (Eigen::Index k = 0; k < N; ++k)
        if (std::isnan(tab.values(k, c)))
          throw FileError(detail::format("{}:{}: column '{}' (field {}) is empty", tab.source,
                                         k < static_cast<Eigen::Index>(tab.line_numbers.size()) ? tab.line_numbers[k] : k + 1,
                                         tab.names[c], c + 1));
    }
  }
  Eigen::MatrixXd u(N, s.inputs.size()), y(N, s.outputs.size());
  for (std::size_t j = 0; j < s.inputs.size(); ++j) u.col(j) = tab.values.col(tab.column(s.inputs[j]));
  for (std::size_t j = 0; j < s.outputs.size(); ++j) y.col(j) = tab.values.col(tab.column(s.outputs[j]));
  if (!s.time.empty()) {
    const Eigen::VectorXd t = tab.values.col(tab.column(s.time));
    return assemble(u, y, &t, s, tab.source, &tab.line_numbers);
  }
  return assemble(u, y, nullptr, s, tab.source, nullptr);
}

IdData load_iddata(const std::string& path, const DataSpec& s) {
  if (!is_mat_file(path)) return iddata_from_table(read_csv(path, s.csv), s);
  check_spec(s, path);
  check_distinct(s, path, [](const std::string& n) { return n; });
  auto vec = [&](const std::string& name) {
    const Eigen::MatrixXd m = read_mat_variable(path, name);
    if (m.rows() != 1 && m.cols() != 1)
      throw FileError(detail::format("{}: variable '{}' is {}x{}; a vector is expected", path, name, m.rows(), m.cols()));
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(m.data(), m.size()));
  };
  std::vector<Eigen::VectorXd> ins, outs;
  for (const auto& n : s.inputs) ins.push_back(vec(n));
  for (const auto& n : s.outputs) outs.push_back(vec(n));
  const Eigen::Index N = outs[0].size();
  auto check_len = [&](const Eigen::VectorXd& v, const std::string& name) {
    if (v.size() != N)
      throw FileError(detail::format("{}: variable '{}' has {} samples but '{}' has {}", path, name, v.size(), s.outputs[0], N));
  };
  Eigen::MatrixXd u(N, ins.size()), y(N, outs.size());
  for (std::size_t j = 0; j < ins.size(); ++j) { check_len(ins[j], s.inputs[j]); u.col(j) = ins[j]; }
  for (std::size_t j = 0; j < outs.size(); ++j) { check_len(outs[j], s.outputs[j]); y.col(j) = outs[j]; }
  for (Eigen::Index j = 0; j < u.cols(); ++j)
    for (Eigen::Index k = 0; k < N; ++k)
      if (!std::isfinite(u(k, j))) throw FileError(detail::format("{}: variable '{}' sample {} is not finite", path, s.inputs[j], k));
  for (Eigen::Index j = 0; j < y.cols(); ++j)
    for (Eigen::Index k = 0; k < N; ++k)
      if (!std::isfinite(y(k, j))) throw FileError(detail::format("{}: variable '{}' sample {} is not finite", path, s.outputs[j], k));
  if (!s.time.empty()) {
    const Eigen::VectorXd t = vec(s.time);
    check_len(t, s.time);
    return assemble(u, y, &t, s, path, nullptr);
  }
  return assemble(u, y, nullptr, s, path, nullptr);
}


namespace {
// Rows "A:B" (1-based, inclusive, either end open) of a record of n rows as [begin, end); InvalidOptions naming the
// rows' name, the text and the record size.
std::pair<int, int> row_range(const std::string& name, const std::string& text, int n) {
  const auto colon = text.find(':');
  auto bad = [&](const std::string& why) {
    return InvalidOptions(name + " " + text + ": " + why + " (the record has " + std::to_string(n) + " rows)");
  };
  if (colon == std::string::npos || text.find(':', colon + 1) != std::string::npos)
    throw bad("give A:B, the first and last row (1-based; '1:500', '501:')");
  auto number = [&](const std::string& part, int fallback) {
    if (part.empty()) return fallback;
    size_t used = 0;
    long v = 0;
    try {
      v = std::stol(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != part.size() || v < 1 || v > n) throw bad("'" + part + "' is not a row number from 1 to " + std::to_string(n));
    return static_cast<int>(v);
  };
  const int first = number(text.substr(0, colon), 1), last = number(text.substr(colon + 1), n);
  if (last - first + 1 < 2) throw bad("the range holds fewer than 2 rows");
  return {first - 1, last};
}

// What detrending removed, channel by channel: "input 1 4.994, output 2 4.84337" (linear: offset + slope (t - t_ref)).
std::string removed_text(const IdData& d, const TrendInfo& removed, Detrend how) {
  std::string what;
  char value[64];
  for (int j = 0; j < d.nu() + d.ny(); ++j) {
    const bool in = j < d.nu();
    const int k = in ? j : j - d.nu();
    if (how == Detrend::Mean)
      std::snprintf(value, sizeof value, "%.6g", in ? removed.u_offset(k) : removed.y_offset(k));
    else
      std::snprintf(value, sizeof value, "%.6g + %.6g (t - %.6g)", in ? removed.u_offset(k) : removed.y_offset(k),
                    in ? removed.u_slope(k) : removed.y_slope(k), removed.t_ref);
    what += detail::format("{}{} {} {}", j > 0 ? ", " : "", in ? "input" : "output",
                           channel_name(in ? d.input_names() : d.output_names(), k), value);
  }
  return what;
}
}  // namespace

std::string channel_name(const std::vector<std::string>& names, int j) {
  const auto k = static_cast<std::size_t>(j);
  return k < names.size() && !names[k].empty() ? names[k] : std::to_string(j + 1);
}

ChosenRecord choose_record(const std::string& path, const RecordChoice& choice) {
  if (!(choice.ts >= 0) || !std::isfinite(choice.ts))
    throw InvalidOptions(detail::format("the sampling period must be a positive number of seconds (got {})", choice.ts));
  DataSpec spec;
  spec.ts = choice.ts;
  spec.intersample = choice.intersample;
  spec.inputs = choice.inputs;
  spec.outputs = choice.outputs;
  // Column (CSV) or variable (.mat) names; the table is read once.
  const bool is_mat = is_mat_file(path);
  std::optional<CsvTable> tab;
  std::vector<std::string> names;
  if (is_mat) {
    names = mat_variable_names(path);
  } else {
    tab = read_csv(path);
    names = tab->names;
  }
  // Two selections are the same column when they name the same position (CSV) or variable (.mat).
  auto same = [&](const std::string& a, const std::string& b) { return tab ? tab->column(a) == tab->column(b) : a == b; };
  ChosenRecord out;
  // Without a time column and ts, a column named t or time (any case) is the time axis.
  std::string time_col = choice.time;
  if (time_col.empty() && choice.ts == 0.0) {
    for (const auto& n : names) {
      std::string lower = n;
      std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
      if (lower != "t" && lower != "time") continue;
      if (!time_col.empty())
        throw ColumnSelectionError(path + ": columns '" + time_col + "' and '" + n +
                                   "' could both be the time axis; name the time column (ctid: --time)");
      time_col = n;
    }
    if (time_col.empty())
      throw ColumnSelectionError("give the time axis: a time column or the sampling period (ctid: --time COLUMN or --ts "
                                 "SECONDS; no column is named t or time)");
    out.time_column = time_col;
  }
  spec.time = time_col;
  const bool need_output = choice.need_output;
  if (spec.inputs.empty() || (need_output && spec.outputs.empty())) {
    // Default columns: everything that is not the time column, inputs first, output last.
    std::vector<std::string> rest;
    for (const auto& n : names)
      if (time_col.empty() || !same(n, time_col)) rest.push_back(n);
    if (need_output && spec.outputs.empty()) {
      if (rest.size() != 2 && spec.inputs.empty()) {
        std::string cols;
        for (const auto& n : names) cols += (cols.empty() ? "" : ", ") + n;
        throw ColumnSelectionError(path + ": choose the input and output columns (ctid: --input and --output; " +
                                   (is_mat ? "variables: " : "columns: ") + cols + ")");
      }
      if (rest.empty()) throw ColumnSelectionError(path + ": no column left for the output; choose it (ctid: --output)");
      spec.outputs = {rest.back()};
      rest.pop_back();
    }
    if (spec.inputs.empty()) {
      if (need_output) std::erase_if(rest, [&](const std::string& n) { return same(n, spec.outputs.front()); });
      if (rest.empty()) throw ColumnSelectionError(path + ": no column left for the input; choose it (ctid: --input)");
      spec.inputs = need_output ? rest : std::vector<std::string>{rest.front()};
    }
  }
  if (need_output)
    for (const auto& o : spec.outputs)
      for (const auto& in : spec.inputs)
        if (same(o, in)) throw ColumnSelectionError(detail::format("'{}' is selected both as an input and as the output", o));
  if (!need_output) spec.outputs = {spec.inputs.front()};  // placeholder output for loading only
  IdData d = tab ? iddata_from_table(*tab, spec) : load_iddata(path, spec);
  out.file_rows = d.size();
  out.last_row = d.size();
  if (!out.time_column.empty())
    out.notes.push_back(detail::format("column '{}' is the time axis (no time column or sampling period was given)", out.time_column));
  if (d.uniform_time_deviation() > 1e-9) {
    std::string note;
    io_detail::appendf(note, "%s: the sample times are within %.2g Ts of a uniform grid (threshold %g Ts): read as "
                       "uniform, Ts = %.10g s", path.c_str(), d.uniform_time_deviation(), IdData::kUniformTimeTolerance, d.ts());
    out.notes.push_back(std::move(note));
  }
  if (!choice.rows.empty()) {
    const auto [begin, end] = row_range(choice.rows_name, choice.rows, d.size());
    d = d.slice(begin, end);
    out.first_row = begin + 1;
    out.last_row = end;
  }
  out.preprocessing = choice.rows.empty()
                          ? "all " + std::to_string(out.file_rows) + " rows"
                          : detail::format("rows {}..{} of {}", out.first_row, out.last_row, out.file_rows);
  if (!choice.detrend) {
    out.preprocessing += "; no detrending";
    out.data = std::move(d);
    return out;
  }
  out.data = d.detrend(*choice.detrend, &out.removed);
  out.removed_text = removed_text(d, out.removed, *choice.detrend);
  out.preprocessing += detail::format("; {} removed ({})", *choice.detrend == Detrend::Mean ? "means" : "linear trends",
                                      out.removed_text);
  return out;
}

std::vector<std::string> offset_warnings(const IdData& d) {
  std::vector<std::string> out;
  auto check = [&](const Eigen::VectorXd& x, const std::string& name) {
    const double m = x.mean(), sd = std::sqrt((x.array() - m).square().mean());
    if (std::abs(m) <= 0.5 * sd || sd <= 0) return;
    std::string w;
    io_detail::appendf(w, "%s has a mean of %.4g, %.2g times its standard deviation: a linear model through the origin "
                       "cannot fit that offset", name.c_str(), m, std::abs(m) / sd);
    out.push_back(std::move(w));
  };
  for (int j = 0; j < d.nu(); ++j) check(d.u().col(j), "input " + channel_name(d.input_names(), j));
  for (int j = 0; j < d.ny(); ++j) check(d.y().col(j), "output " + channel_name(d.output_names(), j));
  return out;
}

FrequencyData load_frequency_data(const std::string& path, const FrequencyColumns& c, int* rows) {
  const CsvTable t = read_csv(path);
  if (rows) *rows = static_cast<int>(t.values.rows());
  auto col = [&](const std::string& name) { return Eigen::VectorXd(t.values.col(t.column(name))); };
  auto complex = [&](const std::string& re, const std::string& im) -> Eigen::VectorXcd {
    return col(re).cast<std::complex<double>>() + std::complex<double>(0, 1) * col(im);
  };
  const Eigen::VectorXd w = col(c.w);
  const bool spectra = !c.u_re.empty() || !c.u_im.empty() || !c.y_re.empty() || !c.y_im.empty();
  CTID_REQUIRE_OPTION(!spectra || (!c.u_re.empty() && !c.u_im.empty() && !c.y_re.empty() && !c.y_im.empty()),
                      "{}: frequency data from spectra need all four columns u_re, u_im, y_re and y_im", path);
  const Eigen::VectorXcd a = spectra ? complex(c.u_re, c.u_im) : complex(c.re, c.im);
  const Eigen::VectorXcd b = spectra ? complex(c.y_re, c.y_im) : Eigen::VectorXcd();
  try {
    return spectra ? FrequencyData::from_spectra(w, a, b) : FrequencyData(w, a);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(path + ": " + e.what());
  }
}

}  // namespace ctid
