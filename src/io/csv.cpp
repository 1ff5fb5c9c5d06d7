#include "ctid/io/csv.hpp"

#include <limits>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string_view>

#include "ctid/core/check.hpp"
#include "ctid/io/file.hpp"
#include "ctid/model/fsf.hpp"
#include "ctid/validate/uncertainty.hpp"

namespace ctid {

int CsvTable::column(const std::string& key) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == key) return static_cast<int>(i);
  char* end = nullptr;
  const long pos = std::strtol(key.c_str(), &end, 10);
  if (!key.empty() && end && *end == '\0') {
    if (pos >= 1 && pos <= static_cast<long>(names.size())) return static_cast<int>(pos - 1);
    throw ColumnSelectionError(detail::format("{}: column position {} is outside 1..{}", source, pos, names.size()));
  }
  std::string known;
  for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
  throw ColumnSelectionError(detail::format("{}: no column named '{}' (columns: {})", source, key, known));
}

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\"");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\"");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& line, char delim) {
  std::vector<std::string> out;
  if (delim == ' ') {
    std::istringstream is(line);
    std::string f;
    while (is >> f) out.push_back(f);
    return out;
  }
  std::string cur;
  for (char c : line) {
    if (c == delim) { out.push_back(trim(cur)); cur.clear(); }
    else cur += c;
  }
  out.push_back(trim(cur));
  return out;
}

// A field as it may appear in a one-line message: control and non-ASCII bytes as \xNN, at most 40 characters.
std::string printable(const std::string& s) {
  std::string out;
  for (unsigned char c : s) {
    if (out.size() >= 40) return out + "...";
    if (c >= 0x20 && c < 0x7f) out += static_cast<char>(c);
    else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", c);
      out += hex;
    }
  }
  return out;
}

bool parse_number(const std::string& s, double& v) {
  if (s.empty()) return false;
  errno = 0;
  char* end = nullptr;
  v = std::strtod(s.c_str(), &end);
  return end && *end == '\0';
}

}  // namespace

CsvTable parse_csv(const std::string& text_in, const std::string& source, const CsvReadOptions& o) {
  CsvTable t;
  t.source = source;
  // What is not a text table is named, not parsed field by field.
  if (text_in.size() >= 2 && static_cast<unsigned char>(text_in[0]) == 0x1f && static_cast<unsigned char>(text_in[1]) == 0x8b)
    throw FileError(detail::format("{}: the file is gzip-compressed; decompress it first (gunzip)", source));
  if (text_in.rfind("\x89HDF", 0) == 0 || text_in.rfind("MATLAB", 0) == 0)
    throw FileError(detail::format("{}: this is a MATLAB .mat file, not a text table; name it *.mat", source));
  if (text_in.find('\0') != std::string::npos)
    throw FileError(detail::format("{}: the file is binary (it holds NUL bytes), not a text table", source));
  // A UTF-8 byte-order mark (spreadsheet exports) is not part of the first field.
  const std::string_view text = std::string_view(text_in).substr(text_in.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0);
  std::istringstream in{std::string(text)};
  std::string line;
  int lineno = 0;
  char delim = o.delimiter == '\t' ? ' ' : o.delimiter;
  bool first = true;
  std::vector<std::vector<double>> rows;
  std::size_t ncol = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.size() > kMaxLineBytes)
      throw FileError(detail::format("{}:{}: the line has {} bytes, more than the limit of {} (is this a text table?)", source,
                                     lineno, line.size(), kMaxLineBytes));
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto p = line.find_first_not_of(" \t");
    if (p == std::string::npos) continue;
    if (o.comment_chars.find(line[p]) != std::string::npos) continue;
    if (delim == 0) delim = line.find(',') != std::string::npos ? ',' : (line.find(';') != std::string::npos ? ';' : ' ');
    std::vector<std::string> f = split(line, delim);
    // Trailing delimiters ("1,2,3,"): the header's are dropped; a row's only beyond the header's width.
    while (!f.empty() && f.back().empty() && (first || f.size() > ncol)) f.pop_back();
    if (first) {
      first = false;
      bool numeric = true;
      double v;
      for (const auto& c : f) numeric = numeric && parse_number(c, v);
      const bool header = o.header == CsvHeader::Yes || (o.header == CsvHeader::Auto && !numeric);
      ncol = f.size();
      if (header) {
        for (std::size_t i = 0; i < f.size(); ++i) t.names.push_back(f[i].empty() ? std::to_string(i + 1) : f[i]);
        for (std::size_t i = 0; i < t.names.size(); ++i)
          for (std::size_t k = 0; k < i; ++k)
            if (t.names[i] == t.names[k])
              throw FileError(detail::format("{}:{}: column name '{}' appears twice (fields {} and {}); names must be unique",
                                             source, lineno, t.names[i], k + 1, i + 1));
        continue;
      }
      for (std::size_t i = 0; i < f.size(); ++i) t.names.push_back(std::to_string(i + 1));
    }
    if (f.size() != ncol)
      throw FileError(detail::format("{}:{}: expected {} fields, found {}", source, lineno, ncol, f.size()));
    std::vector<double> r(ncol);
    for (std::size_t i = 0; i < ncol; ++i) {
      if (f[i].empty()) {  // an empty cell: NaN here; an error only if the column is used (iddata_from_table)
        r[i] = std::numeric_limits<double>::quiet_NaN();
        continue;
      }
      if (!parse_number(f[i], r[i]))
        throw FileError(detail::format("{}:{}: column '{}' (field {}): cannot read '{}' as a number", source, lineno,
                                       printable(t.names[i]), i + 1, printable(f[i])));
      if (!std::isfinite(r[i]))
        throw FileError(detail::format("{}:{}: column '{}' (field {}): value '{}' is not finite", source, lineno,
                                       t.names[i], i + 1, f[i]));
    }
    rows.push_back(std::move(r));
    t.line_numbers.push_back(lineno);
  }
  if (rows.empty()) throw FileError(detail::format("{}: no data rows", source));
  t.values.resize(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(ncol));
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (std::size_t c = 0; c < ncol; ++c) t.values(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = rows[r][c];
  return t;
}

CsvTable read_csv(const std::string& path, const CsvReadOptions& o) { return parse_csv(read_text_file(path), path, o); }

void write_csv(const std::string& path, const std::vector<std::string>& names, const Eigen::MatrixXd& values) {
  CTID_REQUIRE(static_cast<Eigen::Index>(names.size()) == values.cols(), "write_csv: {} names for {} columns", names.size(),
               values.cols());
  std::ostringstream os;
  os.precision(17);
  for (std::size_t i = 0; i < names.size(); ++i) os << (i ? "," : "") << names[i];
  os << "\n";
  for (Eigen::Index r = 0; r < values.rows(); ++r) {
    for (Eigen::Index c = 0; c < values.cols(); ++c) os << (c ? "," : "") << values(r, c);
    os << "\n";
  }
  write_text_file(path, os.str());
}

void write_fsf_responses(const std::string& prefix, const FsfModel& f) {
  const int K = 501;
  Eigen::MatrixXd tm(K, 5);
  for (int i = 0; i < K; ++i) {
    const Eigen::VectorXd t{{f.T() * i / (K - 1)}};
    tm.row(i) << t(0), f.step_response(t)(0), f.step_response_std(t)(0), f.impulse_response(t)(0),
        f.impulse_response_std(t)(0);
  }
  write_csv(prefix + "_time.csv", {"t", "step", "step_std", "impulse", "impulse_std"}, tm);
  const Eigen::VectorXd w = model_frequency_grid(f);
  const Eigen::VectorXcd g = f.frequency_response(w), gs = f.frequency_response_std(w);
  Eigen::MatrixXd fm(w.size(), 7);
  for (Eigen::Index i = 0; i < w.size(); ++i)
    fm.row(i) << w(i), g(i).real(), g(i).imag(), gs(i).real(), gs(i).imag(), std::abs(g(i)),
        std::arg(g(i)) * 180.0 / 3.14159265358979;
  write_csv(prefix + "_freq.csv", {"w", "re", "im", "re_std", "im_std", "mag", "phase_deg"}, fm);
}

}  // namespace ctid
