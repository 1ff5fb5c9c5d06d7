// The command line — every subcommand: help, version, data loading, exit codes and messages of docs/guide.md, bad input, output files.
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

#include "cli_util.hpp"
#include "ctid/ctid.hpp"
#include "estimate/state_space_fixtures.hpp"
#include "test_util.hpp"

namespace fs = std::filesystem;
using namespace ctid;
using namespace ctid_cli_test;

TEST(Cli, HelpAndVersion) {
  for (const char* sub : {"fit", "simulate", "validate", "demo", "poles", "response", "gfrf"}) {
    const CliRun r = ctid_run(std::string(sub) + " --help");
    EXPECT_EQ(r.code, 0) << sub;
    EXPECT_NE(r.out.find("--"), std::string::npos) << sub;
  }
  EXPECT_NE(ctid_run("--version").out.find(ctid::version()), std::string::npos);
  EXPECT_EQ(ctid_run("").code, 2);
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
      // The library's physical fit refuses a parameter the model lacks, and FSF settings on the raw route.
      {"fit " + good_csv() + base + "--method physical --model \"k/(s+a)\" --param k=1 --param a=1 --param c=2", 2,
       "parameter c: 'c' does not appear in the model"},
      {"fit " + good_csv() + base + "--method physical --via raw --model \"k/(s+a)\" --param k=1 --param a=1 --set T=5",
       2, "T: the raw route fits the record itself"},
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
