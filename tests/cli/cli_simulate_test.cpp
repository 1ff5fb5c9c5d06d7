// The command line — ctid simulate and ctid validate: result files read back, the initial-state rule.
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

// One rule for the initial state of a simulation (simulate/simulate.hpp, SimulationPurpose): `ctid simulate RESULT
// RECORD --initial X` gives, on a record the result was not fitted to, the library's simulate(result, record,
// FreeRun, X) to 1e-12 of the output's scale, for a result of every model type and each initial condition (and the
// default, without --initial); where the library refuses the initial condition, the command exits 2 naming it.
// Python's ctid.simulate is compared with the same command in python/tests/test_registry.py.
TEST(Cli, SimulateFollowsTheLibrarysInitialStateRuleForEveryModelType) {
  const std::string dir = test::temp_path("initial_rule");
  for (const ModelTypeCase& c : model_type_cases(dir)) {
    const auto [json, f] = fit_case(dir, c);
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

// Values that cannot mean anything are refused with one line naming the value (exit 2), not taken silently or
// answered with a computed range: --snr nan (before: no noise added, exit 0), --initial-samples 0 (before: a 300-digit
// range), an unknown example record with no near name (before: "did you mean ''?").
TEST(Cli, MeaninglessValuesAreNamed) {
  const std::string data = good_csv(), cols = " --time time --input force --output position";
  const std::string fit = test::temp_path("snr_srivc.json"), out = test::temp_path("snr_sim.csv");
  fs::remove(fit);
  ASSERT_EQ(ctid_run("fit " + data + cols + " --method srivc --nb 1 --nf 2 --json " + fit).code, 0);
  CliRun r = ctid_run("simulate " + fit + " " + data + cols + " --snr nan --out " + out + " --force");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--snr must be a finite number of dB (got nan)"), std::string::npos) << r.err;
  r = ctid_run("simulate " + fit + " " + data + cols + " --initial estimated --initial-samples 0 --out " + out +
               " --force");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--initial-samples must be at least 1 (got 0)"), std::string::npos) << r.err;
  EXPECT_LT(r.err.size(), 200u) << r.err;
  r = ctid_run("example-data qqqqqqqqqqqq " + test::temp_path("none.csv"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("no example record 'qqqqqqqqqqqq' (known: "), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("did you mean"), std::string::npos) << r.err;
}

// A grey-box simulation from an estimated initial state reads the record's output; when the record names it
// otherwise the message says why the output is needed and how to name it (before: only "no column named 'position'").
TEST(Cli, AnEstimatedInitialStateSaysItNeedsTheOutput) {
  const std::string data = test::temp_path("spring_for_x0.csv"), fit = test::temp_path("spring_for_x0.json");
  fs::remove(data);
  fs::remove(fit);
  ASSERT_EQ(ctid_run("example-data spring " + data).code, 0);
  ASSERT_EQ(ctid_run("fit " + data + " --time t --method greybox --model " + std::string(CTID_EXAMPLES_DATA_DIR) +
                     "/spring_greybox.json --json " + fit).code, 0);
  std::string text = read_text_file(data);
  text.replace(text.find("position"), 8, "pos");
  const std::string renamed = write("spring_renamed.csv", text);
  const CliRun r = ctid_run("simulate " + fit + " " + renamed + " --time t --input force --initial estimated "
                            "--initial-samples 20 --out " + test::temp_path("x0_sim.csv") + " --force");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("no column named 'position'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--initial estimated reads the record's measured output to find the initial state: name its "
                       "column with --output"), std::string::npos) << r.err;
}
