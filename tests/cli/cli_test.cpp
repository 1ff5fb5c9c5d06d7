// The command line: exit codes and messages of docs/guide.md, and no partial output files.
#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <sys/wait.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "estimate/state_space_fixtures.hpp"
#include "ctid/ctid.hpp"
#include "test_util.hpp"

namespace fs = std::filesystem;
using namespace ctid;

namespace {
struct CliRun {
  int code;
  std::string out, err;
};

// Runs the CLI (after `prefix`, e.g. "timeout 120 ") with stdout captured and stderr read back.
CliRun ctid_run(const std::string& args, const std::string& prefix = "") {
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

std::string write(const std::string& name, const std::string& text) {
  const std::string p = test::temp_path(name);
  std::ofstream(p) << text;
  return p;
}

// A clean second-order data set (noise-free, 20 s at 10 ms) written as CSV with a time column.
std::string good_csv() {
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
}  // namespace

TEST(Cli, HelpAndVersion) {
  for (const char* sub : {"fit", "simulate", "validate", "demo", "poles", "response", "gfrf"}) {
    const CliRun r = ctid_run(std::string(sub) + " --help");
    EXPECT_EQ(r.code, 0) << sub;
    EXPECT_NE(r.out.find("--"), std::string::npos) << sub;
  }
  EXPECT_NE(ctid_run("--version").out.find(ctid::version()), std::string::npos);
  EXPECT_EQ(ctid_run("").code, 2);
}

TEST(Cli, FitWritesJsonThatSimulateAndValidateRead) {
  const std::string json = test::temp_path("fit.json");
  fs::remove(json);
  CliRun r = ctid_run("fit " + good_csv() + " --time time --input force --output position --nf 2 --nb 1 --method lssvf --set tau=0.3 --json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("a1"), std::string::npos);
  const Result<TransferFunction> res = parse_result_json(read_text_file(json));
  // Noise-free data at 10 ms: O(Ts^2) output-interpolation error, about 1e-4 relative.
  EXPECT_NEAR(res.parameters.value("a1"), 1.2, 1e-3);
  EXPECT_NEAR(res.parameters.value("a2"), 4.0, 1e-3);
  EXPECT_NEAR(res.parameters.value("b0"), 3.0, 1e-3);
  // The same file again without --force is refused, and left as it was.
  const std::string before = read_text_file(json);
  r = ctid_run("fit " + good_csv() + " --time time --input force --output position --nf 2 --nb 1 --json " + json);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("exists; use --force"), std::string::npos);
  EXPECT_EQ(read_text_file(json), before);

  const std::string sim = test::temp_path("sim.csv");
  fs::remove(sim);
  r = ctid_run("simulate " + json + " " + good_csv() + " --time time --input force --out " + sim);
  ASSERT_EQ(r.code, 0) << r.err;
  const CsvTable t = read_csv(sim);
  EXPECT_EQ(t.names, (std::vector<std::string>{"t", "force", "y"}));
  const CsvTable g = read_csv(good_csv());
  EXPECT_LT((t.values.col(2) - g.values.col(2)).cwiseAbs().maxCoeff(), 1e-3);

  const std::string vj = test::temp_path("val.json");
  fs::remove(vj);
  r = ctid_run("validate " + json + " " + good_csv() + " --time time --input force --output position --json " + vj);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("fit: 99.9"), std::string::npos) << r.out;
  EXPECT_NE(read_text_file(vj).find("residual_autocorrelation"), std::string::npos);
  EXPECT_EQ(r.out.find("unstable"), std::string::npos) << r.out;
  // An unstable model whose simulation stays finite on the record is scored, with a note naming its poles.
  const std::string slow = write("slow_unstable.json", R"({"type": "transfer_function", "num": [1], "den": [1, -0.1]})");
  r = ctid_run("validate " + slow + " " + good_csv() + " --time time --input force --output position");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("note: the model is unstable; unstable poles: 0.1+0j"), std::string::npos) << r.out;
}

TEST(Cli, BiproperModelsAsInTheLibraryAndShortFitsOfDivergingModels) {
  // nb = nf + 1 (a direct feedthrough) is accepted by SRIVC and tfest in C++ and Python; the CLI accepted it only for
  // strictly proper orders. On the noise-free second-order record the s^2 coefficient comes out 0 (to 1e-3: the
  // O(Ts^2) interpolation error of the record), a1 = 1.2, a2 = 4.
  const std::string json = test::temp_path("biproper.json");
  fs::remove(json);
  CliRun r = ctid_run("fit " + good_csv() + " --time time --input force --output position --nf 2 --nb 3 --method srivc "
                      "--json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  const Result<TransferFunction> res = parse_result_json(read_text_file(json));
  EXPECT_EQ(res.parameters.size(), 5);  // a1, a2, b0, b1, b2
  EXPECT_NEAR(res.parameters.value("b0"), 0.0, 1e-3);
  EXPECT_NEAR(res.parameters.value("a1"), 1.2, 1e-3);
  EXPECT_NEAR(res.parameters.value("a2"), 4.0, 1e-3);
  // LSSVF's regression needs a strictly proper model: refused by the library with its reason.
  r = ctid_run("fit " + good_csv() + " --time time --input force --output position --nf 2 --nb 3 --method lssvf");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("strictly proper"), std::string::npos) << r.err;
  // A model whose simulation grows like e^{5 t} over 20 s: its fit (about -1e43 %) in three significant digits.
  const std::string fast = write("fast_unstable.json", R"({"type": "transfer_function", "num": [1], "den": [1, -5]})");
  r = ctid_run("validate " + fast + " " + good_csv() + " --time time --input force --output position");
  const size_t at = r.out.find("fit: -");
  ASSERT_NE(at, std::string::npos) << r.out;
  EXPECT_NE(r.out.substr(at, 20).find("e+"), std::string::npos) << r.out;
  EXPECT_LT(r.out.find('\n', at) - at, 80u) << r.out;
}

TEST(Cli, AColumnNamedTimeIsTheTimeAxisWhenNoneIsGiven) {
  // good_csv's columns are time, force, position: without --time and --ts the fit is the one with --time time.
  const CliRun with = ctid_run("fit " + good_csv() + " --time time --input force --output position --nf 2 --nb 1");
  const CliRun without = ctid_run("fit " + good_csv() + " --input force --output position --nf 2 --nb 1");
  ASSERT_EQ(without.code, 0) << without.err;
  EXPECT_NE(without.err.find("note: column 'time' is the time axis"), std::string::npos) << without.err;
  const size_t at = with.out.find("fit: ");
  ASSERT_NE(at, std::string::npos) << with.out;
  EXPECT_EQ(without.out.substr(at, 20), with.out.substr(at, 20));
  // Two candidates, or none: a usage error naming them.
  const std::string two = write("two_times.csv", "T,time,u,y\n0,0,1,0\n1,1,0,1\n2,2,1,0\n");
  CliRun r = ctid_run("fit " + two + " --input u --output y");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("columns 'T' and 'time' could both be the time axis"), std::string::npos) << r.err;
  const std::string none = write("no_time.csv", "a,u,y\n0,1,0\n1,0,1\n2,1,0\n");
  r = ctid_run("fit " + none + " --input u --output y");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no column is named t or time"), std::string::npos) << r.err;
}

TEST(Cli, ALoggersClockJitterIsReadAsUniformSamplingWithANote) {
  // good_csv's record with each time moved by +-2.4e-5 Ts (the relative jitter of a real dSPACE log): uniform data
  // (so --nk, which needs a sampling period, is accepted) with a note giving the deviation; the estimate equals the
  // one from exact times to the printed digits.
  const CsvTable g = read_csv(good_csv());
  Eigen::MatrixXd m = g.values;
  for (Eigen::Index k = 0; k < m.rows(); ++k) m(k, 0) += (k % 2 ? 2.4e-5 : -2.4e-5) * 0.01;
  const std::string jittered = test::temp_path("jittered.csv");
  write_csv(jittered, g.names, m);
  const std::string args = " --time time --input force --output position --nf 2 --nb 1 --nk 1 --method srivc";
  const CliRun exact = ctid_run("fit " + good_csv() + args), r = ctid_run("fit " + jittered + args);
  ASSERT_EQ(r.code, exact.code) << r.err;
  // Measured: 4.8e-05 Ts (the grid through the first and last times, themselves moved in opposite directions).
  EXPECT_NE(r.err.find("within 4.8e-05 Ts of a uniform grid (threshold 0.001 Ts): read as uniform"), std::string::npos)
      << r.err;
  EXPECT_EQ(exact.err.find("uniform grid"), std::string::npos) << exact.err;
  const size_t at = exact.out.find("model:"), at_r = r.out.find("model:");
  ASSERT_NE(at, std::string::npos) << exact.out;
  ASSERT_NE(at_r, std::string::npos) << r.out;
  EXPECT_EQ(r.out.substr(at_r, 60), exact.out.substr(at, 60));
}

TEST(Cli, IvsvfAndRlsMethods) {
  CliRun r = ctid_run("fit " + good_csv() + " --time time --input force --output position --nf 2 --nb 1 --method ivsvf");
  EXPECT_EQ(r.code, 0) << r.err;
  const std::string json = test::temp_path("rls.json");
  fs::remove(json);
  r = ctid_run("fit " + good_csv() + " --time time --nf 2 --nb 1 --method rls-svf --set tau=0.3 --set p0=1e8 --json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  // Default columns: time excluded, first remaining column the input, last the output.
  // Noise-free data at 10 ms: measured a1 = 1.19971 (O(Ts^2) interpolation error); tolerance 1e-3.
  const auto res = parse_result_json(read_text_file(json));
  EXPECT_NEAR(res.parameters.value("a1"), 1.2, 1e-3);
  EXPECT_NEAR(res.parameters.value("b0"), 3.0, 1e-3);
}

TEST(Cli, BadInputGivesOneLineAndTheDocumentedExitCode) {
  const std::string base = " --time time --input force --output position ";
  struct Case {
    std::string args;
    int code;
    std::string message;
  };
  const std::string nan_csv = write("nan.csv", "time,force,position\n0,1,2\n0.1,nan,3\n0.2,1,2\n");
  const std::string inf_csv = write("inf.csv", "time,force,position\n0,1,-Inf\n0.1,2,3\n");
  const std::string text_csv = write("text.csv", "time,force,position\n0,1,2\n0.1,abc,3\n");
  const std::string nonincr = write("nonincr.csv", "time,force,position\n0,1,2\n0.2,1,3\n0.1,1,2\n");
  const std::string tiny = write("tiny.csv", "time,force,position\n0,1,2\n0.1,2,3\n0.2,1,2\n");
  const std::vector<Case> cases = {
      {"fit /nonexistent/data.csv" + base, 3, "cannot open '/nonexistent/data.csv'"},
      {"fit " + good_csv() + " --time time --input flow --output position", 2, "no column named 'flow'"},
      {"fit " + text_csv + base, 3, "text.csv:3: column 'force' (field 2): cannot read 'abc' as a number"},
      {"fit " + nan_csv + base, 3, "nan.csv:3: column 'force' (field 2): value 'nan' is not finite"},
      {"fit " + inf_csv + base, 3, "inf.csv:2: column 'position' (field 3): value '-Inf' is not finite"},
      {"fit " + tiny + base + "--method lssvf --nf 2 --set tau=0.1", 2, "3 samples in the criterion cannot determine 4 free parameters"},
      {"fit " + tiny + base + "--method srivc --nb 2 --nf 4", 2, "srivc: 3 samples cannot determine 6 parameters"},
      {"fit " + nonincr + base, 3, "nonincr.csv:4: time column 'time' is not strictly increasing (0.1 after 0.2)"},
      {"fit " + good_csv() + base + "--method lssvf --nf 0", 2, "nf (model order) must be >= 1 (got 0)"},
      {"fit " + good_csv() + base + "--method lssvf --nf -2", 2, "nf (model order) must be >= 1 (got -2)"},
      {"fit " + good_csv() + base + "--method lssvf --set tau=-0.5", 2, "tau must be > 0, or 0 (automatic) (got -0.5 s)"},
      {"fit " + good_csv() + base + "--method rls-svf --set tau=0", 2, "tau must be > 0 (got 0 s)"},
      {"fit " + good_csv() + base + "--method lssvf --set bogus=1", 2, "--set bogus: not a setting of lssvf"},
      {"fit " + good_csv() + base + "--method magic", 2, "magic"},
      {"fit " + write("untimed.csv", "a,force,position\n0,1,0\n1,0,1\n2,1,0\n") + " --input force --output position", 2,
       "--time COLUMN or --ts SECONDS"},
      {"simulate /nonexistent.json " + good_csv() + " --time time --input force", 3, "cannot open '/nonexistent.json'"},
  };
  for (const Case& c : cases) {
    const CliRun r = ctid_run(c.args);
    EXPECT_EQ(r.code, c.code) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\nstderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;  // one clear line
  }
}

TEST(Cli, NoPartialOutputOnFailure) {
  const std::string json = test::temp_path("never.json");
  fs::remove(json);
  const std::string text_csv = write("text2.csv", "time,force,position\n0,1,2\n0.1,abc,3\n");
  CliRun r = ctid_run("fit " + text_csv + " --time time --input force --output position --json " + json);
  EXPECT_EQ(r.code, 3);
  EXPECT_FALSE(fs::exists(json));
  // No excitation: refused (exit 2); the input file is never overwritten.
  const std::string flat = write("flat.csv", "time,force,position\n0,0,0\n0.1,0,0\n0.2,0,0\n0.3,0,0\n0.4,0,0\n0.5,0,0\n");
  r = ctid_run("fit " + flat + " --time time --input force --output position --method lssvf --set tau=1");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("input 'force' is constant (0)"), std::string::npos) << r.err;
  r = ctid_run("fit " + flat + " --time time --input force --output position --method lssvf --set tau=1 --json " + flat + " --force");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("it is the input file"), std::string::npos) << r.err;
  EXPECT_EQ(read_csv(flat).values.rows(), 6);
}

TEST(Cli, DemoRunsOnBundledData) {
  // The demo is ctid fit with its defaults on the first half of the DaISy dryer, validated on the second
  // half (SrivcAuto.HairDryerValidatesAbove85Percent: >= 85 %), and prints that command: run as printed, it gives the
  // same output.
  const CliRun r = ctid_run("demo");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto at = r.out.find("validation on ");
  ASSERT_NE(at, std::string::npos) << r.out;
  double fit = 0;
  const auto f = r.out.find("fit ", r.out.find("):", at));
  ASSERT_EQ(std::sscanf(r.out.c_str() + f, "fit %lf", &fit), 1) << r.out;
  EXPECT_GE(fit, 85.0) << r.out;
  const std::string marker = "the same fit from the command line:\n  ctid ";
  const auto c = r.out.find(marker);
  ASSERT_NE(c, std::string::npos) << r.out;
  const std::string command = r.out.substr(c + marker.size(), r.out.find('\n', c + marker.size()) - c - marker.size());
  EXPECT_NE(r.out.find("\nwhat it did: "), std::string::npos) << r.out;
  // The printed path is relative to the folder the demo ran in: run the command there.
  const CliRun same = ctid_run(command);
  ASSERT_EQ(same.code, 0) << command << "\n" << same.err;
  const std::string fit_part = r.out.substr(r.out.find("srivc-auto chose"), c - r.out.find("srivc-auto chose"));
  // The printed model, fit and validation of the demo are the command's output, line for line (bar the timing).
  auto without_time = [](std::string s) {
    const auto t = s.find("termination:");
    if (t != std::string::npos) s.erase(t, s.find('\n', t) - t);
    while (!s.empty() && s.back() == '\n') s.pop_back();
    return s;
  };
  EXPECT_EQ(without_time(fit_part), without_time(same.out));
}

TEST(Cli, SamplesAndValidateHoldOutPartOfARecord) {
  // --samples A:B selects the estimation rows; --validate-samples (of the same file) or --validate FILE a held-out
  // record, from which the estimation record's means are removed. The printed validation fit is the library's:
  // srivc on rows 1..500 minus their means, simulated on rows 501..1000 minus the same means from the initial state
  // that fits them best (validation_initial_condition).
  const std::string dryer = std::string(CTID_EXAMPLES_DATA_DIR) + "/dryer.dat";
  const std::string base = " --ts 0.08 --input 1 --output 2 --detrend mean --method srivc --nb 1 --nf 2 --nk 2 ";
  DataSpec spec;
  spec.ts = 0.08;
  spec.inputs = {"1"};
  spec.outputs = {"2"};
  const IdData all = iddata_from_table(read_csv(dryer), spec);
  TrendInfo trend;
  const IdData est = all.slice(0, 500).detrend(Detrend::Mean, &trend);
  const IdData val = all.slice(500, 1000).remove_trend(trend);
  const Result<TransferFunction> lib = srivc(est, {1, 2, 2});
  SimulateOptions so;
  so.initial = InitialCondition::Estimated;
  const std::string expected =
      "fit " + fit_percent_text(fit_percent(val.y().col(0), simulate(AnyModel(lib.model), val, so).y.col(0))) + " %";
  CliRun r = ctid_run("fit " + dryer + base + "--samples 1:500 --validate-samples 501:");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("samples: 500 "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("validation on " + dryer + " rows 501..1000 (500 samples, initial state: the one that fits them best): " +
                       expected),
            std::string::npos)
      << r.out << "\nexpected " << expected;
  // The same held-out rows as a file of their own.
  Eigen::MatrixXd second(500, 2);
  second << all.slice(500, 1000).u(), all.slice(500, 1000).y();
  const std::string held = test::temp_path("dryer_second_half.csv");
  write_csv(held, {"u", "y"}, second);
  r = ctid_run("fit " + dryer + base + "--samples :500 --validate " + held);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("validation on " + held + " (500 samples"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(expected), std::string::npos) << r.out;
  // The report shows the held-out record in a section of its own.
  const std::string html = test::temp_path("held_out.html");
  fs::remove(html);
  r = ctid_run("fit " + dryer + base + "--samples 1:500 --validate-samples 501: --report " + html);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string page = read_text_file(html);
  EXPECT_NE(page.find("Record 2: validation, " + dryer + " rows 501..1000"), std::string::npos);
  // The report says how the data were treated (the dryer's first 500 inputs average 4.994) and what made it.
  EXPECT_NE(page.find("<td>preprocessing</td><td>" + dryer + ": rows 1..500 of 1000; means removed (input 1 4.994,"),
            std::string::npos);
  EXPECT_NE(page.find("<td>command</td><td>ctid fit " + dryer + base), std::string::npos);
  EXPECT_NE(page.find("<td>made by</td><td>ctid " + std::string(version())), std::string::npos);
  // Bad ranges and flags: one line naming the option, the value and the record's size; exit 2.
  for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
           {"--samples 0:10", "--samples 0:10: '0' is not a row number from 1 to 1000 (the record has 1000 rows)"},
           {"--samples 1:5000", "'5000' is not a row number from 1 to 1000"},
           {"--samples 7:7", "--samples 7:7: the range holds fewer than 2 rows"},
           {"--samples 500", "--samples 500: give A:B"},
           {"--validate-samples 1:x", "--validate-samples 1:x: 'x' is not a row number"}}) {
    r = ctid_run("fit " + dryer + base + args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_NE(r.err.find(says), std::string::npos) << args << ": " << r.err;
  }
  r = ctid_run("fit " + dryer + " --ts 0.08 --input 1 --output 2 --method narx --validate-samples 501:");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("ctid validate RESULT.json DATA"), std::string::npos) << r.err;
  r = ctid_run("fit " + dryer + base + "--validate " + dryer + " --json " + dryer + " --force");
  EXPECT_EQ(r.code, 2);  // an output that is an input file is refused before any work
}

TEST(Cli, WithoutMethodAndOrdersTheDefaultChoosesTheStructureAndRemovesTheMeans) {
  // `ctid fit DATA` on the bundled hair dryer (DaISy; no header: column 1 the input, 2 the output) runs
  // srivc-auto, says on its first line which structure it chose, removes the means with a note naming them, and its
  // model validates on the record's second half as SrivcAuto.HairDryerValidatesAbove85Percent does in the library.
  const std::string dryer = std::string(CTID_EXAMPLES_DATA_DIR) + "/dryer.dat";
  const std::string json = test::temp_path("auto.json");
  fs::remove(json);
  const CliRun r = ctid_run("fit " + dryer + " --ts 0.08 --input 1 --output 2 --json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("srivc-auto chose SRIVC with nb = ", 0), 0u) << r.out;  // the first line
  EXPECT_NE(r.out.find("the least BIC of 12 structures"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("note: the means were removed (input 1 "), std::string::npos) << r.err;
  // The first line's orders are the model's.
  const auto res = parse_result_json(read_text_file(json));
  const std::string orders = detail::format("nb = {}, nf = {}", res.model.num().degree() + 1, res.model.den().degree());
  EXPECT_NE(r.out.substr(0, r.out.find('\n')).find(orders), std::string::npos) << r.out;
  EXPECT_NE(r.err.find(", output 2 4.89"), std::string::npos) << r.err;  // the dryer's output mean, 4.8901
  // --detrend none keeps the offset and is warned about (the dryer's output mean is 4.9, 12 times its deviation).
  const CliRun n = ctid_run("fit " + dryer + " --ts 0.08 --input 1 --output 2 --method srivc --nf 2 --detrend none");
  EXPECT_NE(n.err.find("warning: output 2 has a mean of"), std::string::npos) << n.err;
  // Orders without a method: SRIVC with them; orders with srivc-auto: refused, naming the alternative.
  const CliRun o = ctid_run("fit " + dryer + " --ts 0.08 --input 1 --output 2 --detrend mean --nb 2 --nf 2 --nk 2");
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(o.out.rfind("method: srivc ", 0), 0u) << o.out;
  const CliRun bad = ctid_run("fit " + dryer + " --ts 0.08 --input 1 --output 2 --method srivc-auto --nf 2");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("srivc-auto chooses"), std::string::npos) << bad.err;
}

TEST(Cli, DefaultFitOfSeveralInputsChoosesEachChannel) {
  // Several --input and no method: srivc-auto for each channel (srivc_auto_miso; the library's test checks the
  // structures and delays it finds). Here, kept short (no delay search, nf <= 2, 1500 samples): the first line names
  // each input's structure, which must be the model's, and the steps are listed as choices.
  const std::string miso = test::temp_path("auto_miso.csv");
  fs::remove(miso);
  ASSERT_EQ(ctid_run("example-data miso " + miso).code, 0);
  const std::string json = test::temp_path("auto_miso.json");
  fs::remove(json);
  const CliRun r = ctid_run("fit " + miso + " --time t --input u1 --input u2 --output y --samples 1:1500 "
                            "--set try_delay=0 --set nf_max=2 --json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  const Result<MisoModel> m = parse_miso_result_json(read_text_file(json));
  ASSERT_EQ(m.model.channels.size(), 2u);
  char first[128];
  std::snprintf(first, sizeof first, "srivc-auto chose, per input: u1 nb = %d, nf = %d; u2 nb = %d, nf = %d (",
                m.model.channels[0].num().degree() + 1, m.model.channels[0].den().degree(),
                m.model.channels[1].num().degree() + 1, m.model.channels[1].den().degree());
  EXPECT_EQ(r.out.rfind(first, 0), 0u) << r.out << "\nexpected " << first;
  // Without the delay search the 0.15 s and 0.25 s delays show as a zero in the right half plane; nf = 2 is the truth.
  EXPECT_EQ(m.model.channels[0].den().degree(), 2);
  EXPECT_EQ(m.model.channels[1].den().degree(), 2);
  EXPECT_NE(r.out.find("chosen: each input alone: u1: nb = "), std::string::npos) << r.out;
  EXPECT_EQ(ctid_run("fit " + miso + " " + miso + " --time t --input u1 --input u2 --output y").code, 2);
}

TEST(Cli, SrivcTfestWithDelayAndOrderSelection) {
  // Noise-free second order with a 0.137 s delay (13.7 samples) at 10 ms.
  const TransferFunction g(Eigen::VectorXd{{3.0}}, Eigen::VectorXd{{1.0, 1.2, 4.0}}, 0.137);
  const int N = 3000;
  const Eigen::VectorXd u = prbs(N, {.register_length = 9, .clock_period = 10}), t = time_grid(0.01, N);
  Eigen::MatrixXd m(N, 3);
  m << t, u, lsim(g, u, t);
  const std::string csv = test::temp_path("delayed.csv");
  write_csv(csv, {"t", "u", "y"}, m);
  for (const char* method : {"srivc", "tfest"}) {
    const std::string json = test::temp_path(std::string(method) + ".json");
    fs::remove(json);
    const CliRun r = ctid_run("fit " + csv + " --time t --method " + method + " --nb 1 --nf 2 --delay --set delay_max=0.5 --json " + json);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto res = parse_result_json(read_text_file(json));
    // Noise-free: SRIVC's fixed point and the OE optimum are the true model (1e-6 tolerance).
    EXPECT_NEAR(res.model.io_delay(), 0.137, 1e-6) << method;
    EXPECT_NEAR(res.parameters.value("a2"), 4.0, 4e-6) << method;
  }
  // Order selection on the same system with an integer delay of 14 samples.
  const TransferFunction g14(Eigen::VectorXd{{3.0}}, Eigen::VectorXd{{1.0, 1.2, 4.0}}, 0.14);
  m.col(2) = lsim(g14, u, t);
  const std::string csv14 = test::temp_path("delayed14.csv");
  write_csv(csv14, {"t", "u", "y"}, m);
  const CliRun o = ctid_run("order " + csv14 + " --time t --nb 1:2 --nf 1:3 --nk 13:14");
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("   1   1  2 14"), std::string::npos) << o.out;  // rank 1 is [1 2 14]
  // The same ranking as JSON (every command that computes something can write its result).
  const std::string oj = test::temp_path("order.json");
  fs::remove(oj);
  ASSERT_EQ(ctid_run("order " + csv14 + " --time t --nb 1:2 --nf 1:3 --nk 13:14 --rank bic --json " + oj).code, 0);
  const nlohmann::json ord = nlohmann::json::parse(read_text_file(oj));
  EXPECT_EQ(ord.at("type"), "order_selection");
  EXPECT_EQ(ord.at("rank_by"), "bic");
  ASSERT_EQ(ord.at("candidates").size(), 12u);  // nb 1:2 x nf 1:3 (all with nb <= nf + 1) x nk 13:14
  EXPECT_EQ(ord.at("candidates")[0].at("nf"), 2);
  EXPECT_EQ(ord.at("candidates")[0].at("nk"), 14);
  EXPECT_EQ(ord.at("candidates")[0].at("usable"), true);
  EXPECT_EQ(ctid_run("order " + csv14 + " --time t --nf 2 --json " + oj).code, 2);  // exists, no --force
  // Structures that diverge (on the `second` example record nb = 1, nf = 3 reaches RT2 = -5e266) keep the table's
  // columns: every row is at most 100 characters (it was 300 with fixed decimals).
  const std::string second = test::temp_path("second_order.csv");
  fs::remove(second);
  ASSERT_EQ(ctid_run("example-data second " + second).code, 0);
  const CliRun wide = ctid_run("order " + second + " --time t --input u --output y --nb 1:3 --nf 1:4 --nk 0");
  ASSERT_EQ(wide.code, 0) << wide.err;
  std::istringstream rows(wide.out);
  for (std::string row; std::getline(rows, row);) EXPECT_LE(row.size(), 100u) << row;
  EXPECT_EQ(ctid_run("order " + csv + " --time t --nf 3:1").code, 2);
  EXPECT_EQ(ctid_run("order " + csv + " --time t --nf x").code, 2);
  const CliRun bad = ctid_run("fit " + csv + " --time t --method srivc --delay --set delay_min=2 --set delay_max=1");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("delay range [2, 1] s is empty"), std::string::npos) << bad.err;
  EXPECT_EQ(ctid_run("fit " + csv + " --time t --method lssvf --delay").code, 2);
}

TEST(Cli, MisoFitSimulateValidate) {
  // Two inputs, different denominators and delays of 3 and 5 samples, noise-free.
  const TransferFunction g1(Eigen::VectorXd{{4.0}}, Eigen::VectorXd{{1.0, 2.0, 4.0}}, 0.03);
  const TransferFunction g2(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 1.0, 1.0}}, 0.05);
  const int N = 4000;
  Eigen::MatrixXd u(N, 2);
  u.col(0) = prbs(N, {.register_length = 10, .clock_period = 15});
  u.col(1) = prbs(N, {.register_length = 11, .clock_period = 20, .initial_state = 77});
  const Eigen::VectorXd t = time_grid(0.01, N);
  Eigen::MatrixXd m(N, 4);
  m << t, u, lsim(MisoModel{{g1, g2}}, IdData(u, Eigen::VectorXd::Zero(N), 0.01));
  const std::string csv = test::temp_path("miso.csv");
  write_csv(csv, {"t", "u1", "u2", "y"}, m);
  const std::string json = test::temp_path("miso.json");
  fs::remove(json);
  CliRun r = ctid_run("fit " + csv + " --time t --input u1 --input u2 --output y --method srivc --nb 1 --nf 2 --nk 3,5 --json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  const MisoModel mm = std::get<MisoModel>(read_model_json(json));
  ASSERT_EQ(mm.nu(), 2);
  EXPECT_NEAR(mm.channels[1].den().coefficients()(1), 1.0, 1e-6);
  r = ctid_run("validate " + json + " " + csv + " --time t --input u1 --input u2 --output y");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("fit: 100.00"), std::string::npos) << r.out;
  EXPECT_EQ(ctid_run("fit " + csv + " --time t --input u1 --input u2 --output y --method srivc --nf 2,2,2").code, 2);
  EXPECT_EQ(ctid_run("fit " + csv + " --time t --input u1 --input u2 --output y --method oe --nf 2").code, 2);
  // Two records (the two halves, each from its own start: the second does not start at rest, so it is a different
  // experiment than the whole): the CLI's joint fit is the library's srivc_miso on both (to 1e-9 relative).
  const std::string h1 = test::temp_path("miso_h1.csv"), h2 = test::temp_path("miso_h2.csv");
  write_csv(h1, {"t", "u1", "u2", "y"}, m.topRows(N / 2));
  write_csv(h2, {"t", "u1", "u2", "y"}, m.bottomRows(N / 2));
  r = ctid_run("fit " + h1 + " " + h2 + " --time t --input u1 --input u2 --output y --method srivc --nb 1 --nf 2 --nk 3,5 "
               "--json " + json + " --force");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<IdData> halves = {IdData(u.topRows(N / 2), m.col(3).head(N / 2), 0.01),
                                      IdData(u.bottomRows(N / 2), m.col(3).tail(N / 2), 0.01, 0.01 * (N / 2))};
  const Result<MisoModel> lib = srivc_miso(halves, {{1, 2, 3}, {1, 2, 5}});
  const ResultFile back = read_result_file(json);
  ASSERT_EQ(back.result.parameters.size(), lib.parameters.size());
  for (int i = 0; i < lib.parameters.size(); ++i)
    EXPECT_NEAR(back.result.parameters.values(i), lib.parameters.values(i), 1e-9 * std::abs(lib.parameters.values(i)));
}

TEST(Cli, ClosedLoopFit) {
  // Noise-free sampled-data loop (digital PI, ZOH plant input): CLSRIVC returns the plant.
  const TransferFunction G(Eigen::VectorXd{{1.0, 1.0}}, Eigen::VectorXd{{1.0, 0.5, 1.0}});
  const StateSpace ss = G.to_state_space();
  const double Ts = 0.005;
  const int N = 8000;
  const Discretization D = discretize(ss.A(), ss.B(), Ts);
  // Columns t, r, u, y of the loop run from rest with the reference ref.
  auto loop_run = [&](const Eigen::VectorXd& ref) {
    Eigen::MatrixXd out(N, 4);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(2);
    double integral = 0;
    for (int k = 0; k < N; ++k) {
      const double y = (ss.C() * x)(0);
      const double u = ref(k) - (10 * y + 15 * integral);
      integral += Ts * y;
      out.row(k) << k * Ts, ref(k), u, y;
      x = D.Phi * x + D.Gamma0 * u;
    }
    return out;
  };
  const Eigen::VectorXd r = prbs(N, {.register_length = 10, .clock_period = 20});
  const Eigen::MatrixXd m = loop_run(r);
  const std::string csv = test::temp_path("loop.csv");
  write_csv(csv, {"t", "r", "u", "y"}, m);
  const std::string c = test::temp_path("pi.json");
  write_model_json(c, TransferFunction(Eigen::VectorXd{{10.0, 15.0}}, Eigen::VectorXd{{1.0, 0.0}}));
  const std::string json = test::temp_path("loop_fit.json");
  fs::remove(json);
  const CliRun run = ctid_run("fit " + csv + " --time t --input u --output y --method srivc --nb 2 --nf 2 --closed-loop-controller " +
                              c + " --reference r --json " + json);
  ASSERT_EQ(run.code, 0) << run.err;
  const auto res = parse_result_json(read_text_file(json));
  EXPECT_NEAR(res.parameters.value("a1"), 0.5, 1e-6);
  EXPECT_NEAR(res.parameters.value("b1"), 1.0, 1e-6);
  EXPECT_EQ(ctid_run("fit " + csv + " --time t --input u --output y --method srivc --closed-loop-controller " + c).code, 2);
  EXPECT_EQ(ctid_run("fit " + csv + " --time t --input u --output y --method srivc --closed-loop-controller /nonexistent.json --reference r").code, 3);
  // Two DATA files are two experiments of the loop (each from rest, with its own reference column): one joint fit,
  // the library's to 1e-9, the plant to 1e-6 (noise-free).
  const Eigen::MatrixXd m2 = loop_run(prbs(N, {.register_length = 9, .clock_period = 40, .initial_state = 7}));
  const std::string b_csv = test::temp_path("loop_b.csv");
  write_csv(b_csv, {"t", "r", "u", "y"}, m2);
  fs::remove(json);
  const CliRun two = ctid_run("fit " + csv + " " + b_csv + " --time t --input u --output y --method srivc --nb 2 --nf 2 " +
                              "--closed-loop-controller " + c + " --reference r --json " + json);
  ASSERT_EQ(two.code, 0) << two.err;
  EXPECT_NE(two.out.find("experiments: 2"), std::string::npos) << two.out;
  ClosedLoopOptions o;
  o.controller = TransferFunction(Eigen::VectorXd{{10.0, 15.0}}, Eigen::VectorXd{{1.0, 0.0}});
  const auto lib = srivc_closed_loop(std::vector<IdData>{IdData(m.col(2), m.col(3), Ts), IdData(m2.col(2), m2.col(3), Ts)},
                                     {r, m2.col(1)}, {2, 2, 0}, o);
  const auto joint = parse_result_json(read_text_file(json));
  EXPECT_EQ(joint.diagnostics.get(diagnostic::experiments), 2.0);
  for (int i = 0; i < lib.parameters.size(); ++i)
    EXPECT_NEAR(joint.parameters.values(i), lib.parameters.values(i), 1e-9 * std::abs(lib.parameters.values(i)));
  for (const auto& [name, value] : {std::pair{"a1", 0.5}, {"a2", 1.0}, {"b0", 1.0}, {"b1", 1.0}})
    EXPECT_NEAR(joint.parameters.value(name), value, 1e-6) << name;
}

TEST(Cli, FrequencyData) {
  const TransferFunction g(Eigen::VectorXd{{-6400.0, 1600.0}}, Eigen::VectorXd{{1.0, 5.0, 408.0, 416.0, 1600.0}});
  Eigen::VectorXd w(100);
  for (int k = 0; k < 100; ++k) w(k) = 0.1 * std::pow(1000.0, k / 99.0);
  const Eigen::VectorXcd G = g.frequency_response(w);
  Eigen::MatrixXd m(100, 3);
  m << w, G.real(), G.imag();
  const std::string csv = test::temp_path("freq.csv");
  write_csv(csv, {"w", "re", "im"}, m);
  const std::string json = test::temp_path("freq.json");
  fs::remove(json);
  const CliRun r = ctid_run("fit " + csv + " --frequency --method tfest --nb 2 --nf 4 --json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NEAR(parse_result_json(read_text_file(json)).parameters.value("a2"), 408.0, 408e-6);
  // The same data by Johansson's criterion in the frequency domain (RJ 45): exact data give the model (to 1e-6).
  fs::remove(json);
  const CliRun s = ctid_run("fit " + csv + " --frequency --method lssvf --nb 2 --nf 4 --set tau=0.05 --json " + json);
  ASSERT_EQ(s.code, 0) << s.err;
  EXPECT_NE(s.out.find("method: lssvf (frequency data)"), std::string::npos) << s.out;
  EXPECT_NEAR(parse_result_json(read_text_file(json)).parameters.value("a2"), 408.0, 408e-6);
  const CliRun t = ctid_run("fit " + csv + " --frequency --method lssvf --nb 2 --nf 4 --set alpha=1");
  EXPECT_EQ(t.code, 2) << t.err;
  EXPECT_NE(t.err.find("no meaning for frequency data"), std::string::npos) << t.err;
  std::swap(m(10, 0), m(11, 0));  // non-increasing w
  const std::string bad = test::temp_path("freq_bad.csv");
  write_csv(bad, {"w", "re", "im"}, m);
  const CliRun b = ctid_run("fit " + bad + " --frequency --nb 2 --nf 4 --method tfest");
  EXPECT_EQ(b.code, 3);
  EXPECT_NE(b.err.find("frequencies must be strictly increasing (w[11]"), std::string::npos) << b.err;
}

TEST(Cli, GawthropWangFsfAndPhysical) {
  // Unstable circuit 1/(s^2 - 1) under digital PD (Gawthrop & Wang 2005, §5, simulated), noise-free, written as CSV.
  const double Ts = 0.01;
  const int M = 4000;
  Eigen::VectorXd w(M);
  for (int i = 0; i < M; ++i) w(i) = (i / 150) % 3 == 0 ? 0.5 : -0.5;
  const IdData loop = simulate_closed_loop(TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 0.0, -1.0}}),
                                           RstController::pid(3.0, 0.0, 3.0, 0.1, Ts), w, Ts);
  Eigen::MatrixXd m(M, 3);
  m << time_grid(Ts, M), loop.u(), loop.y();
  const std::string csv = test::temp_path("circuit.csv");
  write_csv(csv, {"t", "u", "y"}, m);
  const std::string prefix = test::temp_path("circ");
  fs::remove(prefix + "_time.csv");
  fs::remove(prefix + "_freq.csv");
  CliRun r = ctid_run("fit " + csv + " --time t --method fsf --set T=8 --set n=21 --set a=2 --responses " + prefix);
  ASSERT_EQ(r.code, 0) << r.err;
  const CsvTable step = read_csv(prefix + "_time.csv");
  EXPECT_EQ(step.names, (std::vector<std::string>{"t", "step", "step_std", "impulse", "impulse_std"}));
  // Step response of G(s + 2) = 1/((s+1)(s+3)) reaches 1/3 (spec: within 4-8e-3).
  EXPECT_NEAR(step.values(step.values.rows() - 1, 1), 1.0 / 3.0, 8e-3);
  EXPECT_TRUE(fs::exists(prefix + "_freq.csv"));
  const std::string json = test::temp_path("phys.json");
  fs::remove(json);
  r = ctid_run("fit " + csv + " --time t --method physical --model \"k1/(s^2-k2)\" --param k1=2 --param k2=0 --set T=8 "
               "--set n=21 --set a=2 --json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto res = parse_result_json(read_text_file(json));
  EXPECT_NEAR(res.parameters.value("k1"), 1.0, 0.05);  // within 5 % of (1, 1)
  EXPECT_NEAR(res.parameters.value("k2"), 1.0, 0.05);
  r = ctid_run("fit " + csv + " --time t --method physical --model \"k1/(s^2-k2)\" --param k1=2 --param k2=0 --via raw --set a=2");
  EXPECT_EQ(r.code, 0) << r.err;
  // Declaring the plant unstable is enough; the window, T and n are chosen, printed and recorded.
  fs::remove(json);
  r = ctid_run("fit " + csv + " --time t --method physical --model \"k1/(s^2-k2)\" --param k1=2 --param k2=0 --set unstable=1 "
               "--json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* line : {"chosen: fsf: a = ", "chosen: fsf: T = ", "chosen: fsf: n = "})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << "\n" << r.out;
  const auto automatic = parse_result_json(read_text_file(json));
  EXPECT_EQ(automatic.diagnostics.choices.size(), 3u);
  EXPECT_NEAR(automatic.parameters.value("k1"), 1.0, 0.05);
  EXPECT_NEAR(automatic.parameters.value("k2"), 1.0, 0.05);
  struct Case {
    std::string args, message;
  };
  const std::vector<Case> bad = {
      {"--method fsf --set T=8 --set n=20 --set a=2", "n must be odd and >= 1, or 0: automatic (got 20)"},
      {"--method fsf --set T=8 --set n=0.5", "n must be a whole number"},
      {"--method fsf --set T=80 --set a=2", "longer than the record"},
      {"--method fsf --set T=8 --set a=2 --set b=3", "must not exceed a"},
      {"--method physical --model \"k1/(s^2-k3)\" --param k1=2 --param k2=0 --set T=8 --set a=2",
       "unknown symbol 'k3' (parameters: k1, k2) at column 9"},
      {"--method physical --model \"k1/(s^2-k2\" --param k1=2 --param k2=0 --set T=8 --set a=2", "expected ')' at column 11"},
      {"--method physical --model \"k1/(s^2-k2)\" --param k1=2 --set T=8 --set a=2", "unknown symbol 'k2'"},
  };
  for (const Case& c : bad) {
    const CliRun b = ctid_run("fit " + csv + " --time t " + c.args);
    EXPECT_EQ(b.code, 2) << c.args;
    EXPECT_NE(b.err.find(c.message), std::string::npos) << c.args << "\n" << b.err;
  }
}

namespace {
// El-Shafey Ex. 5.2 input (levels +1, +2, -1, -2 each 80 samples, Ts = pi/320) repeated 4 times, S3 exact.
const TransferFunction kS3(Eigen::VectorXd{{13.0, 52.0}}, Eigen::VectorXd{{1.0, 4.0, 30.0, 52.0}});
constexpr double kTs320 = 3.14159265358979323846 / 320;
std::string steps_csv() {
  const int N = 1280;
  Eigen::VectorXd u(N);
  const double lv[4] = {1, 2, -1, -2};
  for (int i = 0; i < N; ++i) u(i) = lv[(i / 80) % 4];
  Eigen::MatrixXd m(N, 2);
  m << u, lsim(kS3, u, time_grid(kTs320, N));
  const std::string p = test::temp_path("steps.csv");
  write_csv(p, {"u", "y"}, m);
  return p;
}
std::string ts320() { return detail::format("{}", kTs320); }
}  // namespace

TEST(Cli, ModalFitPolesAndResponses) {
  const std::string data = steps_csv(), json = test::temp_path("modal.json");
  fs::remove(json);
  // fit --method modal: Walsh functions on the constant-input windows, Theorem 4.1, numerator by LS (exact data).
  CliRun r = ctid_run("fit " + data + " --ts " + ts320() + " --method modal --nf 3 --nb 2 --set shift_samples=16,32,48 --json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  const LinearModel m = read_model_json(json);
  const auto& tf = std::get<TransferFunction>(m);
  EXPECT_LT((tf.den().coefficients() - kS3.den().coefficients()).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_NEAR(tf.num().coefficient_of_power(0), 52.0, 1e-4);
  // Two DATA files: the second record holds other levels for 96 samples; the joint fit is the
  // library's modal_fit of both records (to 1e-9) and S3 (noise-free, to 1e-5).
  {
    const int N2 = 384;
    Eigen::VectorXd u2(N2);
    const double lv2[4] = {-1.5, 0.5, 2.5, -0.5};
    for (int i = 0; i < N2; ++i) u2(i) = lv2[(i / 96) % 4];
    Eigen::MatrixXd m2(N2, 2);
    m2 << u2, lsim(kS3, u2, time_grid(kTs320, N2));
    const std::string second = test::temp_path("steps2.csv");
    write_csv(second, {"u", "y"}, m2);
    const CliRun j = ctid_run("fit " + data + " " + second + " --ts " + ts320() +
                              " --method modal --nf 3 --nb 2 --set shift_samples=16,32,48 --force --json " + json);
    ASSERT_EQ(j.code, 0) << j.err;
    EXPECT_NE(j.out.find("experiments: 2"), std::string::npos) << j.out;
    const CsvTable t1 = read_csv(data);
    const Result<TransferFunction> lib =
        modal_fit(std::vector<IdData>{IdData(t1.values.col(0), t1.values.col(1), kTs320), IdData(u2, m2.col(1), kTs320)},
                  2, {.shifts = Eigen::Vector3d(16, 32, 48) * kTs320});
    const TransferFunction joint = std::get<TransferFunction>(read_model_json(json));
    EXPECT_LT((joint.den().coefficients() - lib.model.den().coefficients()).cwiseAbs().maxCoeff(), 1e-9 * 52);
    EXPECT_LT((joint.den().coefficients() - kS3.den().coefficients()).cwiseAbs().maxCoeff(), 1e-5);
  }
  // response --kind step: the ES-C11 estimate written as CSV equals the true step response.
  const std::string g = test::temp_path("g.csv");
  fs::remove(g);
  const std::string gj = test::temp_path("g.json");
  fs::remove(gj);
  r = ctid_run("response " + data + " --ts " + ts320() + " --order 3 --kind step --set period=" +
               detail::format("{}", 20 * kTs320) + " --set horizon=5 --out " + g + " --json " + gj);
  ASSERT_EQ(r.code, 0) << r.err;
  const CsvTable t = read_csv(g);
  const Eigen::VectorXd truth = step_response(kS3, t.values.col(0));
  EXPECT_LT((t.values.col(1) - truth).cwiseAbs().maxCoeff(), 1e-8);
  // --json holds the same columns (every computing command writes JSON).
  const auto rj = nlohmann::json::parse(std::ifstream(gj));
  EXPECT_EQ(rj.at("type"), "response");
  EXPECT_EQ(rj.at("kind"), "step");
  EXPECT_EQ(rj.at("order"), 3);
  ASSERT_EQ(rj.at("columns").at("step").size(), static_cast<std::size_t>(t.values.rows()));
  for (Eigen::Index k = 0; k < t.values.rows(); k += 50)
    EXPECT_NEAR(rj.at("columns").at("step").at(k).get<double>(), t.values(k, 1), 1e-12 * (1 + std::abs(t.values(k, 1))));
  // poles: the output of this record after the last switch is not free, so use an S3 free response.
  const int N = 400;
  Eigen::MatrixXd fr(N, 1);
  fr.col(0) = lsim(phase_variable_form(kS3), InputGenerator::constant(0.0), time_grid(kTs320, N), Eigen::Vector3d(1, 0, 0));
  const std::string free = test::temp_path("free.csv");
  write_csv(free, {"y"}, fr);
  r = ctid_run("poles " + free + " --ts " + ts320() + " --order 3 --set shift_samples=20,40,60");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("s^3 + 4 s^2 + 30 s + 52"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Prony"), std::string::npos);
  // The settings are the library's (compare_poles, seconds): shifts in seconds print the same estimates, and a
  // setting in samples says so in its name.
  char shifts_s[128];
  std::snprintf(shifts_s, sizeof shifts_s, "%.17g,%.17g,%.17g", 20 * kTs320, 40 * kTs320, 60 * kTs320);
  const CliRun secs = ctid_run("poles " + free + " --ts " + ts320() + " --order 3 --set shifts=" + shifts_s);
  ASSERT_EQ(secs.code, 0) << secs.err;
  EXPECT_EQ(secs.out, r.out);
  // --json: the same estimates as numbers. S3 = (s + 2)(s^2 + 2 s + 26): noise-free, the characteristic
  // polynomial to 1e-6 (the printed text has 6 digits).
  const std::string pj = test::temp_path("poles.json");
  fs::remove(pj);
  r = ctid_run("poles " + free + " --ts " + ts320() + " --order 3 --set shift_samples=20,40,60 --json " + pj);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json pjs = nlohmann::json::parse(read_text_file(pj));
  EXPECT_EQ(pjs.at("type"), "poles");
  const std::vector<double> cp = pjs.at("data_matrix").at("characteristic");
  ASSERT_EQ(cp.size(), 4u);
  const std::array<double, 4> s3{1, 4, 30, 52};
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(cp[i], s3[i], 1e-6 * 52) << i;
  EXPECT_EQ(pjs.at("data_matrix").at("poles").size(), 3u);
  EXPECT_FALSE(pjs.at("prony").is_null());
  // Without shifts: uniform shifts chosen on Prony's pre-estimate, printed as 'chosen:' and kept in the
  // JSON; noise-free, the same polynomial to its 6 printed digits.
  fs::remove(pj);
  r = ctid_run("poles " + free + " --ts " + ts320() + " --order 3 --json " + pj);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("chosen: shifts = i * "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("s^3 + 4 s^2 + 30 s + 52"), std::string::npos) << r.out;
  const nlohmann::json auto_js = nlohmann::json::parse(read_text_file(pj));
  EXPECT_EQ(auto_js.at("choices").size(), 1u);
  EXPECT_EQ(auto_js.at("shifts").size(), 3u);
  // A response forced by sin 4t (ES Ex. 4.7): order 3 + 2 generator modes, deflated by s^2 + 16.
  Eigen::MatrixXd forced(600, 1);
  forced.col(0) = lsim(kS3.to_state_space(), InputGenerator::sinusoid(4.0, 1.0), time_grid(kTs320, 600));
  const std::string fp = test::temp_path("forced.csv");
  write_csv(fp, {"y"}, forced);
  r = ctid_run("poles " + fp + " --ts " + ts320() + " --order 3 --generator 4 --set shift_samples=30,60,90,120,150");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("s^3 + 4 s^2 + 30 s + 52"), std::string::npos) << r.out;
  // A record whose output never moves: refused before any estimation (exit 2), named.
  Eigen::MatrixXd zero(400, 2);
  zero << Eigen::VectorXd::LinSpaced(400, -1, 1).array().sign().matrix(), Eigen::VectorXd::Zero(400);
  const std::string z = test::temp_path("zero.csv");
  write_csv(z, {"u", "y"}, zero);
  r = ctid_run("fit " + z + " --ts " + ts320() + " --method modal --nf 3 --set shift_samples=16,32,48 --set basis=discrete");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("output 'y' is constant (0)"), std::string::npos) << r.err;
}

TEST(Cli, ModalBadInputs) {
  const std::string data = steps_csv();
  // A window START,LENGTH given in samples of Ts, written in seconds (the setting's unit).
  auto win = [](int start, int length) { return detail::format("{},{}", start * kTs320, length * kTs320); };
  const std::string base = "fit " + data + " --ts " + ts320() + " --method modal --nf 3 ";
  struct Case {
    std::string args, message;
  };
  const std::vector<Case> cases = {
      {base + "--set shift_samples=16,32", "one shift per pole"},
      {base + "--set shift_samples=32,16,48", "increasing"},
      {base + "--set shift_samples=16.5,32,48", "whole number of samples"},
      {base + "--set shifts=0.1,0.2,0.3", "not a whole multiple of the sampling period"},
      {base + "--set shifts=1e-3,2e-3,3e-3 --set shift_samples=1,2,3", "either shifts (seconds) or shift_samples"},
      {base + "--set shift_samples=16,32,48 --set basis=walsh --set functions=6", "power of two"},
      {base + "--set shift_samples=16,32,48 --set basis=fourier --set functions=2 --set windows=" + win(60, 19),
       "Fourier functions for"},
      {base + "--set shift_samples=16,32,48 --set basis=discrete --set windows=" + win(60, 2), "equations"},
      {base + "--set shift_samples=16,32,48 --set windows=0.1", "windows are pairs START,LENGTH"},
      {base + "--set shift_samples=16,32,48 --set colour=red", "not a setting of modal"},
      {base + "--set shift_samples=16,32,48 --set iv=2", "not a setting of modal; did you mean 'iv_shift'?"},
      {"poles " + data + " --ts " + ts320() + " --output y --order 3 --set shift_samples=16,32", "2 shifts; order 3 needs 3"},
      {"response " + data + " --ts " + ts320() + " --order 3 --kind step", "period"},
  };
  for (const auto& c : cases) {
    const CliRun r = ctid_run(c.args);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

TEST(Cli, NarxKiaAndGfrf) {
  // Billings & Li system (33), +-1 input held at 400 Hz, 1000 samples, noise-free, simulated by the NDE integrator.
  std::vector<NdeTerm> t;
  for (const char* s : {"y", "Dy", "D^2y", "u", "y^2", "y*Dy"}) t.push_back(NdeTerm::parse(s));
  const NdeModel truth(t, (Eigen::VectorXd(6) << 1, 0.002, 1e-4, -1, 0.1, -0.006).finished());
  const int N = 1000;
  Eigen::VectorXd u(N);
  for (int i = 0; i < N; ++i) u(i) = ((i * 7919 + i / 3) % 5) < 2 ? 1.0 : -1.0;  // deterministic +-1 sequence
  Eigen::MatrixXd m(N, 2);
  m << u, truth.simulate(u, time_grid(0.0025, N), Intersample::Zoh, {}, 1e-11).y;
  const std::string data = test::temp_path("bl.csv"), narx = test::temp_path("narx.json"), nde = test::temp_path("nde.json"),
                    csv = test::temp_path("h2.csv");
  write_csv(data, {"u", "y"}, m);
  for (const auto& f : {narx, nde, csv}) fs::remove(f);
  CliRun r = ctid_run("fit " + data + " --ts 0.0025 --method narx --set ylag=6 --set ulag=6 --json " + narx);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("ERR"), std::string::npos);
  EXPECT_TRUE(read_narx_json(narx).terms().size() >= 5);
  // KIA alone (refine=0): within 5 % of the truth; with the default output-error refinement: within 0.1 %.
  r = ctid_run("fit " + data + " --ts 0.0025 --method kia --narx " + narx + " --set quadratic=y^2,y*Dy --set refine=0 --json " + nde);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.find("refined"), std::string::npos);
  for (const char* s : {"Dy", "D^2y", "u", "y^2", "y*Dy"})
    EXPECT_NEAR(read_nde_json(nde).coefficient(s), truth.coefficient(s), 0.05 * std::abs(truth.coefficient(s))) << s;
  fs::remove(nde);
  // Without --set quadratic, every product of y, Dy and u is a candidate (the NARX model has quadratic
  // terms) and ERR pruning at 0.01 % keeps exactly the true pair y^2, y*Dy (measured: within 5 % as above).
  r = ctid_run("fit " + data + " --ts 0.0025 --method kia --narx " + narx + " --set refine=0 --json " + nde);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("chosen: quadratic candidates: all 6 products"), std::string::npos) << r.out;
  {
    const NdeModel automatic = read_nde_json(nde);
    std::vector<std::string> names;
    for (const auto& term : automatic.terms()) names.push_back(term.name());
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, (std::vector<std::string>{"D^2y", "Dy", "u", "y", "y*Dy", "y^2"}));
    for (const char* s : {"Dy", "D^2y", "u", "y^2", "y*Dy"})
      EXPECT_NEAR(automatic.coefficient(s), truth.coefficient(s), 0.05 * std::abs(truth.coefficient(s))) << s;
  }
  fs::remove(nde);
  // An equation that does not reproduce its NARX model is not usable: pruning at ERR 30 % keeps y + a D^2y = 0
  // (no input term; its fit is -123 % against the NARX model's 99.98 %, both printed).
  r = ctid_run("fit " + data + " --ts 0.0025 --method kia --narx " + narx + " --set err_threshold=30 --set refine=0");
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("does not reproduce its NARX model"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("NARX model's free-run fit on the same record: 99.9"), std::string::npos) << r.out;
  // Points beyond the Nyquist frequency pi/T = 1256.6 rad/s: refused with the bound (the default is 1.25/T = 500).
  r = ctid_run("fit " + data + " --ts 0.0025 --method kia --narx " + narx + " --set max=2000");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("beyond the Nyquist frequency pi/T = 1256.6"), std::string::npos) << r.err;
  r = ctid_run("fit " + data + " --ts 0.0025 --method kia --narx " + narx + " --set quadratic=y^2,y*Dy --json " + nde);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("refined by output error"), std::string::npos) << r.out;
  const NdeModel got = read_nde_json(nde);
  for (const char* s : {"Dy", "D^2y", "u", "y^2", "y*Dy"})
    EXPECT_NEAR(got.coefficient(s), truth.coefficient(s), 1e-3 * std::abs(truth.coefficient(s))) << s;
  const std::string h2json = test::temp_path("h2.json");
  fs::remove(h2json);
  r = ctid_run("gfrf " + nde + " --order 2 --w 10,50 --out " + csv + " --json " + h2json);
  ASSERT_EQ(r.code, 0) << r.err;
  const CsvTable h2 = read_csv(csv);
  ASSERT_EQ(h2.values.rows(), 4);
  EXPECT_NEAR(h2.values(1, 4), got.h2({0, 10}, {0, 50}).real(), 1e-12 * std::abs(got.h2({0, 10}, {0, 50})));
  const auto hj = nlohmann::json::parse(std::ifstream(h2json));
  EXPECT_EQ(hj.at("type"), "gfrf");
  EXPECT_EQ(hj.at("model"), "nde");
  EXPECT_EQ(hj.at("order"), 2);
  EXPECT_NEAR(hj.at("columns").at("re").at(1).get<double>(), h2.values(1, 4), 1e-12 * std::abs(h2.values(1, 4)));
  EXPECT_NEAR(hj.at("columns").at("s2_im").at(1).get<double>(), 50.0, 1e-12);
  // --points: arbitrary complex pairs from a CSV (here the layout of the file just written, one row per pair).
  const std::string pts = write("points.csv", "s1_re,s1_im,s2_re,s2_im\n3,40,-1,7\n0,10,0,50\n");
  const std::string csv2 = test::temp_path("h2_points.csv");
  fs::remove(csv2);
  r = ctid_run("gfrf " + nde + " --order 2 --points " + pts + " --out " + csv2);
  ASSERT_EQ(r.code, 0) << r.err;
  const CsvTable hp = read_csv(csv2);
  ASSERT_EQ(hp.values.rows(), 2);
  const auto h = got.h2({3, 40}, {-1, 7});
  EXPECT_NEAR(hp.values(0, 4), h.real(), 1e-12 * std::abs(h));
  EXPECT_NEAR(hp.values(0, 5), h.imag(), 1e-12 * std::abs(h));
  EXPECT_NEAR(hp.values(1, 6), h2.values(1, 6), 1e-12 * h2.values(1, 6));
  r = ctid_run("gfrf " + nde + " --order 3 --points " + pts);
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("no column 's3_re'"), std::string::npos) << r.err;
  r = ctid_run("gfrf " + nde + " --order 2 --points " + pts + " --w 10");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("either"), std::string::npos) << r.err;
  // simulate: the NDE and NARX files reproduce the record (time axis from --ts); an escaping NDE is exit 1.
  const std::string sim = test::temp_path("nde_sim.csv");
  fs::remove(sim);
  r = ctid_run("simulate " + nde + " " + data + " --ts 0.0025 --input u --out " + sim);
  ASSERT_EQ(r.code, 0) << r.err;
  const Eigen::VectorXd ysim = read_csv(sim).values.col(2);
  EXPECT_LT((ysim - m.col(1)).norm() / m.col(1).norm(), 0.02);
  fs::remove(sim);
  r = ctid_run("simulate " + narx + " " + data + " --ts 0.0025 --input u --out " + sim);
  ASSERT_EQ(r.code, 0) << r.err;
  // validate scores NARX and NDE files as it does linear ones: the fit printed is fit_percent of the simulated
  // output (the same simulation as `simulate`) against the record, to the 4 printed digits.
  const Eigen::VectorXd ynarx = read_csv(sim).values.col(2);
  const std::string vj = test::temp_path("nde_validate.json");
  for (const std::string& model : {nde, narx}) {
    fs::remove(vj);
    r = ctid_run("validate " + model + " " + data + " --ts 0.0025 --input u --output y --json " + vj);
    ASSERT_EQ(r.code, 0) << r.err;
    const double expected = fit_percent(m.col(1), model == nde ? ysim : ynarx);
    const nlohmann::json vjs = nlohmann::json::parse(read_text_file(vj));
    EXPECT_NEAR(vjs["fit"]["fit_percent"].get<double>(), expected, 1e-9 * std::abs(expected)) << model;
    EXPECT_EQ(vjs["model"]["type"], model == nde ? "nde" : "narx") << vjs["model"].dump();
    EXPECT_NE(r.out.find("residual whiteness"), std::string::npos) << r.out;
  }
  const std::string escaping =
      write("escape.json", R"J({"type": "nde", "terms": [{"name": "Dy", "value": 1}, {"name": "y^2", "value": -1}, {"name": "u", "value": 5}]})J");  // Dy = y^2 - 5u, mean(u) < 0
  fs::remove(sim);
  r = ctid_run("simulate " + escaping + " " + data + " --ts 0.0025 --input u --out " + sim);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("escapes"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(sim));  // no partial output
  // Bad input.
  r = ctid_run("fit " + data + " --ts 0.0025 --method narx --set ylag=0");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("ylag"), std::string::npos) << r.err;
  Eigen::MatrixXd small = m.topRows(100);
  const std::string sd = test::temp_path("small.csv");
  write_csv(sd, {"u", "y"}, small);
  r = ctid_run("fit " + sd + " --ts 0.0025 --method narx --set degree=2 --set ylag=16 --set ulag=16");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("candidate terms but only"), std::string::npos) << r.err;
  const std::string bad = write("bad_narx.json", R"J({"type": "narx", "ts": 0.0025, "terms": [{"name": "y(k-1)*w(k-2)", "value": 1}]})J");
  r = ctid_run("fit " + data + " --ts 0.0025 --method kia --narx " + bad);
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("terms[0]"), std::string::npos) << r.err;
}

namespace {
// Runs headless Chromium on a report: the page's self-check line ("plots=N drawn=M errors=E") from the DOM
// after load, the console messages on stderr, and a screenshot. Empty when Chromium is not installed.
struct BrowserRun {
  std::string selfcheck, log;
};
std::optional<BrowserRun> open_in_browser(const std::string& html, const std::string& png) {
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
}  // namespace

TEST(Cli, ReportsOpenInABrowserWithEveryPlotDrawn) {
  // One report per model type: SRIVC and FSF on the bundled hair dryer, MISO SRIVC on two simulated inputs, NARX
  // and KIA (+ output-error refinement) on the Billings & Li system (33). Each must load with no console error and every plot drawn (canvas with
  // painted pixels); the screenshots go to the build tree (docs/images holds copies).
  const std::string dryer = std::string(CTID_EXAMPLES_DATA_DIR) + "/dryer.dat";
  const std::string base = " --ts 0.08 --input 1 --output 2 --detrend mean ";
  std::vector<NdeTerm> t;
  for (const char* s : {"y", "Dy", "D^2y", "u", "y^2", "y*Dy"}) t.push_back(NdeTerm::parse(s));
  const NdeModel truth(t, (Eigen::VectorXd(6) << 1, 0.002, 1e-4, -1, 0.1, -0.006).finished());
  const int N = 1000;
  Eigen::VectorXd u(N);
  for (int i = 0; i < N; ++i) u(i) = ((i * 7919 + i / 3) % 5) < 2 ? 1.0 : -1.0;
  Eigen::MatrixXd m(N, 2);
  m << u, truth.simulate(u, time_grid(0.0025, N), Intersample::Zoh, {}, 1e-11).y;
  const std::string bl = test::temp_path("bl_report.csv");
  write_csv(bl, {"u", "y"}, m);
  // Two inputs through (s + 3)/(s^2 + 2 s + 5) and 2/(s + 1) (MISO SRIVC, noise-free).
  Eigen::MatrixXd mu(2000, 2);
  mu << prbs(2000, {.register_length = 8, .clock_period = 7}), prbs(2000, {.register_length = 10, .clock_period = 4});
  const MisoModel g2{{TransferFunction(Eigen::VectorXd{{1.0, 3.0}}, Eigen::VectorXd{{1.0, 2.0, 5.0}}),
                      TransferFunction(Eigen::VectorXd{{2.0}}, Eigen::VectorXd{{1.0, 1.0}})}};
  Eigen::MatrixXd mm(2000, 3);
  mm << mu, lsim(g2, IdData(mu, Eigen::VectorXd::Zero(2000), 0.02));
  const std::string miso = test::temp_path("miso_report.csv");
  write_csv(miso, {"u1", "u2", "y"}, mm);
  // A MIMO record (the two-mode 2 x 2 system, 20 dB) for the state-space report.
  const Eigen::MatrixXd su = test::ss::levels(1500, 2, 7, 5);
  Eigen::MatrixXd sm(1500, 4);
  sm << su, test::ss::record(test::ss::two_modes(), su, Eigen::VectorXd::LinSpaced(1500, 0.0, 1499 * 0.05),
                             Eigen::Vector4d::Zero(), 20.0, 5).y();
  const std::string mimo = test::temp_path("mimo_report.csv");
  write_csv(mimo, {"u1", "u2", "y1", "y2"}, sm);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"ssest", "fit " + mimo + " --ts 0.05 --input u1 --input u2 --output y1 --output y2 --method ssest --nx 4"},
      {"miso", "fit " + miso + " --ts 0.02 --input u1 --input u2 --output y --method srivc --nb 2,1 --nf 2,1"},
      {"srivc", "fit " + dryer + base + "--method srivc --nb 2 --nf 2 --nk 2"},
      {"fsf", "fit " + dryer + base + "--method fsf --set T=4 --set n=21"},
      {"modal", "fit " + dryer + base + "--method modal --nf 2 --nk 2 --set shift_samples=1,2 --set basis=discrete"},
      {"narx", "fit " + bl + " --ts 0.0025 --method narx --set ylag=6 --set ulag=6"},
      {"kia", "fit " + bl + " --ts 0.0025 --method kia --set ylag=6 --set ulag=6 --set quadratic=y^2,y*Dy"},
  };
  for (const auto& [name, args] : cases) {
    const std::string html = test::temp_path("report_" + name + ".html");
    fs::remove(html);
    const CliRun r = ctid_run(args + " --report " + html);
    ASSERT_EQ(r.code, 0) << name << ": " << r.err;
    std::ifstream f(html);
    const std::string text((std::istreambuf_iterator<char>(f)), {});
    EXPECT_NE(text.find("Residual tests"), std::string::npos) << name;
    EXPECT_NE(text.find("Parameters"), std::string::npos) << name;
    if (name == "modal") EXPECT_NE(text.find("Modal functions (El-Shafey)"), std::string::npos);
    for (const char* ref : {"src=\"http", "href=\"http", "url(http"}) EXPECT_EQ(text.find(ref), std::string::npos) << name;
    EXPECT_TRUE(report_has_plot_library());
    const std::string png = std::string(CTID_TEST_OUTPUT_DIR) + "/report_" + name + ".png";
    const auto b = open_in_browser(html, png);
    if (!b) GTEST_SKIP() << "chromium is not installed (scripts/install-deps.sh installs it)";
    int plots = -1, drawn = -2, errors = -1;
    ASSERT_EQ(std::sscanf(b->selfcheck.c_str(), "plots=%d drawn=%d errors=%d", &plots, &drawn, &errors), 3)
        << name << ": self-check line '" << b->selfcheck << "'\n" << b->log;
    EXPECT_GE(plots, 8) << name;
    EXPECT_EQ(drawn, plots) << name;
    EXPECT_EQ(errors, 0) << name;
    EXPECT_EQ(b->log.find("Uncaught"), std::string::npos) << name << ": " << b->log;
    EXPECT_GT(fs::exists(png) ? fs::file_size(png) : 0, 50000u) << name;
  }
  // ctid report of a MISO result file: the same fit as the result says, both channels.
  const std::string mj = test::temp_path("miso_result.json"), mh = test::temp_path("miso_result.html");
  fs::remove(mj);
  fs::remove(mh);
  const std::string mio = " --ts 0.02 --input u1 --input u2 --output y ";
  ASSERT_EQ(ctid_run("fit " + miso + mio + "--method srivc --nb 2,1 --nf 2,1 --json " + mj).code, 0);
  CliRun r = ctid_run("report " + mj + " " + miso + mio + "--out " + mh);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string mt = read_text_file(mh);
  char fit[64];
  std::snprintf(fit, sizeof fit, "fit %.4g %%", parse_miso_result_json(read_text_file(mj)).fit.fit_percent);
  EXPECT_NE(mt.find(fit), std::string::npos) << fit;
  EXPECT_NE(mt.find("G2 (u2)"), std::string::npos);
  // Bad use: a report of frequency data, an unknown model type.
  r = ctid_run("fit " + dryer + " --frequency --report " + test::temp_path("x.html"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--report needs time-domain data"), std::string::npos) << r.err;
  // A state-space model is reported with its modes; one with two outputs needs two selected outputs (exit 2, by
  // name, nothing written).
  const std::string ss1 = write("ss1.json", R"J({"type": "state_space", "A": [[-1]], "B": [[1]], "C": [[1]], "D": [[0]]})J");
  r = ctid_run("report " + ss1 + " " + dryer + base + "--out " + test::temp_path("ss1.html"));
  EXPECT_EQ(r.code, 0) << r.err;
  const std::string ss = write("ss.json", R"J({"type": "state_space", "A": [[-1]], "B": [[1]], "C": [[1], [2]], "D": [[0], [0]]})J");
  r = ctid_run("report " + ss + " " + dryer + base + "--out " + test::temp_path("y.html"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("state_space"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(test::temp_path("y.html")));
}

TEST(Cli, CompareScoresSeveralModelsOnOneRecord) {
  // ctid compare: SRIVC fits of two structures on rows 1..500 of the hair dryer, compared on rows 501..1000 (their own
  // means removed). Each printed fit must be the one an independent simulate() gives from the initial state that fits
  // the rows best (MATLAB's compare; validation_initial_condition) to the printed 2 decimals; the richer structure
  // ranks first; the report loads with every plot drawn.
  const std::string dryer = std::string(CTID_EXAMPLES_DATA_DIR) + "/dryer.dat";
  const std::string io = " --ts 0.08 --input 1 --output 2 --detrend mean ";
  const std::string a = test::temp_path("cmp_a.json"), b = test::temp_path("cmp_b.json");
  const std::string html = test::temp_path("cmp.html"), json = test::temp_path("cmp.json");
  for (const auto& f : {a, b, html, json}) fs::remove(f);
  ASSERT_EQ(ctid_run("fit " + dryer + io + "--samples 1:500 --method srivc --nb 1 --nf 1 --json " + a).code, 0);
  ASSERT_EQ(ctid_run("fit " + dryer + io + "--samples 1:500 --method srivc --nb 2 --nf 2 --nk 3 --json " + b).code, 0);
  DataSpec spec;
  spec.ts = 0.08;
  spec.inputs = {"1"};
  spec.outputs = {"2"};
  const IdData val = iddata_from_table(read_csv(dryer), spec).slice(500, 1000).detrend(Detrend::Mean);
  SimulateOptions so;
  so.initial = InitialCondition::Estimated;
  double expected[2];
  for (int k = 0; k < 2; ++k) {
    const AnyModel m = read_result_file(k ? b : a).result.model;
    expected[k] = fit_percent(val.y().col(0), simulate(m, val, so).y.col(0));
  }
  ASSERT_GT(expected[1], expected[0]);
  CliRun r = ctid_run("compare " + a + " " + b + " " + dryer + io + "--samples 501: --report " + html + " --json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  for (int k = 0; k < 2; ++k) {
    char fit[32];
    std::snprintf(fit, sizeof fit, "  %9.2f  ", expected[k]);
    EXPECT_NE(r.out.find(fit), std::string::npos) << r.out << "\nexpected" << fit;
  }
  EXPECT_NE(r.out.find("best: " + b), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(read_text_file(json));
  ASSERT_EQ(j["models"].size(), 2u);
  EXPECT_NEAR(j["models"][1]["outputs"][0]["fit_percent"].get<double>(), expected[1], 1e-9);
  EXPECT_EQ(j["models"][1]["initial"], "estimated");
  const std::string text = read_text_file(html);
  for (const char* s : {"Bode magnitude", "Unit step response", "Poles of the linear models", "Residual tests"})
    EXPECT_NE(text.find(s), std::string::npos) << s;
  if (const auto br = open_in_browser(html, std::string(CTID_TEST_OUTPUT_DIR) + "/compare.png")) {
    int plots = -1, drawn = -2, errors = -1;
    ASSERT_EQ(std::sscanf(br->selfcheck.c_str(), "plots=%d drawn=%d errors=%d", &plots, &drawn, &errors), 3) << br->log;
    EXPECT_EQ(plots, 7);  // input, output, the overlay, Bode magnitude and phase, step, poles
    EXPECT_EQ(drawn, plots);
    EXPECT_EQ(errors, 0) << br->log;
  }
  // A model that does not stay finite on the record: every other row is printed and the report written, the row says
  // so, and the command ends with exit 1 naming the model and the cause.
  const std::string bad = write("cmp_unstable.json", R"({"type": "transfer_function", "num": [1], "den": [1, -20]})");
  r = ctid_run("compare " + a + " " + bad + " " + dryer + io + "--samples 501: --report " + html + " --force");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.out.find("diverges"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find(bad), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not finite"), std::string::npos) << r.err;
  // Bad use: a model whose inputs differ from the selection (named, exit 2); no record after the models.
  const IdData whole = iddata_from_table(read_csv(dryer), spec);
  Eigen::MatrixXd two(whole.size(), 3);
  two << whole.u(), whole.u(), whole.y();
  const std::string two_inputs = test::temp_path("cmp_two_inputs.csv");
  write_csv(two_inputs, {"u1", "u2", "y"}, two);
  r = ctid_run("compare " + a + " " + b + " " + two_inputs + " --ts 0.08 --input u1 --input u2 --output y");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(a + " (transfer_function) has 1 input(s) and 1 output(s); the record has 2 and 1"), std::string::npos)
      << r.err;
  EXPECT_EQ(ctid_run("compare " + a).code, 2);
}

TEST(Cli, ReportOfAResultFile) {
  // ctid report RESULT.json DATA: the result of fit --json on the same record gives the same fit in the report.
  const std::string dryer = std::string(CTID_EXAMPLES_DATA_DIR) + "/dryer.dat";
  const std::string base = " --ts 0.08 --input 1 --output 2 --detrend mean ";
  const std::string json = test::temp_path("dryer_result.json"), html = test::temp_path("dryer_report.html");
  fs::remove(json);
  fs::remove(html);
  ASSERT_EQ(ctid_run("fit " + dryer + base + "--method srivc --nb 2 --nf 2 --nk 2 --json " + json).code, 0);
  const CliRun r = ctid_run("report " + json + " " + dryer + base + "--out " + html);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream f(html);
  const std::string text((std::istreambuf_iterator<char>(f)), {});
  const double fit = parse_result_json(std::string(std::istreambuf_iterator<char>(std::ifstream(json).rdbuf()), {})).fit.fit_percent;
  char expect[64];
  std::snprintf(expect, sizeof expect, "fit %.4g %%", fit);
  EXPECT_NE(text.find(expect), std::string::npos) << expect;
  EXPECT_NE(text.find("95 % band"), std::string::npos);  // the covariance was read back
  EXPECT_EQ(ctid_run("report " + json + " " + dryer + base + "--out " + html).code, 2);  // exists: needs --force
}

TEST(Cli, RobustnessCampaignBadInputs) {
  // The table of bad inputs. Each must end with its documented exit code (2 usage, 3 input file), exactly one
  // line on stderr naming the problem, within the time limit (no hang: `timeout` would give 124), without a signal,
  // and without leaving the requested output file behind.
  const std::string base = " --time time --input force --output position ";
  std::string rows_ok = "time,force,position\n", rows_const = rows_ok, rows_zero = rows_ok;
  for (int i = 0; i < 500; ++i) {
    const double t = 0.01 * i, u = std::sin(3 * t) + 0.1 > 0 ? 1.0 : -1.0;
    rows_ok += detail::format("{},{},{}\n", t, u, std::sin(t) + 0.1 * u);
    rows_const += detail::format("{},1,{}\n", t, std::sin(t));
    rows_zero += detail::format("{},{},0\n", t, u);
  }
  const std::string ok = write("rb_ok.csv", rows_ok), cst = write("rb_const.csv", rows_const),
                    zero = write("rb_zero.csv", rows_zero);
  const std::string empty = write("rb_empty.csv", ""), header = write("rb_header.csv", "time,force,position\n");
  const std::string ragged = write("rb_ragged.csv", "time,force,position\n0,1,2\n0.1,1\n0.2,1,2\n");
  const std::string dup = write("rb_dup.csv", "time,force,position\n0,1,2\n0.1,1,3\n0.1,1,2\n0.2,1,2\n");
  const std::string badmat = write("rb_bad.mat", "MATLAB 5.0 MAT-file garbage");
  std::string hdr = "MATLAB 5.0 MAT-file, Platform: GLNXA64, Created by: ctid test";
  hdr.resize(116, ' ');
  hdr += std::string(8, '\0') + std::string("\x00\x01", 2) + "IM" + std::string("\x0e\x00\x00\x00\xe8\x03\x00\x00", 8);
  const std::string truncmat = write("rb_trunc.mat", hdr + std::string("\x06\x00\x00\x00", 4));
  const std::string truncjson = write("rb_trunc.json", R"({"type": "transfer_function", "num": [1)");
  const std::string wrongjson = write("rb_wrong.json", R"({"type": "transfer_function", "num": "x", "den": [1, 2]})");
  // 1/(s - 500) over the 5 s record grows like e^2500: its simulation overflows.
  const std::string unstable = write("rb_unstable.json", R"({"type": "transfer_function", "num": [1], "den": [1, -500]})");
  const std::string dir = test::temp_path("rb_dir");
  fs::create_directories(dir);
  const std::string out = test::temp_path("rb_out.json");
  struct Case {
    std::string args;
    int code;
    std::string message;
  };
  const std::vector<Case> cases = {
      // Files and their contents.
      {"fit " + empty + base, 3, "no data rows"},
      {"fit " + header + base, 3, "no data rows"},
      {"fit " + ragged + base, 3, "rb_ragged.csv:3: expected 3 fields, found 2"},
      {"fit " + dup + base, 3, "not strictly increasing (0.1 after 0.1)"},
      {"fit " + dir + base, 3, "rb_dir"},
      {"fit " + badmat + " --ts 0.1 --input u --output y", 3, "cannot read"},
      {"fit " + truncmat + " --ts 0.1 --input u --output y", 3, "the file is truncated or damaged"},
      // No information in the data.
      {"fit " + cst + base + "--method srivc", 2, "input 'force' is constant (1)"},
      {"fit " + cst + base + "--method fsf --set T=1 --set n=11", 2, "input 'force' is constant"},
      {"fit " + cst + base + "--method narx", 2, "input 'force' is constant"},
      {"fit " + zero + base + "--method tfest --nf 2", 2, "output 'position' is constant (0)"},
      {"fit " + zero + base + "--method kia", 2, "output 'position' is constant (0)"},
      // Structures the data cannot support.
      {"fit " + ok + base + "--method srivc --nf 300", 2, "500 samples cannot determine 600 parameters"},
      {"fit " + ok + base + "--method narx --set ylag=100000", 2, "candidate terms (at most 1e7)"},
      {"fit " + ok + base + "--method narx --set ylag=100000 --set degree=1", 2, "usable rows"},
      {"fit " + ok + base + "--method srivc --nk 100000", 2, "the input delay 1000 s is not shorter than the record"},
      {"fit " + ok + base + "--method fsf --set T=1 --set n=100001", 2, "exceed N"},
      // Absurd option values.
      {"fit " + ok + base + "--method srivc --set max_iterations=1e99", 2, "out of range"},
      {"fit " + ok + base + "--method lssvf --set tau=1e300", 2, "more than 1000 times the record"},
      {"fit " + ok + base + "--method tfest --nf 2 --delay --set delay_max=1e300", 2, "delay_max = 1e+300 s"},
      {"fit " + ok + base + "--method oe --set delay=1e9", 2, "is not shorter than the record"},
      {"fit " + ok + base + "--method kia --set points=-3", 2, "points must be >= 1 (got -3)"},
      {"fit " + ok + " --ts -1 --input force --output position", 2, "--ts must be a positive"},
      // Damaged model files and expressions.
      {"simulate " + truncjson + " " + ok + " --time time --input force", 3, "not valid JSON"},
      {"simulate " + wrongjson + " " + ok + " --time time --input force", 3, "\"num\" must be an array"},
      {"validate " + truncjson + " " + ok + base, 3, "not valid JSON"},
      // A model that diverges on the data is not scored (its residual tests used to "pass": 0/Inf correlations).
      {"validate " + unstable + " " + ok + base + "--json " + out, 1, "the model diverges on these inputs; unstable poles: 500+0j"},
      {"simulate " + unstable + " " + ok + " --time time --input force --out " + out, 1, "the model diverges"},
      {"fit " + ok + base + "--method kia --narx " + truncjson, 3, "not valid JSON"},
      {"gfrf " + truncjson + " --order 1 --w 1", 3, "not valid JSON"},
      {"fit " + ok + base + "--method physical --model 'k/(s+q)' --param k=1 --set T=1 --set n=11", 2,
       "unknown symbol 'q'"},
      {"fit " + ok + base + "--method physical --model 'k/(s+' --param k=1 --set T=1 --set n=11", 2,
       "unexpected end of expression"},
  };
  for (const Case& c : cases) {
    fs::remove(out);
    const bool writes_json = c.args.rfind("fit ", 0) == 0;
    const CliRun r = ctid_run(c.args + (writes_json ? " --json " + out : ""), "timeout 120 ");
    EXPECT_EQ(r.code, c.code) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\nstderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.args;
  }
}

// No crash, no lost file, no wrong answer that says "converged". Each case asserts the exit code, the
// key words of the one line on stderr, and that nothing the user gave was changed.
TEST(Cli, TrustCampaign) {
  const std::string base = " --time time --input force --output position ";
  // Pure noise: no model (the F test of the fit), exit 1.
  std::string noise = "time,force,position\n";
  {
    std::mt19937 rng(5);
    std::normal_distribution<double> n01;
    for (int i = 0; i < 1000; ++i) noise += detail::format("{},{},{}\n", 0.01 * i, n01(rng) > 0 ? 1 : -1, n01(rng));
  }
  const std::string noise_csv = write("tr_noise.csv", noise);
  const std::string mat = test::temp_path("tr_data.mat");
  {
    const CsvTable t = read_csv(good_csv());
    write_mat(mat, {{"t", t.values.col(0)}, {"u", t.values.col(1)}, {"y", t.values.col(2)}});
  }
  const std::string upper = test::temp_path("TR_DATA.MAT");
  fs::copy_file(mat, upper, fs::copy_options::overwrite_existing);
  const std::string bom = write("tr_bom.csv", "\xEF\xBB\xBF" + read_text_file(good_csv()).substr(read_text_file(good_csv()).find('\n') + 1));
  const std::string dupcols = write("tr_dupcols.csv", "time,force,force\n0,1,2\n0.1,2,3\n0.2,1,2\n");
  const std::string ctrl = write("tr_ctrl.json", R"({"type": "transfer_function", "num": [1], "den": [1]})");
  const std::string narx = write("tr_narx.json", R"J({"type": "narx", "ts": 0.01, "terms": [{"name": "y(k-1)", "value": 0.5}]})J");
  const std::string parasitic = write("tr_parasitic.json", R"({"type": "transfer_function", "num": [1], "den": [1e-20, 1, 2]})");
  const std::string dir = test::temp_path("tr_dir");
  fs::create_directories(dir);
  struct Case {
    std::string args;
    int code;
    std::string message;
  };
  const std::vector<Case> cases = {
      // Crashes of before: no input selection with a .mat file (default: every variable but time and output).
      {"fit " + mat + " --time t --output y --nf 2 --nb 1 --method lssvf --set tau=0.3", 0, ""},
      {"fit " + upper + " --time t --input u --output y --nf 2 --nb 1 --method lssvf --set tau=0.3", 0, ""},
      // Non-regular files and files that are not text tables.
      {"fit /dev/zero --ts 1", 3, "'/dev/zero': it is a character device, not a data file"},
      {"fit " + dir + " --ts 1", 3, "it is a directory, not a data file"},
      {"fit " + dupcols + " --time time", 3, "column name 'force' appears twice (fields 2 and 3)"},
      {"fit " + good_csv() + base + "--input force", 2, "inputs 'force' and 'force' are the same column"},
      {"fit " + good_csv() + " --time time --input position --output position", 2, "both as an input and as the output"},
      // A BOM on a header-less file: the first row is data, the fit is that of the clean file.
      {"fit " + bom + " --time 1 --input 2 --output 3 --nf 2 --nb 1 --method lssvf --set tau=0.3", 0, ""},
      // Caps on grids and searches.
      {"fit " + good_csv() + base + "--method srivc --delay --set delay_grid=1e8", 2, "delay_grid must be in [1, 10000], or 0"},
      {"fit " + good_csv() + base + "--method lssvf --set tau_grid_size=1e9", 2, "tau_grid_size must be in [2, 1000] (got 1000000000)"},
      {"fit " + good_csv() + base + "--method lssvf --set tau_grid=20", 2, "not a setting of lssvf; did you mean 'tau_grid_size'?"},
      {"order " + good_csv() + base + "--nb 1:100 --nf 1:100 --nk 0:100", 2, "more than the limit of 2000"},
      // Flags that do not apply.
      {"fit " + good_csv() + base + "--method srivc --reference force", 2, "--reference needs --closed-loop-controller"},
      {"fit " + good_csv() + base + "--method srivc --responses r", 2, "--responses writes FSF responses"},
      {"fit " + good_csv() + base + "--method modal --nf 2 --set shift_samples=1,2 --delay", 2, "--delay (delay estimation) needs"},
      {"fit " + good_csv() + base + "--method srivc --narx " + narx, 2, "--narx gives KIA its NARX model"},
      {"fit " + good_csv() + base + "--method physical --via bogus", 2, "--via must be fsf, frequency or raw (got 'bogus')"},
      {"fit " + good_csv() + base + "--method narx --nf 2", 2, "--nf sets transfer-function orders"},
      {"fit " + good_csv() + base + "--method lssvf --set tau=0.3 --set tau=0.4", 2, "--set tau is given twice"},
      {"fit " + good_csv() + base + "--closed-loop-controller " + ctrl + " --method oe", 2, "needs --method srivc"},
      // A fit the data cannot tell from no model.
      {"fit " + noise_csv + base + "--method tfest --nf 2", 1, "the data cannot tell this model from no model"},
      // Parameters the data do not determine separately: in k/(m s^2 + c s + k) only m/k and c/k matter. Before:
      // "k = 1.77 +- 5.3e5, converged", exit 0; the scaled information matrix's eigenvalue ratio is 1e-16.
      {"fit " + std::string(CTID_EXAMPLES_DATA_DIR) + "/dryer.dat --ts 0.08 --input 1 --output 2 --detrend mean "
       "--method physical --via raw --model \"k/(m*s^2+c*s+k)\" --param k=1 --param m=1 --param c=1",
       1, "the data cannot separate k, m and c: changing them together by the relative amounts (+1 k, +1 m, +1 c)"},
      // A user-given model with a parasitic pole.
      {"simulate " + parasitic + " " + good_csv() + " --time time --input force", 3, "zero up to rounding"},
  };
  for (const Case& c : cases) {
    const CliRun r = ctid_run(c.args, "timeout 120 ");
    EXPECT_EQ(r.code, c.code) << c.args << "\n" << r.err;
    if (c.code != 0) {
      EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\nstderr: " << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.args << "\n" << r.err;
    }
  }
  // The BOM file gives the clean file's numbers: a1 = 1.2 of 3/(s^2 + 1.2 s + 4) to the LSSVF accuracy (1e-2).
  const CliRun b = ctid_run("fit " + bom + " --time 1 --input 2 --output 3 --nf 2 --nb 1 --method lssvf --set tau=0.3");
  const CliRun g = ctid_run("fit " + good_csv() + base + "--nf 2 --nb 1 --method lssvf --set tau=0.3");
  auto params = [](const std::string& out) { return out.substr(out.find("a1"), out.find("filter time") - out.find("a1")); };
  EXPECT_EQ(params(b.out), params(g.out)) << b.out << g.out;
}

// Outputs are checked against every input file and each other before the fit; special files and
// symlinks are never replaced.
TEST(Cli, OutputFilesNeverReplaceWhatTheUserGave) {
  const std::string base = " --time time --input force --output position --nf 2 --nb 1 --method lssvf --set tau=0.3 ";
  const std::string narx = write("os_narx.json", R"J({"type": "narx", "ts": 0.01, "terms": [{"name": "y(k-1)", "value": 0.5}]})J");
  const std::string narx_text = read_text_file(narx);
  CliRun r = ctid_run("fit " + good_csv() + " --time time --input force --output position --method kia --narx " + narx +
                      " --json " + narx + " --force");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("it is the input file"), std::string::npos) << r.err;
  EXPECT_EQ(read_text_file(narx), narx_text);
  const std::string x = test::temp_path("os_x.out");
  fs::remove(x);
  r = ctid_run("fit " + good_csv() + base + "--json " + x + " --report " + x);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("two outputs of this command name the same file"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(x));
  r = ctid_run("fit " + good_csv() + base + "--json /nonexistent_dir/x.json");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
  // A special file is refused even with --force (as root this would have replaced /dev/null).
  r = ctid_run("fit " + good_csv() + base + "--json /dev/null --force");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("it is a character device, not a regular file"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  // A symlink is written through: the link stays, its target gets the result.
  const std::string target = test::temp_path("os_target.json"), link = test::temp_path("os_link.json");
  fs::remove(link);
  write("os_target.json", "old");
  fs::create_symlink(target, link);
  r = ctid_run("fit " + good_csv() + base + "--json " + link + " --force");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_NE(read_text_file(target).find("\"method\""), std::string::npos);
  // A symlink to the data file is the data file.
  const std::string data_link = test::temp_path("os_data_link.csv");
  fs::remove(data_link);
  fs::create_symlink(good_csv(), data_link);
  const std::string data_text = read_text_file(good_csv());
  r = ctid_run("fit " + good_csv() + base + "--json " + data_link + " --force");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(read_text_file(good_csv()), data_text);
}

// `ctid report` refuses what `ctid validate` would: a covariance that is not positive semi-definite or
// of the wrong size (exit 3), a model that diverges on the record (exit 1).
TEST(Cli, ReportRefusesUnsoundResults) {
  const std::string base = " --time time --input force --output position ";
  const std::string json = test::temp_path("rr_fit.json");
  fs::remove(json);
  ASSERT_EQ(ctid_run("fit " + good_csv() + base + "--method srivc --nf 2 --nb 1 --json " + json).code, 0);
  nlohmann::json j = nlohmann::json::parse(read_text_file(json));
  auto report = [&](const nlohmann::json& v, const std::string& name) {
    const std::string p = write(name, v.dump());
    const std::string out = test::temp_path(name + ".html");
    fs::remove(out);
    CliRun r = ctid_run("report " + p + " " + good_csv() + base + "--out " + out);
    EXPECT_EQ(r.code == 0, fs::exists(out)) << name;
    return r;
  };
  EXPECT_EQ(report(j, "rr_ok.json").code, 0);
  nlohmann::json bad = j;
  bad["covariance"][0][1] = bad["covariance"][1][0] = 1e3;  // |correlation| far above 1
  CliRun r = report(bad, "rr_notpsd.json");
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_NE(r.err.find("not positive semi-definite"), std::string::npos) << r.err;
  bad = j;
  bad["covariance"] = nlohmann::json::array({nlohmann::json::array({1.0})});
  r = report(bad, "rr_size.json");
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_NE(r.err.find("is 1 x 1 for 3 parameters"), std::string::npos) << r.err;
  bad = j;
  bad["model"]["den"] = nlohmann::json::array({1.0, -500.0, 4.0});
  r = report(bad, "rr_diverge.json");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("the model diverges"), std::string::npos) << r.err;
}

// `ctid fit --method M --help` lists every setting of the library's registry entries of M
// (estimate/methods.hpp) with its default and unit, and every one of them is accepted by --set under that name
// (set to its own default, the fit must not stop with a usage error naming it).
TEST(Cli, MethodHelpListsEveryRegisteredSettingAndSetAcceptsIt) {
  const std::map<std::string, std::vector<std::string>> cli_methods = {
      {"srivc-auto", {"srivc_auto"}}, {"lssvf", {"lssvf"}}, {"ivsvf", {"ivsvf"}}, {"rls-svf", {"rls_svf"}},
      {"srivc", {"srivc", "srivc_miso", "srivc_closed_loop"}}, {"oe", {"oe", "tf_from_frequency"}},
      {"tfest", {"tfest", "tf_from_frequency"}}, {"fsf", {"fsf"}}, {"physical", {"physical"}},
      {"modal", {"modal"}}, {"narx", {"narx"}}, {"kia", {"kia", "narx"}}, {"greybox", {"greybox"}}, {"subspace", {"subspace"}},
      {"ssest", {"ssest"}}};
  std::set<std::string> covered;
  for (const auto& [cli, entries] : cli_methods) {
    const CliRun h = ctid_run("fit --method " + cli + " --help");
    ASSERT_EQ(h.code, 0) << cli << "\n" << h.err;
    for (const auto& name : entries) {
      covered.insert(name);
      const MethodInfo& m = method_info(name);
      EXPECT_NE(h.out.find("settings of " + name), std::string::npos) << cli;
      for (const auto& s : m.settings) {
        const auto at = h.out.find("\n  " + s.name + " ", h.out.find("settings of " + name));
        ASSERT_NE(at, std::string::npos) << cli << ": " << name << "." << s.name << " missing from the help";
        const std::string line = h.out.substr(at + 1, h.out.find('\n', at + 1) - at - 1);
        const std::string d = s.default_value.empty() ? "none" : s.default_value;
        EXPECT_NE(line.find("default " + d), std::string::npos) << line;
        if (!s.unit.empty()) EXPECT_NE(line.find(s.unit), std::string::npos) << line;
      }
    }
  }
  // Every registry entry is reachable from some CLI method: directly, or (the library's building blocks) through
  // the workflow that runs it, where its settings are included: frols and narmax in narx, the KIA stages and
  // nde_oe (prefixed oe_) in kia.
  const std::map<std::string, std::pair<std::string, std::string>> through = {
      {"frols", {"narx", ""}}, {"narmax", {"narx", ""}}, {"kia_linear", {"kia", ""}},
      {"kia_quadratic", {"kia", "q"}}, {"kia_cubic", {"kia", "c"}}, {"nde_oe", {"kia", "oe_"}}};
  // poles and modal_response are their own commands: `ctid poles --help` and `ctid response --help` list their
  // settings.
  for (const auto& [command, name] : {std::pair<std::string, std::string>{"poles", "poles"}, {"response", "modal_response"}}) {
    const CliRun ph = ctid_run(command + " --help");
    ASSERT_EQ(ph.code, 0) << ph.err;
    for (const auto& s : method_info(name).settings)
      EXPECT_NE(ph.out.find("  " + s.name + " "), std::string::npos) << name << "." << s.name << " missing from ctid "
                                                                    << command << " --help";
    covered.insert(name);
  }
  for (const auto& m : methods()) {
    if (covered.count(m.name)) continue;
    ASSERT_TRUE(through.count(m.name)) << m.name << " is not reachable from ctid fit";
    const auto& [parent, prefix] = through.at(m.name);
    std::set<std::string> parent_names;
    for (const auto& s : method_info(parent).settings) parent_names.insert(s.name);
    for (const auto& s : m.settings) {
      if (s.name == "candidates" || s.name == "noise_candidates") continue;  // quadratic=, cubic=; noise_terms
      const std::string want = (m.name == "narmax" && (s.name == "iterations" || s.name == "tolerance"))
                                   ? "narmax_" + s.name
                                   : prefix + s.name;
      EXPECT_TRUE(parent_names.count(want)) << m.name << "." << s.name << " not reachable as " << parent << "." << want;
    }
  }

  // --set accepts each single-input setting under its registry name (given its default value: a named or model
  // setting gets a valid example instead). The fit may still fail for reasons of the data, never "not a setting".
  const std::string base = " --time time --input force --output position --nf 2 --nb 1 ";
  for (const auto& [cli, name] : std::vector<std::pair<std::string, std::string>>{
           {"lssvf", "lssvf"}, {"ivsvf", "ivsvf"}, {"rls-svf", "rls_svf"}, {"srivc", "srivc"}, {"oe", "oe"}, {"tfest", "tfest"}}) {
    for (const auto& s : method_info(name).settings) {
      std::string value = s.default_value.empty() ? "none" : s.default_value;
      std::string key = s.name;
      if (s.kind == OptionKind::NamedReals) key += ".a1", value = "1.2";
      if (s.kind == OptionKind::NamedBounds) key += ".a1", value = "0,10";
      if (s.kind == OptionKind::Model) value = s.name == "data_filter" ? "1/0.01,1" : "3/1,1.2,4";
      const CliRun r = ctid_run("fit " + good_csv() + base + "--method " + cli + " --set " + key + "=" + value);
      EXPECT_EQ(r.err.find("not a setting"), std::string::npos) << cli << " " << key << ": " << r.err;
      EXPECT_NE(r.code, 2) << cli << " --set " << key << "=" << value << ": " << r.err;
    }
  }
}

// Several DATA files are several experiments of one system, fitted jointly by SRIVC: the CLI's
// estimate is the library's srivc(std::vector<IdData>) (to 1e-9), other methods refuse several files by name.
TEST(Cli, SeveralDataFilesAreFittedJointly) {
  const TransferFunction g(Eigen::VectorXd{{3.0}}, Eigen::VectorXd{{1.0, 1.2, 4.0}});
  const int N = 600;
  const Eigen::VectorXd t = time_grid(0.02, N);
  const Eigen::VectorXd u1 = prbs(N, {.register_length = 7, .clock_period = 5});
  Eigen::VectorXd u2(N);
  for (int k = 0; k < N; ++k) u2(k) = std::sin(1.1 * t(k)) + 0.5 * std::sin(3.7 * t(k));
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<IdData> ds;
  std::vector<std::string> files;
  for (const Eigen::VectorXd* u : std::vector<const Eigen::VectorXd*>{&u1, &u2}) {
    Eigen::VectorXd y = lsim(g, *u, t);
    for (int k = 0; k < N; ++k) y(k) += noise(rng);
    Eigen::MatrixXd m(N, 3);
    m << t, *u, y;
    files.push_back(test::temp_path("exp" + std::to_string(files.size() + 1) + ".csv"));
    write_csv(files.back(), {"time", "force", "position"}, m);
    ds.emplace_back(*u, y, 0.02);
  }
  const std::string json = test::temp_path("joint.json");
  const CliRun r = ctid_run("fit " + files[0] + " " + files[1] +
                            " --time time --input force --output position --method srivc --nf 2 --nb 1 --json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("experiments: 2"), std::string::npos) << r.out;
  const Result<TransferFunction> lib = srivc(ds, {1, 2, 0});
  const auto j = nlohmann::json::parse(std::ifstream(json));
  const auto& ps = j.at("parameters");
  ASSERT_EQ(ps.size(), 3u);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(ps.at(i).at("value").get<double>(), lib.parameters.values(i), 1e-9 * std::abs(lib.parameters.values(i)));
  const CliRun tf = ctid_run("fit " + files[0] + " " + files[1] +
                            " --time time --input force --output position --method tfest --nf 2 --nb 1 --json " + json + " --force");
  ASSERT_EQ(tf.code, 0) << tf.err;
  const Result<TransferFunction> lib_t = tfest(ds, {1, 2, 0});
  const auto jt = nlohmann::json::parse(std::ifstream(json));
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(jt.at("parameters").at(i).at("value").get<double>(), lib_t.parameters.values(i),
                1e-9 * std::abs(lib_t.parameters.values(i)));
  const CliRun o = ctid_run("fit " + files[0] + " " + files[1] + " --time time --input force --output position --method fsf");
  EXPECT_EQ(o.code, 2);
  // The list is the registry's: every method whose capabilities take several records.
  EXPECT_NE(o.err.find("2 DATA files are several experiments: fitted jointly by --method lssvf, ivsvf, rls_svf, srivc, "
                       "oe, tfest, physical, modal, narx, kia, greybox or ssest (got fsf"),
            std::string::npos)
      << o.err;
  for (const auto& m : methods())
    if (m.capabilities.records && m.capabilities.several_records) EXPECT_NE(o.err.find(m.name), std::string::npos) << m.name;
  // NARX on both records (resampled NARX at Ts = 0.02 s): the CLI's file equals the library's joint fit.
  const CliRun n = ctid_run("fit " + files[0] + " " + files[1] +
                            " --time time --input force --output position --method narx --set degree=1 --json " + json +
                            " --force");
  ASSERT_EQ(n.code, 0) << n.err;
  NarxOptions no;
  no.degree = 1;
  const Result<NarxModel> lib_n = narx(ds, no);
  const Result<AnyModel> file_n = read_result_file(json).result;
  ASSERT_EQ(file_n.parameters.size(), lib_n.parameters.size());
  for (int i = 0; i < lib_n.parameters.size(); ++i)
    EXPECT_NEAR(file_n.parameters.values(i), lib_n.parameters.values(i), 1e-9 * std::abs(lib_n.parameters.values(i)));
  // KIA on both records from that joint NARX model (--narx): the CLI's answer is the library's kia(records) (to 1e-9).
  const std::string kj = test::temp_path("joint_kia.json");
  fs::remove(kj);
  const CliRun k = ctid_run("fit " + files[0] + " " + files[1] + " --time time --input force --output position --method kia --narx " +
                            json + " --set y_order=2 --json " + kj);
  ASSERT_NE(k.code, 2) << k.err;
  EXPECT_NE(k.out.find("free-run fit on the same records"), std::string::npos) << k.out;
  KiaOptions ko;
  ko.linear.y_order = 2;
  const KiaRun lib_k = kia(ds, lib_n.model.process(), ko);
  const Result<AnyModel> file_k = read_result_file(kj).result;
  EXPECT_EQ(k.code == 0, lib_k.result().usable());
  ASSERT_EQ(file_k.parameters.size(), lib_k.result().parameters.size());
  for (int i = 0; i < file_k.parameters.size(); ++i)
    EXPECT_NEAR(file_k.parameters.values(i), lib_k.result().parameters.values(i),
                1e-9 * std::abs(lib_k.result().parameters.values(i)));
  // Validation and reports show each record: validate --json lists both (the fit of each equals a fit_report of the
  // library's simulation of the joint SRIVC model on that record, to 1e-6 %), the report has a section per record.
  const std::string cols = " --time time --input force --output position", vj = test::temp_path("joint_val.json"),
                    html = test::temp_path("joint.html");
  fs::remove(vj);
  fs::remove(html);
  ASSERT_EQ(ctid_run("fit " + files[0] + " " + files[1] + cols + " --method srivc --nf 2 --nb 1 --json " + json +
                     " --force --report " + html)
                .code,
            0);
  EXPECT_NE(read_text_file(html).find("Record 2: " + files[1]), std::string::npos);
  const CliRun v = ctid_run("validate " + json + " " + files[0] + " " + files[1] + cols + " --json " + vj);
  ASSERT_EQ(v.code, 0) << v.err;
  EXPECT_NE(v.out.find("record 2 (" + files[1] + "):"), std::string::npos) << v.out;
  const auto jv = nlohmann::json::parse(std::ifstream(vj));
  ASSERT_EQ(jv.at("experiments").size(), 2u);
  for (int e = 0; e < 2; ++e) {
    const double f = fit_report(ds[e].y().col(0), lsim(lib.model, ds[e]), 3).fit_percent;
    EXPECT_NEAR(jv.at("experiments").at(e).at("fit").at("fit_percent").get<double>(), f, 1e-6) << "record " << e + 1;
  }
  // The physical raw route on both records: the library's fit_physical_raw on the list (to 1e-9 relative).
  const CliRun ph = ctid_run("fit " + files[0] + " " + files[1] + cols +
                             " --method physical --model \"k/(s^2 + c*s + w)\" --param k=2 --param c=1 --param w=3 --via raw "
                             "--json " + json + " --force");
  ASSERT_EQ(ph.code, 0) << ph.err;
  const Result<TransferFunction> lib_p = fit_physical_raw(PhysicalModel("k/(s^2 + c*s + w)", {"k", "c", "w"}),
                                                          {{"k", 2.0}, {"c", 1.0}, {"w", 3.0}}, ds);
  const ResultFile file_p = read_result_file(json);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(file_p.result.parameters.values(i), lib_p.parameters.values(i), 1e-9 * std::abs(lib_p.parameters.values(i)));
  EXPECT_EQ(ctid_run("fit " + files[0] + " " + files[1] + cols +
                     " --method physical --model \"k/(s^2 + c*s + w)\" --param k=2 --param c=1 --param w=3 --set T=4")
                .code,
            2);
  const std::string html2 = test::temp_path("joint2.html");
  fs::remove(html2);
  ASSERT_EQ(ctid_run("report " + json + " " + files[0] + " " + files[1] + cols + " --out " + html2).code, 0);
  EXPECT_NE(read_text_file(html2).find("Record 2: " + files[1]), std::string::npos);
}

// Every result file ctid writes is read back by simulate, validate and report, the model type
// recognised from the file; --initial chooses the simulation's initial condition.
TEST(Cli, EveryResultFileIsReadBackAndTheInitialConditionIsExplicit) {
  const std::string data = good_csv(), cols = " --time time --input force --output position";
  // FSF without window (a = 0): its discrete convolution simulates the system (T = 5 s of a plant whose slowest
  // mode decays as e^{-0.6 t}: the truncated tail costs a few percent of fit; measured 95.2 %).
  const std::string fsf = test::temp_path("fsf0.json");
  fs::remove(fsf);
  CliRun r = ctid_run("fit " + data + cols + " --method fsf --set T=5 --set n=21 --set a=0 --json " + fsf);
  ASSERT_EQ(r.code, 0) << r.err;
  r = ctid_run("validate " + fsf + " " + data + cols);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("FSF model: N = 500"), std::string::npos) << r.out;
  const auto fit_of = [](const std::string& out) { return std::stod(out.substr(out.find("fit: ") + 5)); };
  EXPECT_GT(fit_of(r.out), 90.0);
  const std::string html = test::temp_path("fsf0.html");
  fs::remove(html);
  EXPECT_EQ(ctid_run("report " + fsf + " " + data + cols + " --out " + html).code, 0);
  // A windowed FSF model (a > 0) describes G(s + a): simulating it is refused, naming why.
  const std::string fsf1 = test::temp_path("fsf1.json");
  fs::remove(fsf1);
  ASSERT_EQ(ctid_run("fit " + data + cols + " --method fsf --set T=5 --set n=21 --set a=1 --json " + fsf1).code, 0);
  r = ctid_run("simulate " + fsf1 + " " + data + " --time time --input force");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("exponentially windowed data (shift a = 1 1/s)"), std::string::npos) << r.err;
  // validate's own JSON (the model without a parameter table) is read back too.
  const std::string tf = test::temp_path("tf_rt.json"), vj = test::temp_path("tf_val.json");
  fs::remove(tf);
  fs::remove(vj);
  ASSERT_EQ(ctid_run("fit " + data + cols + " --nf 2 --nb 1 --json " + tf).code, 0);
  ASSERT_EQ(ctid_run("validate " + tf + " " + data + cols + " --json " + vj).code, 0);
  r = ctid_run("validate " + vj + " " + data + cols);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_GT(fit_of(r.out), 99.9);
  // A record that starts mid-motion (the last 1700 samples): from rest the start is missed; the estimated initial
  // state recovers the noise-free record (fit > 99.9 %, as on the whole record).
  const CsvTable all = read_csv(data);
  const std::string late = test::temp_path("late.csv");
  write_csv(late, all.names, all.values.bottomRows(1700));
  r = ctid_run("validate " + tf + " " + late + cols);
  ASSERT_EQ(r.code, 0) << r.err;
  const double from_rest = fit_of(r.out);
  r = ctid_run("validate " + tf + " " + late + cols + " --initial estimated");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_GT(fit_of(r.out), 99.9);
  EXPECT_LT(from_rest, fit_of(r.out) - 1.0) << "rest " << from_rest;
  // "measured" has no meaning for a transfer function: a usage error naming the choices.
  r = ctid_run("simulate " + tf + " " + late + cols + " --initial measured");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no output history"), std::string::npos) << r.err;
}

// `ctid fit --method greybox --model FILE` is the library's greybox() on the columns the model names;
// simulate starts from the fitted initial state by default; --initial estimated --initial-samples N estimates it
// from the record's first N samples only; misuse is named.
TEST(Cli, GreyboxModelFileFitSimulateAndValidate) {
  const std::string model = write("spring.json", R"json({"type": "greybox", "inputs": ["force"], "states": ["q", "v"],
    "outputs": {"position": "q"},
    "parameters": {"k": 2.0, "c": {"value": 0.4, "lower": 0}, "fc": {"value": 0.3, "lower": 0}, "m": {"value": 1, "fixed": true}},
    "equations": {"q": "v", "v": "(force - k*q - c*v - fc*tanh(v/0.05))/m"},
    "initial": {"q": "estimate", "v": 0}})json");
  const GreyboxModel truth = read_greybox_json(model).with_parameters(Eigen::Vector4d(2.5, 0.3, 0.2, 1.0));
  const int N = 1500;
  const Eigen::VectorXd t = time_grid(0.01, N);
  Eigen::MatrixXd u(N, 1);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> level(-3, 3);
  for (int k = 0; k < N; ++k) u(k, 0) = k % 100 == 0 ? level(rng) : u(k - 1, 0);
  Eigen::VectorXd y = truth.simulate(u, t, Intersample::Zoh, Eigen::Vector2d(0.4, 0.0), 1e-11).y.col(0);
  std::normal_distribution<double> noise(0.0, 0.005);
  for (int k = 0; k < N; ++k) y(k) += noise(rng);
  Eigen::MatrixXd m(N, 4);
  m << t, Eigen::VectorXd::Zero(N), u, y;
  const std::string csv = test::temp_path("spring.csv");
  write_csv(csv, {"t", "other", "force", "position"}, m);
  const std::string json = test::temp_path("spring_fit.json");
  const CliRun r = ctid_run("fit " + csv + " --time t --method greybox --model " + model + " --json " + json + " --force");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("dv/dt = (force - k*q - c*v - fc*tanh(v/0.05))/m"), std::string::npos) << r.out;
  const Result<GreyboxModel> lib = greybox(IdData(u, y, 0.01), read_greybox_json(model));
  const ResultFile file = read_result_file(json);
  ASSERT_EQ(file.result.parameters.size(), lib.parameters.size());
  for (int i = 0; i < lib.parameters.size(); ++i)
    EXPECT_NEAR(file.result.parameters.values(i), lib.parameters.values(i), 1e-9 * std::abs(lib.parameters.values(i)))
        << lib.parameters.names[i];
  EXPECT_NEAR(file.result.parameters.value("q(0)"), 0.4, 0.01);  // the noise 0.005 over the first samples
  // The integrator is a setting of the fit: BDF reaches the same optimum (to the integration tolerances).
  const CliRun stiff = ctid_run("fit " + csv + " --time t --method greybox --model " + model + " --set integrator=bdf");
  ASSERT_EQ(stiff.code, 0) << stiff.out << stiff.err;
  const CliRun bad = ctid_run("fit " + csv + " --time t --method greybox --model " + model + " --set integrator=rk4");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("auto, explicit, bdf"), std::string::npos) << bad.err;
  // simulate: from the fitted initial state by default (the fit's own simulation, to the integration tolerance).
  const std::string sim = test::temp_path("spring_sim.csv");
  const CliRun s = ctid_run("simulate " + json + " " + csv + " --time t --out " + sim + " --force");
  ASSERT_EQ(s.code, 0) << s.err;
  const Eigen::VectorXd ys = read_csv(sim).values.col(2);
  SimulateOptions so{InitialCondition::Estimated, lib.diagnostics.get(diagnostic::x0)};
  EXPECT_LT((ys - simulate(lib.model, IdData(u, y, 0.01), so).y.col(0)).cwiseAbs().maxCoeff(), 1e-7);
  // validate with the state estimated from the first 50 samples only: the fit is that of the model (noise 0.005).
  const CliRun v = ctid_run("validate " + json + " " + csv + " --time t --initial estimated --initial-samples 50");
  ASSERT_EQ(v.code, 0) << v.out << v.err;
  EXPECT_NE(v.out.find("fit"), std::string::npos) << v.out;
  // Misuse, each named.
  const CliRun a = ctid_run("validate " + json + " " + csv + " --time t --initial rest --initial-samples 50");
  EXPECT_EQ(a.code, 2);
  EXPECT_NE(a.err.find("--initial-samples needs --initial estimated"), std::string::npos) << a.err;
  const CliRun b = ctid_run("fit " + csv + " --time t --method greybox");
  EXPECT_EQ(b.code, 2);
  EXPECT_NE(b.err.find("--method greybox needs --model FILE.json"), std::string::npos) << b.err;
  const CliRun c = ctid_run("fit " + csv + " --time t --method greybox --model " + model + " --nf 2");
  EXPECT_EQ(c.code, 2);
  EXPECT_NE(c.err.find("--nf sets transfer-function orders"), std::string::npos) << c.err;
  const CliRun d = ctid_run("fit " + csv + " --time t --method greybox --model " + model + " --json " + model + " --force");
  EXPECT_EQ(d.code, 2);  // the model file is an input: never overwritten
  EXPECT_EQ(read_greybox_json(model).parameter_values()(0), 2.0);
}

TEST(Cli, SubspaceFitsSeveralOutputsAndWritesAStateSpaceResult) {
  // Two inputs, two outputs, modes at 2 rad/s (zeta 0.05) and 5 rad/s (zeta 0.2), noise-free ZOH record.
  const StateSpace truth = test::ss::two_modes();
  const int N = 3000;
  const Eigen::MatrixXd u = test::ss::levels(N, 2, 7, 8);
  const IdData d(u, Eigen::MatrixXd::Zero(N, 2), 0.05);
  const Eigen::MatrixXd y = lsim(truth, d);
  Eigen::MatrixXd m(N, 4);
  m << u, y;
  const std::string csv = test::temp_path("two_modes.csv");
  write_csv(csv, {"u1", "u2", "y1", "y2"}, m);
  const std::string json = test::temp_path("two_modes_ss.json");
  const CliRun r = ctid_run("fit " + csv + " --ts 0.05 --input u1 --input u2 --output y1 --output y2 --method subspace "
                            "--set route=discrete --json " + json + " --force");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("2 inputs, 2 outputs, 4 states"), std::string::npos) << r.out;  // the order chosen by BIC
  EXPECT_NE(r.out.find("zeta = 0.05"), std::string::npos) << r.out;
  // The mode shapes printed are the system's (exact route): |C v| and phase of each output.
  for (const Mode& mode : truth.modes()) {
    std::string shape = "shape";
    for (Eigen::Index j = 0; j < mode.shape.size(); ++j) {
      char buf[64];
      double deg = std::round(std::arg(mode.shape(j)) * 180 / M_PI);
      if (deg == 0.0 || deg == -180.0) deg = std::abs(deg);
      std::snprintf(buf, sizeof buf, " %.3f (%.0f)", std::abs(mode.shape(j)), deg);
      shape += buf;
    }
    EXPECT_NE(r.out.find(shape), std::string::npos) << shape << "\n" << r.out;
  }
  const ResultFile file = read_result_file(json);
  const StateSpace& back = std::get<StateSpace>(file.result.model);
  EXPECT_EQ(back.ny(), 2);
  // The file holds the library's model: the same frequency response as the system (noise-free, exact route).
  EXPECT_LT(std::abs(back.frequency_response(Eigen::VectorXd::Constant(1, 2.0), 1, 0)(0) -
                     truth.frequency_response(Eigen::VectorXd::Constant(1, 2.0), 1, 0)(0)),
            1e-6);
  // validate: each output's fit and residual tests; the noise-free record is reproduced (fit above 99.999 %).
  const std::string vjson = test::temp_path("two_modes_val.json");
  const CliRun v = ctid_run("validate " + json + " " + csv + " --ts 0.05 --input u1 --input u2 --output y1 --output y2 "
                            "--initial estimated --json " + vjson + " --force");
  ASSERT_EQ(v.code, 0) << v.out << v.err;
  EXPECT_NE(v.out.find("output y2:"), std::string::npos) << v.out;
  const nlohmann::json vj = nlohmann::json::parse(std::ifstream(vjson));
  ASSERT_EQ(vj["outputs"].size(), 2u);
  for (const auto& o : vj["outputs"]) EXPECT_GT(o["fit"]["fit_percent"].get<double>(), 99.999) << o["output"];
  const CliRun one = ctid_run("validate " + json + " " + csv + " --ts 0.05 --input u1 --input u2 --output y1");
  EXPECT_EQ(one.code, 2);
  EXPECT_NE(one.err.find("the model has 2 output(s) and 1 were selected"), std::string::npos) << one.err;
  const CliRun nb = ctid_run("fit " + csv + " --ts 0.05 --input u1 --output y1 --method subspace --nf 2");
  EXPECT_EQ(nb.code, 2);
  EXPECT_NE(nb.err.find("--nf sets transfer-function orders"), std::string::npos) << nb.err;
}

TEST(Cli, SsestFitsTheFrfMatrixOfPeriodicRecords) {
  // Two periodic records of the two-mode system (one multisine per input, 6 periods of 512 samples, the first with a
  // transient, output noise 0.01; tests/estimate/state_space_fixtures.hpp): --period fits the FRF matrix of periods
  // 2-6; reference: the true modes, within 4 reported standard deviations.
  const StateSpace truth = test::ss::two_modes();
  std::vector<std::string> files;
  for (int input = 0; input < 2; ++input) {
    const IdData d = test::ss::periodic_record(truth, 512, 6, 0.05, input, 11 + input, 0.01);
    Eigen::MatrixXd m(d.size(), 4);
    m << d.u(), d.y();
    files.push_back(test::temp_path("periodic_" + std::to_string(input) + ".csv"));
    write_csv(files.back(), {"u1", "u2", "y1", "y2"}, m);
  }
  const std::string io = files[0] + " " + files[1] + " --ts 0.05 --input u1 --input u2 --output y1 --output y2";
  const std::string json = test::temp_path("periodic_ssest.json");
  const CliRun r = ctid_run("fit " + io + " --method ssest --nx 4 --period 512 --json " + json + " --force");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("FRF matrix of the periodic records: 59 excited frequencies"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("5 period(s) of 512 samples averaged (1 skipped)"), std::string::npos) << r.out;
  const ResultFile file = read_result_file(json);
  const StateSpace& fitted = std::get<StateSpace>(file.result.model);
  const Eigen::VectorXd sd = file.result.diagnostics.get(diagnostic::mode_wn_std);
  for (size_t k = 0; k < 2; ++k)
    EXPECT_LT(std::abs(fitted.modes()[k].wn - truth.modes()[k].wn), 4 * sd(static_cast<Eigen::Index>(k))) << r.out;
  // The subspace start alone on the same FRF.
  const CliRun s = ctid_run("fit " + io + " --method subspace --nx 4 --period 512");
  ASSERT_EQ(s.code, 0) << s.out << s.err;
  // Bad use, one line each (exit 2): another method, --skip alone, one record for two inputs, too many skipped.
  const CliRun other = ctid_run("fit " + io + " --method srivc --period 512");
  EXPECT_EQ(other.code, 2);
  EXPECT_NE(other.err.find("--period fits the FRF of periodic records: it needs --method subspace or ssest"),
            std::string::npos) << other.err;
  const CliRun skip = ctid_run("fit " + io + " --method ssest --skip 2");
  EXPECT_EQ(skip.code, 2);
  EXPECT_NE(skip.err.find("--skip belongs to --period"), std::string::npos) << skip.err;
  const CliRun one = ctid_run("fit " + files[0] + " --ts 0.05 --input u1 --input u2 --output y1 --output y2 "
                              "--method ssest --period 512");
  EXPECT_EQ(one.code, 2);
  EXPECT_NE(one.err.find("2 input(s) need 2 record(s)"), std::string::npos) << one.err;
  const CliRun many = ctid_run("fit " + io + " --method ssest --period 512 --skip 5");
  EXPECT_EQ(many.code, 2);
  EXPECT_NE(many.err.find("skipping 5 leaves 1, 2 needed"), std::string::npos) << many.err;
}

TEST(Cli, SsestRefinesWithUncertaintyOrderRangeAndAStartingModel) {
  // The two-mode system with 10 dB white noise on each output (seeded); reference: the true modes.
  const int N = 2000;
  const Eigen::MatrixXd u = test::ss::levels(N, 2, 7, 9);
  const Eigen::MatrixXd y =
      test::ss::record(test::ss::two_modes(), u, Eigen::VectorXd::LinSpaced(N, 0.0, (N - 1) * 0.05),
                       Eigen::Vector4d::Zero(), 10.0, 9).y();
  Eigen::MatrixXd m(N, 4);
  m << u, y;
  const std::string csv = test::temp_path("two_modes_noisy.csv");
  write_csv(csv, {"u1", "u2", "y1", "y2"}, m);
  const std::string io = csv + " --ts 0.05 --input u1 --input u2 --output y1 --output y2 --method ssest";
  const std::string json = test::temp_path("two_modes_ssest.json");
  const std::string html = test::temp_path("two_modes_ssest.html");
  const CliRun r = ctid_run("fit " + io + " --nx 4 --set estimate_d=0 --json " + json + " --report " + html + " --force");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("subspace start: fit"), std::string::npos) << r.out;
  // The MIMO report: the modes table and a comparison per output.
  const std::string page = read_text_file(html);
  for (const char* s : {"<h2>Modes</h2>", "<h2>Measured and simulated output (y1)</h2>",
                        "<h2>Measured and simulated output (y2)</h2>", "Bode magnitude from u2"})
    EXPECT_NE(page.find(s), std::string::npos) << s;
  EXPECT_NE(r.out.find("termination: converged"), std::string::npos) << r.out;
  // Each mode with its standard deviation; the slow mode's wn within 4 of them of 2 rad/s.
  const ResultFile file = read_result_file(json);
  const StateSpace& fitted = std::get<StateSpace>(file.result.model);
  const double wn = fitted.modes()[0].wn;
  const auto pos = r.out.find("wn = ");
  ASSERT_NE(pos, std::string::npos);
  const double sd = std::stod(r.out.substr(r.out.find("+- ", pos) + 3));
  EXPECT_GT(sd, 0.0);
  EXPECT_LT(std::abs(wn - 2.0), 4 * sd) << r.out;
  EXPECT_EQ(file.result.parameters.names[0], "sigma1");
  // An order range: the least BIC is 4 states, the search is printed.
  const CliRun range = ctid_run("fit " + io + " --nx 3:5 --set estimate_d=0");
  ASSERT_EQ(range.code, 0) << range.out << range.err;
  EXPECT_NE(range.out.find("order search (BIC):  nx = 3:"), std::string::npos) << range.out;
  EXPECT_NE(range.out.find("2 inputs, 2 outputs, 4 states"), std::string::npos) << range.out;
  // From the fitted model: the search starts at its optimum (one or two iterations).
  const CliRun again = ctid_run("fit " + io + " --initial " + json + " --set estimate_d=0");
  ASSERT_EQ(again.code, 0) << again.out << again.err;
  const auto it = again.out.find("output-error refinement: ");
  ASSERT_NE(it, std::string::npos) << again.out;
  EXPECT_LE(std::stoi(again.out.substr(it + 25)), 2) << again.out;
  // Holding one entry of C in the starting model's coordinates leaves 15 of the 16 changes of basis free: the
  // entries are not determined, and the answer says so (exit 1).
  const CliRun loose = ctid_run("fit " + io + " --initial " + json + " --set estimate_d=0 fixed.C1_1=1");
  EXPECT_EQ(loose.code, 1) << loose.out << loose.err;
  EXPECT_NE(loose.err.find("leave 15 direction(s) of a change of state coordinates free"), std::string::npos) << loose.err;
  // Validation on another record (the last 1000 samples, which start in motion) re-estimates the initial state by
  // least squares for a linear model: better than from rest on each output (the fitted x0 belongs to the estimation
  // record and is not reused).
  const std::string csv2 = test::temp_path("two_modes_tail.csv");
  write_csv(csv2, {"u1", "u2", "y1", "y2"}, Eigen::MatrixXd(m.bottomRows(1000)));
  auto fits = [&](const std::string& initial) {
    const CliRun v = ctid_run("validate " + json + " " + csv2 + " --ts 0.05 --input u1 --input u2 --output y1 --output y2 "
                              "--initial " + initial);
    EXPECT_EQ(v.code, 0) << v.out << v.err;
    std::vector<double> f;
    for (auto at = v.out.find("fit: "); at != std::string::npos; at = v.out.find("fit: ", at + 1))
      f.push_back(std::stod(v.out.substr(at + 5)));
    return f;
  };
  const std::vector<double> rest = fits("rest"), estimated = fits("estimated");
  ASSERT_EQ(rest.size(), 2u);
  ASSERT_EQ(estimated.size(), 2u);
  for (int j = 0; j < 2; ++j) EXPECT_GT(estimated[static_cast<size_t>(j)], rest[static_cast<size_t>(j)] + 1.0) << j;
  // Bad input named.
  const CliRun bad = ctid_run("fit " + io + " --nx 5:3");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("--nx A:B needs A <= B (got '5:3')"), std::string::npos) << bad.err;
  const CliRun other = ctid_run("fit " + csv + " --ts 0.05 --input u1 --output y1 --method srivc --nx 2");
  EXPECT_EQ(other.code, 2);
  EXPECT_NE(other.err.find("--nx sets a state dimension"), std::string::npos) << other.err;
}

TEST(Cli, ExampleDataWritesTheDocumentedRecords) {
  // Every data file the README and docs use comes from `ctid example-data NAME OUT.csv`.
  CliRun r = ctid_run("example-data --list");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const auto& name : example_data_names()) EXPECT_NE(r.out.find(name + " "), std::string::npos) << name;
  // The file is the library's record (the same numbers to the 17 digits CSV keeps).
  const std::string csv = test::temp_path("second.csv");
  fs::remove(csv);
  r = ctid_run("example-data second " + csv);
  ASSERT_EQ(r.code, 0) << r.err;
  const CsvTable t = read_csv(csv);
  const ExampleData e = example_data("second");
  EXPECT_EQ(t.names, e.columns);
  ASSERT_EQ(t.values.rows(), e.values.rows());
  EXPECT_EQ((t.values - e.values).cwiseAbs().maxCoeff(), 0.0);
  // Its truth, (s + 3)/(s^2 + 1.2 s + 4) at 20 dB, is what SRIVC finds: every parameter within 4 reported std.
  const std::string json = test::temp_path("second.json");
  fs::remove(json);
  r = ctid_run("fit " + csv + " --time t --input u --output y --method srivc --nb 2 --nf 2 --json " + json);
  ASSERT_EQ(r.code, 0) << r.err;
  const Result<TransferFunction> res = parse_result_json(read_text_file(json));
  const std::map<std::string, double> truth{{"a1", 1.2}, {"a2", 4.0}, {"b0", 1.0}, {"b1", 3.0}};
  for (int i = 0; i < res.parameters.size(); ++i)
    EXPECT_NEAR(res.parameters.values(i), truth.at(res.parameters.names[i]), 4 * res.parameters.std(i))
        << res.parameters.names[i];
  // The grey-box page's record and its shipped model file (examples/data/spring_greybox.json): the truth of the
  // record's description, k = 2.5, c = 0.3, fc = 0.2, q(0) = 0.4, within 4 reported std (measured: within 1.7).
  const std::string spring = test::temp_path("spring.csv"), spring_json = test::temp_path("spring_fit.json");
  fs::remove(spring);
  fs::remove(spring_json);
  ASSERT_EQ(ctid_run("example-data spring " + spring).code, 0);
  r = ctid_run("fit " + spring + " --time t --method greybox --model " + std::string(CTID_EXAMPLES_DATA_DIR) +
               "/spring_greybox.json --json " + spring_json);
  ASSERT_EQ(r.code, 0) << r.err;
  const ResultFile gb = read_result_file(spring_json);
  const std::map<std::string, double> gb_truth{{"k", 2.5}, {"c", 0.3}, {"fc", 0.2}, {"q(0)", 0.4}};
  for (const auto& [name, value] : gb_truth)
    EXPECT_NEAR(gb.result.parameters.value(name), value, 4 * gb.result.parameters.std[gb.result.parameters.index(name)])
        << name;
  // The unstable levitation under its PD loop and the open-loop plant file (multiple shooting, chosen automatically):
  // k = 1e-4 and c = 2 within 4 reported std (measured: 0.3 and 0.6).
  const std::string lev = test::temp_path("levitation.csv"), lev_json = test::temp_path("levitation_fit.json");
  fs::remove(lev);
  fs::remove(lev_json);
  ASSERT_EQ(ctid_run("example-data levitation " + lev).code, 0);
  r = ctid_run("fit " + lev + " --time t --intersample foh --method greybox --model " +
               std::string(CTID_EXAMPLES_DATA_DIR) + "/levitation_greybox.json --json " + lev_json);
  ASSERT_EQ(r.code, 0) << r.err;
  const ResultFile lf = read_result_file(lev_json);
  for (const auto& [name, value] : std::map<std::string, double>{{"k", 1e-4}, {"c", 2.0}})
    EXPECT_NEAR(lf.result.parameters.value(name), value, 4 * lf.result.parameters.std[lf.result.parameters.index(name)])
        << name;
  // Nothing the user has is overwritten, and a wrong name is one line naming the closest.
  r = ctid_run("example-data second " + csv);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  r = ctid_run("example-data circiut " + test::temp_path("c.csv"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("did you mean 'circuit'"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

namespace {
// The rows of a JSON-lines batch file.
std::vector<nlohmann::json> jsonl_rows(const std::string& path) {
  std::vector<nlohmann::json> rows;
  std::ifstream f(path);
  for (std::string line; std::getline(f, line);)
    if (!line.empty()) rows.push_back(nlohmann::json::parse(line));
  return rows;
}
// The first cell of every line after the header of a CSV batch file (the ids).
std::vector<std::string> csv_ids(const std::string& path) {
  std::vector<std::string> ids;
  std::ifstream f(path);
  std::string line;
  std::getline(f, line);
  while (std::getline(f, line)) ids.push_back(line.substr(0, line.find(',')));
  return ids;
}
}  // namespace

// Ctid batch fits each record alone with ctid fit's options on a pool of threads: 40 simulated records
// (G = 4/(s^2 + 0.8 s + 4), PRBS, white output noise) and 3 broken ones give 43 rows, 40 usable, each estimate the
// library's srivc on that record (to 1e-9) and within 5 standard deviations of the truth; the broken ones are rows
// whose error names the cause, and the exit code is 1. --resume fits only the missing records.
TEST(Cli, BatchFitsEveryRecordAndResumes) {
  const TransferFunction g(Eigen::VectorXd{{4.0}}, Eigen::VectorXd{{1.0, 0.8, 4.0}});
  const int N = 1500;
  const Eigen::VectorXd t = time_grid(0.02, N);
  const Eigen::VectorXd u = prbs(N, {.register_length = 9, .clock_period = 3});
  const Eigen::VectorXd y0 = lsim(g, u, t);
  const std::string dir = test::temp_path("batch");
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::mt19937_64 rng(18);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::map<std::string, IdData> truth_data;
  for (int r = 0; r < 40; ++r) {
    Eigen::VectorXd y = y0;
    for (int k = 0; k < N; ++k) y(k) += noise(rng);
    Eigen::MatrixXd m(N, 3);
    m << t, u, y;
    const std::string path = dir + "/rec" + std::to_string(100 + r) + ".csv";
    write_csv(path, {"t", "u", "y"}, m);
    truth_data.emplace(path, IdData(u, y, 0.02));
  }
  std::ofstream(dir + "/rec200.csv") << "t,u,y\n0,1,2\n0.02,1,oops\n";
  Eigen::MatrixXd flat(N, 3);
  flat << t, Eigen::VectorXd::Ones(N), y0;
  write_csv(dir + "/rec201.csv", {"t", "u", "y"}, flat);
  const std::string out = dir + "/rows.jsonl", missing = dir + "/missing.csv";
  const std::string cmd = "batch '" + dir + "/rec*.csv' " + missing +
                          " --method srivc --nb 1 --nf 2 --time t --input u --output y --jobs 2 --out " + out;
  const CliRun r = ctid_run(cmd);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.out.find("43 records"), std::string::npos) << r.out;
  const std::vector<nlohmann::json> rows = jsonl_rows(out);
  ASSERT_EQ(rows.size(), 43u);
  std::set<std::string> ids;
  int usable = 0;
  for (const auto& row : rows) {
    const std::string id = row.at("id");
    ids.insert(id);
    if (!row.at("usable").get<bool>()) {
      const std::string e = row.at("error");
      if (id.ends_with("rec200.csv")) EXPECT_NE(e.find("'oops'"), std::string::npos) << e;
      else if (id.ends_with("rec201.csv")) EXPECT_NE(e.find("constant"), std::string::npos) << e;
      else EXPECT_EQ(id, missing) << e;
      continue;
    }
    ++usable;
    EXPECT_EQ(row.at("orders"), "nb=1 nf=2");
    EXPECT_EQ(row.at("model"), "transfer_function");
    const Result<TransferFunction> lib = srivc(truth_data.at(id), {1, 2, 0});
    for (int i = 0; i < lib.parameters.size(); ++i) {
      const std::string name = lib.parameters.names[static_cast<size_t>(i)];
      EXPECT_NEAR(row.at(name).get<double>(), lib.parameters.values(i), 1e-9 * std::abs(lib.parameters.values(i))) << id;
      EXPECT_NEAR(row.at(name + "_std").get<double>(), lib.parameters.std(i), 1e-9 * lib.parameters.std(i)) << id;
    }
    EXPECT_LT(std::abs(row.at("a1").get<double>() - 0.8), 5 * row.at("a1_std").get<double>()) << id;
  }
  EXPECT_EQ(usable, 40);
  EXPECT_EQ(ids.size(), 43u);

  // An existing output without --resume or --force is refused and left as it was.
  const CliRun again = ctid_run(cmd);
  EXPECT_EQ(again.code, 2);
  EXPECT_NE(again.err.find("--resume"), std::string::npos) << again.err;
  EXPECT_EQ(jsonl_rows(out).size(), 43u);

  // CSV: an interrupted batch (the file cut to its first 10 rows) resumes with the 33 others, each id once.
  const std::string csv = dir + "/rows.csv";
  const std::string csv_cmd = "batch '" + dir + "/rec*.csv' " + missing +
                              " --method srivc --nb 1 --nf 2 --time t --input u --output y --out " + csv;
  ASSERT_EQ(ctid_run(csv_cmd).code, 1);
  std::vector<std::string> lines;
  {
    std::ifstream f(csv);
    for (std::string line; std::getline(f, line);) lines.push_back(line);
  }
  ASSERT_EQ(lines.size(), 44u);
  EXPECT_EQ(lines[0].rfind("id,method,model,orders,fit_percent,termination,usable,seconds,error,", 0), 0u) << lines[0];
  {
    std::ofstream f(csv, std::ios::trunc);
    for (int i = 0; i <= 10; ++i) f << lines[static_cast<size_t>(i)] << '\n';
  }
  const CliRun resumed = ctid_run(csv_cmd + " --resume");
  EXPECT_EQ(resumed.code, 1) << resumed.err;
  EXPECT_NE(resumed.out.find("33 fitted now"), std::string::npos) << resumed.out;
  const std::vector<std::string> after = csv_ids(csv);
  EXPECT_EQ(after.size(), 43u);
  EXPECT_EQ(std::set<std::string>(after.begin(), after.end()).size(), 43u);
}

// Options that cannot apply fail the batch once, in one line, leaving no file; a pattern that matches
// nothing is named.
TEST(Cli, BatchRefusesBadOptionsOnce) {
  const std::string dir = test::temp_path("batch_bad");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const Eigen::VectorXd t = time_grid(0.1, 200);
  const Eigen::VectorXd u = prbs(200, {.register_length = 7, .clock_period = 2});
  Eigen::MatrixXd m(200, 3);
  m << t, u, lsim(TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 1.0}}), u, t);
  for (int r = 0; r < 3; ++r) write_csv(dir + "/r" + std::to_string(r) + ".csv", {"t", "u", "y"}, m);
  const std::string out = dir + "/o.csv";
  const CliRun typo = ctid_run("batch '" + dir + "/r*.csv' --method srivc --set maxiter=3 --out " + out);
  EXPECT_EQ(typo.code, 2);
  EXPECT_NE(typo.err.find("every record failed with: --set maxiter: not a setting of srivc"), std::string::npos) << typo.err;
  EXPECT_FALSE(fs::exists(out));
  const CliRun json = ctid_run("batch '" + dir + "/r*.csv' --json x.json --out " + out);
  EXPECT_EQ(json.code, 2);
  EXPECT_NE(json.err.find("--json is an option of ctid fit"), std::string::npos) << json.err;
  const CliRun none = ctid_run("batch '" + dir + "/none*.csv' --out " + out);
  EXPECT_EQ(none.code, 2);
  EXPECT_NE(none.err.find("'" + dir + "/none*.csv' matches no file"), std::string::npos) << none.err;
  const CliRun ext = ctid_run("batch '" + dir + "/r*.csv' --out " + dir + "/o.txt");
  EXPECT_EQ(ext.code, 2);
  EXPECT_NE(ext.err.find("--out must end in .csv or .jsonl"), std::string::npos) << ext.err;
  // Ctrl-C: the fits in progress stop, the rows written stay complete, exit 130; --resume completes the batch. The
  // records take seconds each (srivc-auto's structure and delay search on 2000 noisy samples of a second-order plant).
  {
    const int N = 2000;
    const Eigen::VectorXd ts = time_grid(0.02, N), us = prbs(N, {.register_length = 9, .clock_period = 3});
    Eigen::VectorXd ys = lsim(TransferFunction(Eigen::VectorXd{{4.0}}, Eigen::VectorXd{{1.0, 0.8, 4.0}}), us, ts);
    std::mt19937_64 rng(3);
    std::normal_distribution<double> noise(0.0, 0.05);
    for (int k = 0; k < N; ++k) ys(k) += noise(rng);
    Eigen::MatrixXd s(N, 3);
    s << ts, us, ys;
    for (int r = 0; r < 3; ++r) write_csv(dir + "/s" + std::to_string(r) + ".csv", {"t", "u", "y"}, s);
  }
  const CliRun stopped = ctid_run("batch '" + dir + "/s*.csv' --method srivc-auto --jobs 1 --out " + out,
                                  "timeout --preserve-status -s INT 1 ");
  EXPECT_EQ(stopped.code, 130) << stopped.err;
  EXPECT_NE(stopped.err.find("interrupted"), std::string::npos) << stopped.err;
  const size_t kept = csv_ids(out).size();
  EXPECT_LT(kept, 3u);
  const CliRun rest = ctid_run("batch '" + dir + "/s*.csv' --method srivc-auto --out " + out + " --resume");
  EXPECT_EQ(rest.code, 0) << rest.err;
  EXPECT_NE(rest.out.find(std::to_string(3 - kept) + " fitted now"), std::string::npos) << rest.out;
  EXPECT_EQ(csv_ids(out).size(), 3u);
}

// The registry walked from the command line: every method that fits records (estimate/methods.hpp) runs from
// `ctid fit --method NAME` on a small record of its kind with the flags its capabilities call for, writes its
// registry name into the result file, is listed by `ctid fit --help` and has a page in docs/methods/ that names it.
TEST(Cli, EveryRegisteredFitRunsFromTheCommandLine) {
  const std::string dir = test::temp_path("registry");
  fs::create_directories(dir);
  for (const char* name : {"second", "bl", "spring"})
    ASSERT_EQ(ctid_run(std::string("example-data ") + name + " " + dir + "/" + name + ".csv --force").code, 0) << name;
  const CliRun help = ctid_run("fit --help");
  ASSERT_EQ(help.code, 0) << help.err;
  std::string pages;
  for (const auto& page : fs::directory_iterator(std::string(CTID_EXAMPLES_DATA_DIR) + "/../../docs/methods")) {
    std::ifstream f(page.path());
    pages.append(std::istreambuf_iterator<char>(f), {});
  }
  const std::vector<std::string> fits = fit_method_names();
  ASSERT_GE(fits.size(), 15u);
  for (const auto& name : fits) {
    const MethodCapabilities& c = method_info(name).capabilities;
    std::string args;
    if (c.greybox_model) {
      args = dir + "/spring.csv --model " + std::string(CTID_EXAMPLES_DATA_DIR) + "/spring_greybox.json";
    } else if (c.narx_model || name == "narx") {
      args = dir + "/bl.csv --ts 0.0025 --input u --output y --set degree=2 --set ylag=2 --set ulag=2";
    } else {
      args = dir + "/second.csv --time t --input u --output y";
      if (c.needs_orders) args += " --nf 2 --nb 1";
      if (c.physical_model)
        args += " --via raw --model \"k*(s + z)/(s^2 + a*s + b)\" --param k=0.8 --param z=2.5 --param a=1 --param b=3.5";
      if (c.nx) args += " --nx 2";
    }
    const std::string json = dir + "/" + name + ".json";
    const CliRun r = ctid_run("fit " + args + " --method " + name + " --json " + json + " --force", "timeout 300 ");
    EXPECT_TRUE(r.code == 0 || r.code == 1) << name << ": exit " << r.code << "\n" << r.err;
    EXPECT_EQ(read_result_file(json).method, name) << name;
    EXPECT_NE(help.out.find(name), std::string::npos) << name << " is not in ctid fit --help";
    EXPECT_TRUE(pages.find("--method " + name) != std::string::npos || pages.find("`" + name + "`") != std::string::npos ||
                pages.find(name + "(") != std::string::npos)
        << name << " is named in no page of docs/methods/";
  }
}

// One rule for the initial state of a simulation (simulate/simulate.hpp, SimulationPurpose): `ctid simulate RESULT
// RECORD --initial X` gives, on a record the result was not fitted to, the library's simulate(result, record,
// FreeRun, X) to 1e-12 of the output's scale, for a result of every model type and each initial condition (and the
// default, without --initial); where the library refuses the initial condition, the command exits 2 naming it.
// Python's ctid.simulate is compared with the same command in python/tests/test_registry.py.
TEST(Cli, SimulateFollowsTheLibrarysInitialStateRuleForEveryModelType) {
  const std::string dir = test::temp_path("initial_rule");
  fs::create_directories(dir);
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
  struct Case {
    std::string type, record, columns, fit;
    DataSpec spec;
  };
  const std::string grey = std::string(CTID_EXAMPLES_DATA_DIR) + "/spring_greybox.json";
  const DataSpec siso{{"u"}, {"y"}, "t"}, bl{{"u"}, {"y"}, "", 0.0025}, spring{{"force"}, {"position"}, "t"};
  const std::vector<Case> cases = {
      {"transfer_function", "second", "--time t --input u --output y", "--method oe --nf 2 --nb 1", siso},
      {"miso", "miso", "--time t --input u1 --input u2 --output y", "--method srivc --nf 2 --nb 1",
       DataSpec{{"u1", "u2"}, {"y"}, "t"}},
      {"state_space", "second", "--time t --input u --output y", "--method ssest --nx 2", siso},
      {"fsf", "second", "--time t --input u --output y", "--method fsf", siso},
      {"narx", "bl", "--ts 0.0025 --input u --output y", "--method narx --set degree=2 --set ylag=2 --set ulag=2", bl},
      {"nde", "bl", "--ts 0.0025 --input u --output y", "--method kia --set degree=2 --set ylag=2 --set ulag=2", bl},
      {"greybox", "spring", "--time t --input force --output position", "--method greybox --model " + grey, spring},
  };
  for (const Case& c : cases) {
    const std::string json = dir + "/" + c.type + ".json";
    const CliRun f = ctid_run("fit " + dir + "/" + c.record + "1.csv " + c.columns + " " + c.fit + " --json " + json +
                              " --force", "timeout 300 ");
    ASSERT_TRUE(f.code == 0 || f.code == 1) << c.type << "\n" << f.err;
    const Result<AnyModel> r = read_result_file(json).result;
    ASSERT_EQ(model_type_name(r.model), c.type);
    const IdData d2 = load_iddata(dir + "/" + c.record + "2.csv", c.spec);
    for (const std::string initial : {"", "rest", "measured", "estimated"}) {
      const std::string out = dir + "/" + c.type + "_" + initial + ".csv";
      const CliRun s = ctid_run("simulate " + json + " " + dir + "/" + c.record + "2.csv " + c.columns +
                                (initial.empty() ? "" : " --initial " + initial) + " --out " + out + " --force");
      Simulation lib;
      try {
        lib = simulate(r, d2, SimulationPurpose::FreeRun,
                       initial.empty() ? std::nullopt : std::optional(initial_condition_from_string(initial)));
      } catch (const InvalidArgument& e) {
        EXPECT_EQ(s.code, 2) << c.type << " --initial " << initial << ": the library refuses (" << e.what() << ")";
        continue;
      }
      if (!lib.ok()) {
        EXPECT_EQ(s.code, 1) << c.type << " --initial " << initial << ": " << lib.problem;
        continue;
      }
      ASSERT_EQ(s.code, 0) << c.type << " --initial " << initial << "\n" << s.err;
      const CsvTable t = read_csv(out);
      const Eigen::MatrixXd y = t.values.rightCols(lib.y.cols());
      ASSERT_EQ(y.rows(), lib.y.rows());
      const double scale = std::max(1.0, lib.y.cwiseAbs().maxCoeff());
      EXPECT_LE((y - lib.y).cwiseAbs().maxCoeff(), 1e-12 * scale) << c.type << " --initial " << initial;
    }
  }
}

// The output policy of a failed run (docs/guide.md, "What the CLI never does to your files"): a run refused before
// it computes (exit 2 usage, 3 input file) writes nothing; a fit that ran but cannot be trusted (exit 1) writes the
// files it was asked for, marked so — "usable": false and the reason in the result file, the reason in the report —
// so that what went wrong can be looked at; a simulation that diverges writes nothing.
TEST(Cli, AFitThatIsNotUsableWritesItsFilesMarkedSo) {
  std::string noise = "time,force,position\n";
  std::mt19937 rng(5);
  std::normal_distribution<double> n01;
  for (int i = 0; i < 1000; ++i) noise += detail::format("{},{},{}\n", 0.01 * i, n01(rng) > 0 ? 1 : -1, n01(rng));
  const std::string data = write("policy_noise.csv", noise);
  const std::string json = test::temp_path("policy.json"), html = test::temp_path("policy.html");
  fs::remove(json);
  fs::remove(html);
  const std::string base = "fit " + data + " --time time --input force --output position --method tfest --nf 2";
  const CliRun r = ctid_run(base + " --json " + json + " --report " + html);
  ASSERT_EQ(r.code, 1) << r.err;
  const auto j = nlohmann::json::parse(std::ifstream(json));
  EXPECT_FALSE(j.at("summary").at("usable").get<bool>());
  EXPECT_NE(j.at("summary").at("not_usable_because").get<std::string>().find("the data cannot tell this model from no model"),
            std::string::npos);
  EXPECT_NE(read_text_file(html).find("the data cannot tell this model from no model"), std::string::npos);
  // Refused before computing: nothing written.
  fs::remove(json);
  EXPECT_EQ(ctid_run(base + " --set max_iteration=3 --json " + json).code, 2);
  EXPECT_FALSE(fs::exists(json));
}
