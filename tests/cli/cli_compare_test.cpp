// The command line — ctid compare.
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
