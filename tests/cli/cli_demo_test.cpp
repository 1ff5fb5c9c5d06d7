// The command line — ctid demo and ctid example-data.
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
