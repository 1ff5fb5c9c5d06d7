// ctid batch PATTERN... --method M [ctid fit's options] --out results.csv [--jobs N] [--resume]: one
// method over many records on a pool of threads, one row per record — the library's batch rows and file
// (io/batch_file.hpp), which Python's ctid.batch.fit_many writes too, so that either tool can resume the other's.
#include <glob.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <mutex>
#include <set>
#include <thread>

#include "common.hpp"

namespace ctid::cli {

namespace {

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
  std::vector<std::string> inputs = files;
  inputs.insert(inputs.end(), job.inputs.begin(), job.inputs.end());
  check_output_files({job.out}, inputs, true);  // an input (a record, the model file) is never the rows file
  if (std::filesystem::exists(job.out) && !job.resume && !job.force)
    throw UsageError(job.out + " exists: --resume fits only the records not yet in it, --force replaces it");
  if (job.force && !job.resume) std::filesystem::remove(job.out);
  std::optional<BatchFile> opened;
  try {
    opened.emplace(job.out, job.resume);
  } catch (const InvalidArgument& e) {
    throw UsageError(std::string("--") + e.what());
  } catch (const FileError& e) {
    throw InputError(std::string(e.what()) + " (--resume continues a batch's rows file)");
  }
  BatchFile& writer = *opened;
  std::vector<std::string> todo;
  for (const auto& f : files)
    if (!writer.contains(f)) todo.push_back(f);
  const size_t earlier = files.size() - todo.size();
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const size_t threads = std::min<size_t>(job.jobs > 0 ? static_cast<size_t>(job.jobs) : cores, std::max<size_t>(todo.size(), 1));

  std::mutex mutex;
  std::condition_variable ready;
  std::deque<BatchRow> done;
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
          std::optional<FitOutcome> outcome;
          std::string error;
          const auto start = std::chrono::steady_clock::now();
          bool usage = false;  // a problem of the options (or of this record's columns): exit 2 if every record has it
          try {
            outcome = job.fit_one(todo[i]);
          } catch (const UsageError& e) {
            error = e.what();
            usage = true;
          } catch (const InvalidArgument& e) {  // the library's refusal of an option or of the data's shape
            error = e.what();
            usage = true;
          } catch (const std::exception& e) {
            error = e.what();
          }
          const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          if (g_batch_stop != 0) break;  // interrupted: no row, --resume fits the record again
          BatchRow row = outcome ? batch_row(todo[i], outcome->method, &outcome->result, "", seconds)
                                 : batch_row(todo[i], job.method, nullptr, error, seconds);
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
      std::deque<BatchRow> batch;
      batch.swap(done);
      const bool all_done = finished_workers == threads;
      lock.unlock();
      for (BatchRow& r : batch) {
        const BatchCell* ok = batch_cell(r, "usable");
        failed += !(ok && std::get<bool>(*ok));
        writer.add(std::move(r));
        ++written;
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
  const size_t fitted = writer.rows().size() - earlier;
  if (g_batch_stop != 0) {
    std::fprintf(stderr, "ctid: interrupted: %zu of %zu records are in %s; ctid batch ... --resume fits the %zu others\n",
                 writer.rows().size(), files.size(), job.out.c_str(), files.size() - writer.rows().size());
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
              writer.rows().size() - usable, job.out.c_str());
  return usable == writer.rows().size() ? kOk : kNotUsable;
}

}  // namespace ctid::cli
