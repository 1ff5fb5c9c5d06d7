// The command line — ctid fit --method narx/kia and ctid gfrf.
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
