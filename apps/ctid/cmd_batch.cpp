// ctid batch PATTERN... --method M [ctid fit's options] --out results.csv [--jobs N] [--resume]: one
// method over many records on a pool of threads, one row per record — the columns of Python's
// ctid.batch.fit_many (python/ctid/batch.py), so that either tool can resume the other's file.
#include <glob.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>

#include "common.hpp"

namespace ctid::cli {

BatchOutcome*& batch_outcome() {
  thread_local BatchOutcome* slot = nullptr;
  return slot;
}

namespace {

// The columns every row has, in this order; then, per parameter NAME, NAME and NAME_std (as fit_many's COLUMNS).
const std::vector<std::string> kColumns = {"id", "method", "model", "orders", "fit_percent", "termination",
                                           "usable", "seconds", "error"};
// Columns holding text (the others are numbers, or True/False for usable).
bool is_text_column(const std::string& c) {
  return c == "id" || c == "method" || c == "model" || c == "orders" || c == "termination" || c == "error";
}

// A row: column name -> text as written in the CSV (numbers in number_text, usable as True/False).
using Row = std::map<std::string, std::string>;

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

// One line of text: a message may span lines, a CSV cell should not.
std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\r', ' ');
  return s;
}

Row row_of(const std::string& id, const std::string& method, const BatchOutcome* outcome, const std::string& error,
           double seconds) {
  Row row = {{"id", id},           {"method", method},  {"model", ""},         {"orders", ""},
             {"fit_percent", "nan"}, {"termination", ""}, {"usable", "False"}, {"seconds", detail::round_trip(seconds)},
             {"error", one_line(error)}};
  if (!outcome || !outcome->result) return row;
  const Result<AnyModel>& r = *outcome->result;
  row["model"] = model_type_name(r.model);
  row["orders"] = orders_text(r.model);
  row["fit_percent"] = detail::round_trip(r.fit.fit_percent);
  row["termination"] = to_string(r.summary.termination);
  row["usable"] = r.usable() ? "True" : "False";
  row["seconds"] = detail::round_trip(r.summary.seconds);
  row["error"] = one_line(r.why_not_usable());
  for (int i = 0; i < r.parameters.size(); ++i) {
    row[r.parameters.names[static_cast<size_t>(i)]] = detail::round_trip(r.parameters.values(i));
    row[r.parameters.names[static_cast<size_t>(i)] + "_std"] = detail::round_trip(r.parameters.std(i));
  }
  return row;
}

// RFC 4180: a cell with a comma, a quote or a line break is quoted, its quotes doubled.
std::string csv_cell(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// The cells of one CSV line (quoted cells as csv_cell writes them).
std::vector<std::string> csv_cells(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
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

// The output file: CSV (rewritten once with a wider header when a row brings new parameter names) or JSON lines
// (appended); one flush per row, so that an interrupted batch keeps every row written.
class RowWriter {
 public:
  RowWriter(std::string path, bool resume) : path_(std::move(path)), columns_(kColumns) {
    jsonl_ = path_.ends_with(".jsonl") || path_.ends_with(".json") || path_.ends_with(".ndjson");
    if (!jsonl_ && !path_.ends_with(".csv"))
      throw UsageError("--out must end in .csv or .jsonl (got '" + path_ + "')");
    if (resume && std::filesystem::exists(path_)) read();
  }
  const std::set<std::string>& ids() const { return ids_; }
  size_t size() const { return rows_.size(); }
  size_t usable() const {
    return static_cast<size_t>(std::count_if(rows_.begin(), rows_.end(), [](const Row& r) {
      const auto it = r.find("usable");
      return it != r.end() && it->second == "True";
    }));
  }

  void add(const Row& row) {
    bool grew = false;
    for (const auto& [k, v] : row)
      if (std::find(columns_.begin(), columns_.end(), k) == columns_.end()) columns_.push_back(k), grew = true;
    rows_.push_back(row);
    ids_.insert(row.at("id"));
    if (jsonl_) {
      append(json_line(row));
    } else if (grew || !std::filesystem::exists(path_)) {
      const std::string tmp = path_ + ".tmp";
      {
        std::ofstream f(tmp, std::ios::trunc);
        f << header() << '\n';
        for (const Row& r : rows_) f << csv_line(r) << '\n';
        if (!f) throw InputError("cannot write " + tmp);
      }
      std::filesystem::rename(tmp, path_);
    } else {
      append(csv_line(row));
    }
  }

 private:
  void append(const std::string& line) {
    std::ofstream f(path_, std::ios::app);
    f << line << '\n';
    f.flush();
    if (!f) throw InputError("cannot write " + path_);
  }
  std::string header() const {
    std::string s;
    for (const auto& c : columns_) s += (s.empty() ? "" : ",") + csv_cell(c);
    return s;
  }
  std::string csv_line(const Row& row) const {
    std::string s;
    for (size_t i = 0; i < columns_.size(); ++i) {
      const auto it = row.find(columns_[i]);
      s += (i ? "," : "") + csv_cell(it == row.end() ? "" : it->second);
    }
    return s;
  }
  static std::string json_line(const Row& row) {
    // A number cell as JSON: NaN (no fit) as null, as Python's writer does.
    const auto number = [](const std::string& v) -> nlohmann::ordered_json {
      const double x = std::strtod(v.c_str(), nullptr);
      return std::isnan(x) ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(x);
    };
    nlohmann::ordered_json j;
    for (const auto& c : kColumns) {
      const std::string& v = row.at(c);
      j[c] = is_text_column(c) ? nlohmann::ordered_json(v) : c == "usable" ? nlohmann::ordered_json(v == "True") : number(v);
    }
    for (const auto& [k, v] : row)
      if (std::find(kColumns.begin(), kColumns.end(), k) == kColumns.end()) j[k] = number(v);
    return j.dump();
  }
  // The rows of an earlier run (--resume): their ids are skipped, their cells kept for a rewrite.
  void read() {
    std::ifstream f(path_);
    std::string line;
    int lineno = 0;
    if (jsonl_) {
      while (std::getline(f, line)) {
        ++lineno;
        if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
        try {
          const auto j = nlohmann::ordered_json::parse(line);
          Row r;
          for (const auto& [k, v] : j.items())
            r[k] = v.is_string() ? v.get<std::string>()
                   : v.is_boolean() ? (v.get<bool>() ? "True" : "False")
                   : v.is_number() ? detail::round_trip(v.get<double>())
                                   : "nan";
          ids_.insert(j.at("id").get<std::string>());
          rows_.push_back(std::move(r));
        } catch (const std::exception&) {
          throw InputError(detail::format("{}: line {} is not a row of a batch (JSON with an id)", path_, lineno));
        }
      }
      return;
    }
    if (!std::getline(f, line)) return;
    const std::vector<std::string> header = csv_cells(line);
    if (header.empty() || header[0] != "id")
      throw InputError(path_ + ": the first column is '" + (header.empty() ? "" : header[0]) +
                       "', not 'id': not a batch result file (--resume continues one)");
    for (const auto& c : header)
      if (std::find(columns_.begin(), columns_.end(), c) == columns_.end()) columns_.push_back(c);
    while (std::getline(f, line)) {
      ++lineno;
      if (line.empty()) continue;
      const std::vector<std::string> cells = csv_cells(line);
      Row r;
      for (size_t i = 0; i < header.size() && i < cells.size(); ++i) r[header[i]] = cells[i];
      ids_.insert(r["id"]);
      rows_.push_back(std::move(r));
    }
  }

  std::string path_;
  bool jsonl_ = false;
  std::vector<std::string> columns_;
  std::vector<Row> rows_;
  std::set<std::string> ids_;
};

// The files of the patterns in order, each once: a pattern with * ? [ is expanded here (quoted, it can match more
// files than a shell command line holds) and must match; a plain name is kept as given (a missing file is its row's
// error, as any other unreadable record).
std::vector<std::string> expand(const std::vector<std::string>& patterns) {
  std::vector<std::string> files;
  std::set<std::string> seen;
  for (const auto& p : patterns) {
    if (p.find_first_of("*?[") == std::string::npos) {
      if (seen.insert(p).second) files.push_back(p);
      continue;
    }
    glob_t g{};
    const int rc = ::glob(p.c_str(), 0, nullptr, &g);
    if (rc == GLOB_NOMATCH) {
      ::globfree(&g);
      throw UsageError("the pattern '" + p + "' matches no file");
    }
    if (rc != 0) {
      ::globfree(&g);
      throw UsageError("the pattern '" + p + "' cannot be expanded (a directory is not readable)");
    }
    for (size_t i = 0; i < g.gl_pathc; ++i)
      if (seen.insert(g.gl_pathv[i]).second) files.push_back(g.gl_pathv[i]);
    ::globfree(&g);
  }
  return files;
}

volatile std::sig_atomic_t g_batch_stop = 0;
void on_batch_sigint(int) { g_batch_stop = 1; }

}  // namespace

int run_batch(const BatchJob& job) {
  const std::vector<std::string> files = expand(job.patterns);
  if (std::filesystem::exists(job.out) && !job.resume && !job.force)
    throw UsageError(job.out + " exists: --resume fits only the records not yet in it, --force replaces it");
  check_outputs({job.out}, files, true);
  if (job.force && !job.resume) std::filesystem::remove(job.out);
  RowWriter writer(job.out, job.resume);
  std::vector<std::string> todo;
  for (const auto& f : files)
    if (!writer.ids().count(f)) todo.push_back(f);
  const size_t earlier = files.size() - todo.size();
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const size_t threads = std::min<size_t>(job.jobs > 0 ? static_cast<size_t>(job.jobs) : cores, std::max<size_t>(todo.size(), 1));

  std::mutex mutex;
  std::condition_variable ready;
  std::deque<Row> done;
  std::atomic<size_t> next{0};
  size_t finished_workers = 0;
  std::set<std::string> usage_errors;  // the distinct usage errors of the records
  bool any_other = false;              // a record fitted, or failed otherwise
  g_batch_stop = 0;
  const auto previous = std::signal(SIGINT, on_batch_sigint);
  const auto t0 = std::chrono::steady_clock::now();
  {
    std::vector<std::jthread> pool;
    for (size_t w = 0; w < threads; ++w)
      pool.emplace_back([&] {
        // A fit polls this between its steps: Ctrl-C stops the fits in progress, whose rows are then dropped.
        const ProgressScope stop([](const ProgressEvent&) { return g_batch_stop == 0; });
        for (size_t i; g_batch_stop == 0 && (i = next++) < todo.size();) {
          BatchOutcome outcome;
          batch_outcome() = &outcome;
          std::string error;
          const auto start = std::chrono::steady_clock::now();
          bool usage = false;  // a problem of the options (or of this record's columns): exit 2 if every record has it
          try {
            job.fit_one(todo[i]);
          } catch (const UsageError& e) {
            error = e.what();
            usage = true;
          } catch (const std::exception& e) {
            error = e.what();
          }
          batch_outcome() = nullptr;
          const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          if (g_batch_stop != 0) break;  // interrupted: no row, --resume fits the record again
          if (!outcome.result && error.empty()) error = "the fit gave no result";
          Row row = row_of(todo[i], outcome.result ? outcome.method : job.method, &outcome, error, seconds);
          std::lock_guard lock(mutex);
          if (usage) usage_errors.insert(error);
          else any_other = true;
          done.push_back(std::move(row));
          ready.notify_one();
        }
        std::lock_guard lock(mutex);
        ++finished_workers;
        ready.notify_one();
      });
    const bool tty = ::isatty(STDERR_FILENO) != 0;
    size_t written = 0, failed = 0;
    auto last_shown = t0;
    for (;;) {
      std::unique_lock lock(mutex);
      ready.wait_for(lock, std::chrono::milliseconds(200), [&] { return !done.empty() || finished_workers == threads; });
      std::deque<Row> batch;
      batch.swap(done);
      const bool all_done = finished_workers == threads;
      lock.unlock();
      for (const Row& r : batch) {
        writer.add(r);
        ++written;
        failed += r.at("usable") != "True";
      }
      const auto now = std::chrono::steady_clock::now();
      if (tty && (now - last_shown > std::chrono::milliseconds(500) || all_done)) {
        std::fprintf(stderr, "\r\033[Kctid batch: %zu/%zu records, %zu not usable or failed%s", written, todo.size(), failed,
                     all_done ? "\n" : "");
        last_shown = now;
      }
      if (all_done && batch.empty()) break;
    }
  }
  std::signal(SIGINT, previous);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const size_t fitted = writer.size() - earlier;
  if (g_batch_stop != 0) {
    std::fprintf(stderr, "ctid: interrupted: %zu of %zu records are in %s; ctid batch ... --resume fits the %zu others\n",
                 writer.size(), files.size(), job.out.c_str(), files.size() - writer.size());
    return 130;
  }
  if (fitted > 0 && !any_other && usage_errors.size() == 1) {
    if (earlier == 0) std::filesystem::remove(job.out);  // this run's rows only, each the same error
    std::fprintf(stderr, "ctid: every record failed with: %s\n", usage_errors.begin()->c_str());
    return kUsage;
  }
  const size_t usable = writer.usable();  // over every row of the file, an earlier run's too
  std::printf("ctid batch: %zu records (%zu fitted now on %zu thread(s) in %.3g s, %.4g records/s; %zu from an earlier run): "
              "%zu usable, %zu not usable or failed (the error column says why); rows in %s\n",
              files.size(), fitted, threads, wall, wall > 0 ? static_cast<double>(fitted) / wall : 0.0, earlier, usable,
              writer.size() - usable, job.out.c_str());
  return usable == writer.size() ? kOk : kNotUsable;
}

}  // namespace ctid::cli
