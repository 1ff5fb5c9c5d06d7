// ctid — batch rows and their file (io/batch_file.hpp).
#include "ctid/io/batch_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

#include <nlohmann/json.hpp>

#include "ctid/core/check.hpp"
#include "ctid/core/error.hpp"
#include "ctid/model/miso.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

namespace {

using batch_json = nlohmann::ordered_json;
constexpr double kNone = std::numeric_limits<double>::quiet_NaN();

bool is_text_column(const std::string& c) {
  return c == "id" || c == "method" || c == "model" || c == "orders" || c == "termination" || c == "error";
}

std::string orders_text(const AnyModel& m) {
  auto tf = [](const TransferFunction& g) {
    std::string s = detail::format("nb={} nf={}", g.num().coefficients().size(), g.den().coefficients().size() - 1);
    if (g.io_delay() != 0) {
      char b[48];
      std::snprintf(b, sizeof b, " delay=%.6g", g.io_delay());
      s += b;
    }
    return s;
  };
  if (const auto* g = std::get_if<TransferFunction>(&m)) return tf(*g);
  if (const auto* ss = std::get_if<StateSpace>(&m)) return detail::format("nx={}", ss->A().rows());
  if (const auto* mi = std::get_if<MisoModel>(&m)) {
    std::string s;
    for (const auto& g : mi->channels) s += (s.empty() ? "" : "; ") + tf(g);
    return s;
  }
  return "";
}

// A message may span lines; a cell does not.
std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\r', ' ');
  return s;
}

std::string cell_text(const BatchCell& c) {
  if (const auto* s = std::get_if<std::string>(&c)) return *s;
  if (const auto* x = std::get_if<double>(&c)) return detail::round_trip(*x);
  if (const auto* i = std::get_if<std::int64_t>(&c)) return std::to_string(*i);
  return std::get<bool>(c) ? "True" : "False";
}

batch_json cell_json(const BatchCell& c) {
  if (const auto* s = std::get_if<std::string>(&c)) return *s;
  if (const auto* x = std::get_if<double>(&c)) return std::isnan(*x) ? batch_json(nullptr) : batch_json(*x);
  if (const auto* i = std::get_if<std::int64_t>(&c)) return *i;
  return std::get<bool>(c);
}

// A CSV cell read back: text columns as text, usable as yes/no, the others as numbers ("" as NaN).
BatchCell cell_from_text(const std::string& column, const std::string& v, const std::string& where) {
  if (is_text_column(column)) return v;
  if (column == "usable") return v == "True" || v == "true" || v == "1";
  if (v.empty()) return kNone;
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (end == v.c_str() || *end != '\0')
    throw FileError(detail::format("{}: column '{}' holds '{}', not a number", where, column, v));
  return x;
}

BatchCell cell_from_json(const batch_json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_boolean()) return v.get<bool>();
  if (v.is_number_integer()) return v.get<std::int64_t>();
  if (v.is_number()) return v.get<double>();
  return kNone;
}

// RFC 4180: a cell with a comma, a quote or a line break is quoted, its quotes doubled.
std::string csv_cell(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::vector<std::string> csv_cells(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') cells.back() += '"', ++i;
      else if (c == '"') quoted = false;
      else cells.back() += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      cells.emplace_back();
    } else if (c != '\r') {
      cells.back() += c;
    }
  }
  return cells;
}

}  // namespace

const std::vector<std::string>& batch_columns() {
  static const std::vector<std::string> c = {"id",          "method", "model",   "orders", "fit_percent",
                                             "termination", "usable", "seconds", "error"};
  return c;
}

BatchRow batch_row(const std::string& id, const std::string& method, const Result<AnyModel>* r,
                   const std::string& error, double seconds) {
  BatchRow row = {{"id", id},          {"method", method},  {"model", std::string()}, {"orders", std::string()},
                  {"fit_percent", kNone}, {"termination", std::string()}, {"usable", false}, {"seconds", seconds},
                  {"error", one_line(error)}};
  if (!r) return row;
  row[2].second = std::string(model_type_name(r->model));
  row[3].second = orders_text(r->model);
  row[4].second = r->fit.fit_percent;
  row[5].second = std::string(to_string(r->summary.termination));
  row[6].second = r->usable();
  row[7].second = r->summary.seconds;
  row[8].second = one_line(r->why_not_usable());
  const ParameterSet& p = r->parameters;
  for (int i = 0; i < p.size(); ++i) {
    const std::string& name = p.names[static_cast<std::size_t>(i)];
    row.emplace_back(name, p.values(i));
    row.emplace_back(name + "_std", i < p.std.size() ? p.std(i) : kNone);
  }
  return row;
}

const BatchCell* batch_cell(const BatchRow& row, const std::string& column) {
  for (const auto& [name, cell] : row)
    if (name == column) return &cell;
  return nullptr;
}

BatchFile::BatchFile(std::string path, bool resume) : path_(std::move(path)), columns_(batch_columns()) {
  jsonl_ = path_.ends_with(".jsonl") || path_.ends_with(".json") || path_.ends_with(".ndjson");
  if (!jsonl_ && !path_.ends_with(".csv"))
    throw InvalidArgument("out must end in .csv or .jsonl (got '" + path_ + "')");  // the file is 'out' in both front ends
  if (resume && std::filesystem::exists(path_)) read();
}

std::size_t BatchFile::usable() const {
  return static_cast<std::size_t>(std::count_if(rows_.begin(), rows_.end(), [](const BatchRow& r) {
    const BatchCell* c = batch_cell(r, "usable");
    return c && std::holds_alternative<bool>(*c) && std::get<bool>(*c);
  }));
}

void BatchFile::add(BatchRow row) {
  const BatchCell* id = batch_cell(row, "id");
  if (!id || !std::holds_alternative<std::string>(*id)) throw InvalidArgument("a batch row needs a text cell 'id'");
  bool grew = false;
  for (const auto& [name, cell] : row)
    if (std::find(columns_.begin(), columns_.end(), name) == columns_.end()) columns_.push_back(name), grew = true;
  ids_.insert(std::get<std::string>(*id));
  rows_.push_back(std::move(row));
  const BatchRow& r = rows_.back();
  if (jsonl_) {
    batch_json j = batch_json::object();
    for (const auto& [name, cell] : r) j[name] = cell_json(cell);
    append(j.dump());
  } else if (grew || !std::filesystem::exists(path_)) {
    const std::string tmp = path_ + ".tmp";
    {
      std::ofstream f(tmp, std::ios::trunc);
      std::string header;
      for (const auto& c : columns_) header += (header.empty() ? "" : ",") + csv_cell(c);
      f << header << '\n';
      for (const BatchRow& x : rows_) f << csv_line(x) << '\n';
      if (!f) throw FileError("cannot write " + tmp);
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path_, ec);
    if (ec) throw FileError("cannot write " + path_ + ": " + ec.message());
  } else {
    append(csv_line(r));
  }
}

void BatchFile::append(const std::string& line) const {
  std::ofstream f(path_, std::ios::app);
  f << line << '\n';
  f.flush();
  if (!f) throw FileError("cannot write " + path_);
}

std::string BatchFile::csv_line(const BatchRow& row) const {
  std::string s;
  for (std::size_t i = 0; i < columns_.size(); ++i) {
    const BatchCell* c = batch_cell(row, columns_[i]);
    s += (i ? "," : "") + csv_cell(c ? cell_text(*c) : "");
  }
  return s;
}

// The rows of an earlier run (resume): their ids are skipped, their cells kept for a rewrite.
void BatchFile::read() {
  std::ifstream f(path_);
  if (!f) throw FileError("cannot read " + path_);
  std::string line;
  int lineno = 0;
  if (jsonl_) {
    while (std::getline(f, line)) {
      ++lineno;
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      BatchRow r;
      try {
        const batch_json j = batch_json::parse(line);
        for (const auto& [k, v] : j.items()) r.emplace_back(k, cell_from_json(v));
        ids_.insert(j.at("id").get<std::string>());
      } catch (const std::exception&) {
        throw FileError(detail::format("{}: line {} is not a row of a batch (JSON with an id)", path_, lineno));
      }
      for (const auto& [name, cell] : r)
        if (std::find(columns_.begin(), columns_.end(), name) == columns_.end()) columns_.push_back(name);
      rows_.push_back(std::move(r));
    }
    return;
  }
  if (!std::getline(f, line)) return;
  ++lineno;
  const std::vector<std::string> header = csv_cells(line);
  if (header.empty() || header[0] != "id")
    throw FileError(path_ + ": the first column is '" + (header.empty() ? "" : header[0]) +
                    "', not 'id': not a batch result file");
  for (const auto& c : header)
    if (std::find(columns_.begin(), columns_.end(), c) == columns_.end()) columns_.push_back(c);
  while (std::getline(f, line)) {
    ++lineno;
    if (line.empty()) continue;
    const std::vector<std::string> cells = csv_cells(line);
    BatchRow r;
    const std::string where = detail::format("{} line {}", path_, lineno);
    for (std::size_t i = 0; i < header.size() && i < cells.size(); ++i)
      r.emplace_back(header[i], cell_from_text(header[i], cells[i], where));
    ids_.insert(std::get<std::string>(*batch_cell(r, "id")));
    rows_.push_back(std::move(r));
  }
}

}  // namespace ctid
