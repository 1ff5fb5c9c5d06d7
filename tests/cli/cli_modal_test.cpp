// The command line — ctid fit --method modal, ctid poles and ctid response (El-Shafey's modal functions).
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
