// The command line — ctid batch: many records, one row each; resume.
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
  // The rows file is never one of the inputs, even with --force: here the grey-box model file (before: replaced by
  // the batch's rows).
  const std::string model = dir + "/model.jsonl";
  fs::copy_file(std::string(CTID_EXAMPLES_DATA_DIR) + "/spring_greybox.json", model);
  const std::string model_text = read_text_file(model);
  const CliRun same = ctid_run("batch '" + dir + "/r*.csv' --time t --method greybox --model " + model + " --out " +
                               model + " --force");
  EXPECT_EQ(same.code, 2) << same.err;
  EXPECT_NE(same.err.find(model), std::string::npos) << same.err;
  EXPECT_EQ(read_text_file(model), model_text);
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
