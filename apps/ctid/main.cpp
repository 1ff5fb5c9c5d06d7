// ctid — command-line tool. Subcommands: fit, simulate, validate, order, poles, response, gfrf, report, compare, demo, example-data (docs/guide.md).
// Exit codes: 0 ok, 1 estimate not usable, 2 usage, 3 input file error; one line on stderr.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <functional>
#include <unistd.h>

#include "common.hpp"

namespace ctid::cli {

namespace {
volatile std::sig_atomic_t g_sigint = 0;
extern "C" void on_sigint(int) {
  if (g_sigint) std::_Exit(130);  // a second Ctrl-C: stop at once
  g_sigint = 1;
}

// Progress and Ctrl-C for every estimator of the library (core/progress.hpp): the first Ctrl-C asks the
// estimator to stop (it returns its best iterate as "interrupted", exit 1); on a terminal, work that runs for
// more than 1.5 s shows one status line on stderr (stage and iteration), erased at the end.
class CliProgress {
 public:
  CliProgress()
      : tty_(::isatty(STDERR_FILENO) != 0),
        start_(std::chrono::steady_clock::now()),
        scope_([this](const ProgressEvent& e) { return on_event(e); }) {
    std::signal(SIGINT, on_sigint);
  }
  ~CliProgress() {
    if (shown_) std::fprintf(stderr, "\r\033[K");
  }

 private:
  bool on_event(const ProgressEvent& e) {
    const auto now = std::chrono::steady_clock::now();
    if (tty_ && now - start_ > std::chrono::milliseconds(1500) && now - last_ > std::chrono::milliseconds(200)) {
      last_ = now;
      shown_ = true;
      std::fprintf(stderr, "\r\033[Kctid: %s, step %d, %.0f s (Ctrl-C stops)", e.stage, e.iteration,
                   std::chrono::duration<double>(now - start_).count());
    }
    return g_sigint == 0;
  }
  bool tty_, shown_ = false;
  std::chrono::steady_clock::time_point start_, last_{};
  ProgressScope scope_;
};
}  // namespace
}  // namespace ctid::cli

int main(int argc, char** argv) {
  using namespace ctid::cli;
  CLI::App app{"ctid — continuous-time system identification"};
  Command command;  // set by the subcommand parsed
  app.set_version_flag("--version", std::string("ctid ") + ctid::version());
  app.require_subcommand(1);
  setup_fit(*app.add_subcommand("fit", "Estimate a continuous-time model from input/output data"), command);
  setup_batch(*app.add_subcommand("batch", "Fit each of many records with one method (threads); one row per record in a CSV or JSON-lines file"), command);
  setup_simulate(*app.add_subcommand("simulate", "Simulate a model file on the inputs of a data file"), command);
  setup_validate(*app.add_subcommand("validate", "Compare a model with measured data (fit, residual tests)"), command);
  setup_order(*app.add_subcommand("order", "Rank model structures [nb nf nk] by YIC, RT2, AIC or BIC (SRIVC fits)"), command);
  setup_poles(*app.add_subcommand("poles", "Poles from a free response: data-matrix method (El-Shafey) against Prony"), command);
  setup_response(*app.add_subcommand("response", "Nonparametric step, impulse or frequency response (modal functions)"), command);
  setup_gfrf(*app.add_subcommand("gfrf", "Generalised frequency response functions of a NARX or NDE model file"), command);
  setup_report(*app.add_subcommand("report", "Self-contained HTML report of a result file on a record"), command);
  setup_compare(*app.add_subcommand("compare", "Several models on one record side by side (fits, simulations, Bode, step)"), command);
  setup_demo(*app.add_subcommand("demo", "Identify a bundled real data set and print the model"), command);
  setup_example_data(*app.add_subcommand("example-data", "Write a simulated example record the README and docs use"), command);
  std::string typed = "ctid";
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    typed += " " + (s.find_first_of(" \t'\"") == std::string::npos ? s : "'" + s + "'");
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    const int code = app.exit(e);
    std::fputs(fit_method_help(*app.get_subcommand("fit")).c_str(), stdout);
    return code;
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "ctid: %s\n", e.what());
    return kUsage;
  }
  try {
    const CliProgress progress;
    ctid::Provenance provenance = ctid::make_provenance(typed);
    return command ? command(provenance) : kUsage;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "ctid: %s\n", e.what());
    return kUsage;
  } catch (const NotUsable& e) {
    std::fprintf(stderr, "ctid: %s\n", e.what());
    return kNotUsable;
  } catch (const InputError& e) {
    std::fprintf(stderr, "ctid: %s\n", e.what());
    return kInputFile;
  } catch (const ctid::FileError& e) {
    std::fprintf(stderr, "ctid: %s\n", e.what());
    return kInputFile;
  } catch (const ctid::InvalidArgument& e) {
    std::fprintf(stderr, "ctid: %s\n", e.what());
    return kUsage;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ctid: unexpected error: %s\n", e.what());
    return kNotUsable;
  }
}
