// The command line — ctid fit: every method by its registry name, its flags, several records, validation, result files.
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
  // --nx 0 is the library's nx = 0, the order where the singular values drop most (as without --nx; before: refused).
  const CliRun chosen = ctid_run("fit " + csv + " --ts 0.05 --input u1 --input u2 --output y1 --output y2 "
                                 "--method subspace --nx 0");
  EXPECT_EQ(chosen.code, 0) << chosen.err;
  const std::string unset = ctid_run("fit " + csv + " --ts 0.05 --input u1 --input u2 --output y1 --output y2 "
                                     "--method subspace").out;
  EXPECT_EQ(chosen.out.substr(0, chosen.out.find("termination:")), unset.substr(0, unset.find("termination:")));
  EXPECT_NE(chosen.out.find("4 states"), std::string::npos) << chosen.out;
  const CliRun other = ctid_run("fit " + csv + " --ts 0.05 --input u1 --output y1 --method srivc --nx 2");
  EXPECT_EQ(other.code, 2);
  EXPECT_NE(other.err.find("--nx sets a state dimension"), std::string::npos) << other.err;
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

// The same record twice is not two experiments (before: accepted, every standard deviation shrunk by sqrt(2)).
TEST(Cli, TheSameRecordTwiceIsRefused) {
  const std::string data = good_csv(), cols = " --time time --input force --output position";
  const CliRun r = ctid_run("fit " + data + " " + data + cols + " --method srivc --nb 1 --nf 2");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("records 1 and 2 are the same data (the same file given twice?)"), std::string::npos) << r.err;
}
