// The command line — ctid report and fit --report: the HTML page, opened in a browser.
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

namespace {
// The "simulated" series of the first plot after the heading `section` in a report: the page's chart specification
// ({"id":"plotN",...,"series":[...,{"label":"simulated",...,"y":[...]}]}) read back, null as NaN.
std::vector<double> simulated_series(const std::string& html, const std::string& section) {
  const auto at = html.find(section);
  if (at == std::string::npos) return {};
  const auto div = html.find("<div class=\"plot\" id=\"", at);
  if (div == std::string::npos) return {};
  const auto id0 = div + std::string("<div class=\"plot\" id=\"").size();
  const std::string id = html.substr(id0, html.find('"', id0) - id0);
  const auto spec = html.find("{\"id\":\"" + id + "\"");
  const auto label = html.find("\"label\":\"simulated\"", spec);
  const auto y0 = html.find("\"y\":[", label) + 5, y1 = html.find(']', y0);
  std::vector<double> y;
  std::stringstream in(html.substr(y0, y1 - y0));
  for (std::string v; std::getline(in, v, ',');) y.push_back(v == "null" ? NAN : std::stod(v));
  return y;
}
}  // namespace

// One rule for the initial state of a simulation, also in the report: `ctid report RESULT RECORD1 RECORD2
// [--initial X]` draws, for the further record, the library's simulate(result, record, OtherRecord, X) — to 1e-12 of
// the output's scale, read back from the page's chart (the simulated series is written with 17 digits) — for a
// result of every model type and each initial condition (and the default); where the library refuses the initial
// condition, the command exits 2.
TEST(Cli, ReportFollowsTheLibrarysInitialStateRuleForEveryModelType) {
  const std::string dir = test::temp_path("initial_rule_report");
  for (const ModelTypeCase& c : model_type_cases(dir)) {
    const auto [json, f] = fit_case(dir, c);
    ASSERT_TRUE(f.code == 0 || f.code == 1) << c.type << "\n" << f.err;
    const Result<AnyModel> r = read_result_file(json).result;
    const IdData d2 = load_iddata(dir + "/" + c.record + "2.csv", c.spec);
    for (const std::string initial : {"", "rest", "measured", "estimated"}) {
      const std::string html = dir + "/" + c.type + "_" + initial + ".html";
      const CliRun s = ctid_run("report " + json + " " + dir + "/" + c.record + "1.csv " + dir + "/" + c.record +
                                "2.csv " + c.columns + (initial.empty() ? "" : " --initial " + initial) + " --out " +
                                html + " --force");
      const std::optional<InitialCondition> ic =
          initial.empty() ? std::nullopt : std::optional(initial_condition_from_string(initial));
      Simulation lib;
      try {
        simulate(r, load_iddata(dir + "/" + c.record + "1.csv", c.spec), SimulationPurpose::OwnFit, ic);
        lib = simulate(r, d2, SimulationPurpose::OtherRecord, ic);
      } catch (const InvalidArgument& e) {
        EXPECT_EQ(s.code, 2) << c.type << " --initial " << initial << ": the library refuses (" << e.what() << ")";
        continue;
      }
      ASSERT_EQ(s.code, 0) << c.type << " --initial " << initial << "\n" << s.err;
      std::ifstream in(html);
      const std::string page((std::istreambuf_iterator<char>(in)), {});
      const std::vector<double> y = simulated_series(page, "Record 2: ");
      ASSERT_EQ(static_cast<Eigen::Index>(y.size()), lib.y.rows()) << c.type << " --initial " << initial;
      const double scale = std::max(1.0, lib.y.cwiseAbs().maxCoeff());
      for (Eigen::Index k = 0; k < lib.y.rows(); ++k) {
        if (!std::isfinite(lib.y(k, 0))) {
          EXPECT_TRUE(std::isnan(y[static_cast<size_t>(k)])) << c.type << " sample " << k;
          continue;
        }
        ASSERT_LE(std::abs(y[static_cast<size_t>(k)] - lib.y(k, 0)), 1e-12 * scale)
            << c.type << " --initial " << initial << " sample " << k;
      }
    }
  }
}
