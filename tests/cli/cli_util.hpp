// The command line's tests: running the tool, writing inputs, a clean record, and opening a report in a browser.
#pragma once

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <sys/wait.h>
#include <vector>

#include <gtest/gtest.h>

#include "ctid/ctid.hpp"
#include "test_util.hpp"

namespace ctid_cli_test {
using namespace ctid;

struct CliRun {
  int code;
  std::string out, err;
};

// Runs the CLI (after `prefix`, e.g. "timeout 120 ") with stdout captured and stderr read back.
inline CliRun ctid_run(const std::string& args, const std::string& prefix = "") {
  const std::string errf = test::temp_path("stderr.txt");
  const std::string cmd = prefix + std::string(CTID_CLI_PATH) + " " + args + " 2>" + errf;
  CliRun r{0, "", ""};
  FILE* p = popen(cmd.c_str(), "r");
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), p)) r.out += buf.data();
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream f(errf);
  r.err.assign(std::istreambuf_iterator<char>(f), {});
  return r;
}

inline std::string write(const std::string& name, const std::string& text) {
  const std::string p = test::temp_path(name);
  std::ofstream(p) << text;
  return p;
}

// A clean second-order data set (noise-free, 20 s at 10 ms) written as CSV with a time column.
inline std::string good_csv() {
  static const std::string path = [] {
    const TransferFunction g(Eigen::VectorXd{{3.0}}, Eigen::VectorXd{{1.0, 1.2, 4.0}});
    const int N = 2000;
    PrbsOptions po;
    po.register_length = 9;
    po.clock_period = 10;
    const Eigen::VectorXd u = prbs(N, po), t = time_grid(0.01, N);
    Eigen::MatrixXd m(N, 3);
    m << t, u, lsim(g, u, t);
    const std::string p = test::temp_path("good.csv");
    write_csv(p, {"time", "force", "position"}, m);
    return p;
  }();
  return path;
}

// Runs headless Chromium on a report: the page's self-check line ("plots=N drawn=M errors=E") from the DOM
// after load, the console messages on stderr, and a screenshot. Empty when Chromium is not installed.
struct BrowserRun {
  std::string selfcheck, log;
};
inline std::optional<BrowserRun> open_in_browser(const std::string& html, const std::string& png) {
  if (std::system("command -v chromium >/dev/null 2>&1") != 0) return std::nullopt;
  const std::string flags = "timeout 120 chromium --headless --no-sandbox --disable-gpu --hide-scrollbars "
                            "--enable-logging=stderr --v=0 --virtual-time-budget=10000 --window-size=1100,5000 ";
  const std::string dom = test::temp_path("dom.html"), log = test::temp_path("chromium.log");
  std::system((flags + "--dump-dom " + html + " >" + dom + " 2>" + log).c_str());
  std::system((flags + "--screenshot=" + png + " " + html + " >/dev/null 2>&1").c_str());
  std::ifstream d(dom), l(log);
  const std::string text((std::istreambuf_iterator<char>(d)), {});
  BrowserRun r;
  r.log.assign(std::istreambuf_iterator<char>(l), {});
  const auto at = text.find("id=\"ctid-selfcheck\">");
  if (at != std::string::npos) r.selfcheck = text.substr(at + 20, text.find('<', at + 20) - at - 20);
  return r;
}

// A result of every model type and a record it was not fitted to: each example record split in two (written to dir
// as NAME1.csv and NAME2.csv), the fit (`fit`: its method flags) on the first part. The cases of the tests of the
// initial-state rule (ctid simulate, ctid report).
struct ModelTypeCase {
  std::string type, record, columns, fit;
  DataSpec spec;
};
inline std::vector<ModelTypeCase> model_type_cases(const std::string& dir) {
  std::filesystem::create_directories(dir);
  // Each example record split in two: the fit on the first part, the simulations on the second.
  auto split = [&](const std::string& name, int first) {
    const ExampleData e = example_data(name);
    const int n = static_cast<int>(e.values.rows());
    write_csv(dir + "/" + name + "1.csv", e.columns, e.values.topRows(first));
    write_csv(dir + "/" + name + "2.csv", e.columns, e.values.bottomRows(n - first));
  };
  split("second", 1000);
  split("miso", 1000);
  split("bl", 600);
  split("spring", 900);
  const std::string grey = std::string(CTID_EXAMPLES_DATA_DIR) + "/spring_greybox.json";
  const DataSpec siso{{"u"}, {"y"}, "t"}, bl{{"u"}, {"y"}, "", 0.0025}, spring{{"force"}, {"position"}, "t"};
  return {
      {"transfer_function", "second", "--time t --input u --output y", "--method oe --nf 2 --nb 1", siso},
      {"miso", "miso", "--time t --input u1 --input u2 --output y", "--method srivc --nf 2 --nb 1",
       DataSpec{{"u1", "u2"}, {"y"}, "t"}},
      {"state_space", "second", "--time t --input u --output y", "--method ssest --nx 2", siso},
      {"fsf", "second", "--time t --input u --output y", "--method fsf", siso},
      {"narx", "bl", "--ts 0.0025 --input u --output y", "--method narx --set degree=2 --set ylag=2 --set ulag=2", bl},
      {"nde", "bl", "--ts 0.0025 --input u --output y", "--method kia --set degree=2 --set ylag=2 --set ulag=2", bl},
      {"greybox", "spring", "--time t --input force --output position", "--method greybox --model " + grey, spring},
  };
}

// The case's fit on the first part of its record by `ctid fit`, written to DIR/TYPE.json (returned with the run).
inline std::pair<std::string, CliRun> fit_case(const std::string& dir, const ModelTypeCase& c) {
  const std::string json = dir + "/" + c.type + ".json";
  return {json, ctid_run("fit " + dir + "/" + c.record + "1.csv " + c.columns + " " + c.fit + " --json " + json +
                             " --force", "timeout 300 ")};
}

}  // namespace ctid_cli_test
