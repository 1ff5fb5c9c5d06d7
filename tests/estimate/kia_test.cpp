// Kernel Invariance Algorithm (Billings & Li 1999, BL 15-32) on the published NARX model (34):
// converged linear coefficients within 1 % of Table 2, yDy within 5 % and y^2 within 20 % of
// Table 3, ERR rankings as in Tables 1-3. The paper's procedure has no hold factor (zoh = false here).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/data/input_design.hpp"
#include "ctid/io/json.hpp"
#include "ctid/estimate/nonlinear/frols.hpp"
#include "ctid/estimate/nonlinear/gfrf.hpp"
#include "ctid/estimate/nonlinear/kia.hpp"
#include "ctid/estimate/nonlinear/nde_oe.hpp"
#include "ctid/io/load.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/validate/metrics.hpp"
#include "estimate/billings_li_models.hpp"
#include "test_util.hpp"

using namespace ctid;

namespace {
double value(const Result<NdeModel>& r, const std::string& name) { return r.parameters.value(name); }
double err(const Result<NdeModel>& r, const std::string& name) {
  return r.diagnostics.get(diagnostic::err)(r.parameters.index(name));
}
}  // namespace

TEST(Kia, LinearStageReproducesTable2) {
  // 250 real + 250 imaginary points in (0, 500) rad/s, GLS order 10 (the paper's). Table 2 converged:
  // D^2y 9.951e-5, Dy 1.9168e-3, u -0.96325; ERR D^2y 63.9 > u 34.3 > Dy 1.8. Measured over 3 seeds:
  // (1.0002e-4, 1.9073e-3, -0.9594), (1.0006e-4, 1.9063e-3, -0.9607), (0.99983e-4, 1.9071e-3, -0.9594).
  const NarxModel m = bl34();
  for (unsigned seed : {1u, 2u, 3u}) {
    const auto r = kia_linear(m, {.y_order = 2, .u_order = 0, .points = {.seed = seed}, .zoh = false});
    EXPECT_EQ(r.summary.termination, Termination::Converged);
    EXPECT_NEAR(value(r, "D^2y"), 9.951e-5, 0.01 * 9.951e-5) << seed;
    EXPECT_NEAR(value(r, "Dy"), 1.9168e-3, 0.01 * 1.9168e-3) << seed;
    EXPECT_NEAR(value(r, "u"), -0.96325, 0.01 * 0.96325) << seed;
    EXPECT_GT(err(r, "D^2y"), err(r, "u"));
    EXPECT_GT(err(r, "u"), err(r, "Dy"));
    EXPECT_GT(r.diagnostics.get(diagnostic::err_sum), 99.9);
    // The printed ERR (63.86 D^2y, 34.35 u, 1.79 Dy %) on the paper's random points, which are not published: ours
    // over three point sets 64.8-69.5, 27.8-32.6, 2.50-2.71. Tolerances: the largest deviation over our point sets
    // plus about 2 points (0.5 for Dy).
    EXPECT_NEAR(err(r, "D^2y"), 63.86, 8.0) << seed;
    EXPECT_NEAR(err(r, "u"), 34.35, 8.5) << seed;
    EXPECT_NEAR(err(r, "Dy"), 1.79, 1.5) << seed;
    // The first iteration (plain least squares) is biased towards zero in D^2y, as printed (7.5832e-5 against the
    // converged 9.951e-5): ours 8.84-9.17e-5, between the printed first iteration and the converged value. Its Dy
    // and u (printed 1.8424e-3, -0.84392) are not reproduced: ours 2.17-2.22e-3 and -0.948 to -0.965 (the
    // first iteration's bias depends on the points; billings-li.md).
    const Eigen::VectorXd first = r.diagnostics.get(diagnostic::first_iteration);
    const double first_d2y = first(r.parameters.index("D^2y"));
    EXPECT_GT(first_d2y, 7.5832e-5) << seed;
    EXPECT_LT(first_d2y, value(r, "D^2y")) << seed;
  }
}

TEST(Kia, OverParameterisedThenPrunedByErr) {
  // Table 1 candidates D^4y, D^3y, D^2y, Dy, u, Du, D^2u: after GLS convergence u, D^2y and Dy carry the ERR
  // (measured 58, 39, 2.4 %; every other term < 0.4 %), and pruning at 0.5 % then re-estimating gives Table 2.
  const NarxModel m = bl34();
  const auto all = kia_linear(m, {.y_order = 4, .u_order = 2, .zoh = false});
  std::vector<std::pair<double, std::string>> ranked;
  for (int i = 0; i < all.parameters.size(); ++i)
    ranked.emplace_back(all.diagnostics.get(diagnostic::err)(i), all.parameters.names[i]);
  std::sort(ranked.rbegin(), ranked.rend());
  EXPECT_EQ(ranked[0].second, "u");
  EXPECT_EQ(ranked[1].second, "D^2y");
  EXPECT_EQ(ranked[2].second, "Dy");
  EXPECT_LT(ranked[3].first, 0.5);
  // Table 1's coefficients (the paper's points are not published, these are the default points).
  // Measured: u -0.9618, D^2y 1.034e-4, Dy 1.821e-3, D^4y 3.247e-10, D^2u -1.857e-6 against Table 1's -0.961,
  // 1.03e-4, 1.891e-3, 3.12e-10, -1.83e-6; tolerances about twice the measured differences. D^3y (-3.5e-9, Table 1
  // +2.885e-9) and Du (-3.4e-5, Table 1 -7.23e-5) carry under 0.002 % of the ERR in both: they are zero within what
  // the points determine, and only their size is compared.
  EXPECT_NEAR(value(all, "u"), -0.961, 0.01 * 0.961);
  EXPECT_NEAR(value(all, "D^2y"), 1.03e-4, 0.01 * 1.03e-4);
  EXPECT_NEAR(value(all, "Dy"), 1.891e-3, 0.08 * 1.891e-3);
  EXPECT_NEAR(value(all, "D^4y"), 3.12e-10, 0.1 * 3.12e-10);
  EXPECT_NEAR(value(all, "D^2u"), -1.83e-6, 0.05 * 1.83e-6);
  EXPECT_LT(std::abs(value(all, "D^3y")), 1e-8);
  EXPECT_LT(std::abs(value(all, "Du")), 1e-4);
  const auto pruned = kia_linear(m, {.y_order = 4, .u_order = 2, .err_threshold = 0.5, .zoh = false});
  EXPECT_EQ(pruned.parameters.size(), 3);
  EXPECT_NEAR(value(pruned, "D^2y"), 9.951e-5, 0.01 * 9.951e-5);
  EXPECT_NEAR(value(pruned, "Dy"), 1.9168e-3, 0.01 * 1.9168e-3);
  EXPECT_NEAR(value(pruned, "u"), -0.96325, 0.01 * 0.96325);
}

TEST(Kia, QuadraticStageReproducesTable3) {
  // 35 real + 35 imaginary point pairs in (0, 220), linear part from the linear stage, GLS order 3.
  // Table 3 converged: y^2 0.0990, yDy -0.0055; ERR yDy 82.5 > y^2 17.2. Measured: 0.0979, -0.00551.
  const NarxModel m = bl34();
  const auto lin = kia_linear(m, {.y_order = 2, .u_order = 0, .zoh = false});
  const auto q = kia_quadratic(m, lin.model, {.candidates = {NdeTerm::parse("y^2"), NdeTerm::parse("y*Dy")}, .zoh = false});
  EXPECT_NEAR(value(q, "y^2"), 0.0990, 0.2 * 0.0990);
  EXPECT_NEAR(value(q, "y*Dy"), -0.0055, 0.05 * 0.0055);
  EXPECT_GT(err(q, "y*Dy"), err(q, "y^2"));
  // Table 3's ERR split (yDy 82.471, y^2 17.184 %, sum 99.655) is not reproduced on our points: ours over three
  // point sets yDy 93.4-96.1, y^2 3.9-5.5, sum 98.8-99.95 (the same ranking; the converged y^2 0.098-0.105 against
  // the printed 0.0990). Its first-iteration yDy is reproduced (ours -0.00547 to -0.00549 against -0.0056), its
  // first-iteration y^2 (0.0794, below the converged value) is not: ours 0.107-0.124, above it (billings-li.md).
  for (unsigned seed : {1u, 2u, 3u}) {
    KiaQuadraticOptions qo{.candidates = {NdeTerm::parse("y^2"), NdeTerm::parse("y*Dy")}, .zoh = false};
    qo.points.seed = seed;
    const auto qs = kia_quadratic(m, lin.model, qo);
    EXPECT_NEAR(value(qs, "y^2"), 0.0990, 0.1 * 0.0990) << seed;
    EXPECT_NEAR(value(qs, "y*Dy"), -0.0055, 0.05 * 0.0055) << seed;
    EXPECT_GT(err(qs, "y*Dy"), 90.0) << seed;  // printed 82.471: not reproduced
    EXPECT_GT(qs.diagnostics.get(diagnostic::err_sum), 98.5) << seed;
    const Eigen::VectorXd first = qs.diagnostics.get(diagnostic::first_iteration);
    EXPECT_NEAR(first(qs.parameters.index("y*Dy")), -0.0056, 2e-4) << seed;
  }
  // Four candidates: y*u and Dy^2 take little ERR (measured 0.30 % and 0.08 %) but distort y^2; pruning at 0.5 %
  // and re-estimating returns the two-term result (the paper's over-parameterise -> prune workflow).
  const std::vector<NdeTerm> four = {NdeTerm::parse("y^2"), NdeTerm::parse("y*Dy"), NdeTerm::parse("Dy^2"),
                                     NdeTerm::parse("y*u")};
  const auto q4 = kia_quadratic(m, lin.model, {.candidates = four, .err_threshold = 0.5, .zoh = false});
  EXPECT_EQ(q4.parameters.size(), 2);
  EXPECT_NEAR(value(q4, "y^2"), 0.0990, 0.2 * 0.0990);
  // The final model prints as an equation with the y coefficient +1.
  EXPECT_EQ(q4.model.coefficient("y"), 1.0);
  EXPECT_NE(q4.model.to_string().find("y*Dy"), std::string::npos);
}

TEST(Kia, PointsAndBadInputs) {
  const auto p = kia_points({.region = KiaRegion::Axes, .count = 10, .max = 100, .seed = 4});
  ASSERT_EQ(p.size(), 10u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(p[i].imag(), 0.0);
  for (int i = 5; i < 10; ++i) EXPECT_EQ(p[i].real(), 0.0);
  EXPECT_EQ(kia_points({.count = 10, .max = 100, .seed = 4}), kia_points({.count = 10, .max = 100, .seed = 4}));
  const auto g = kia_points({.region = KiaRegion::ImaginaryAxis, .count = 4, .max = 100, .grid = true});
  EXPECT_EQ(g[3], std::complex<double>(0, 100));
  EXPECT_THROW(kia_points({.count = 0}), InvalidArgument);
  EXPECT_THROW(kia_linear(bl34(), {.y_order = 0}), InvalidOptions);
  EXPECT_THROW(kia_quadratic(bl34(), NdeModel(), {.candidates = {NdeTerm::parse("y")}}), InvalidOptions);
  // The automatic point range is the paper's in units of T: 1.25/T = 500 rad/s and 0.55/T = 220 rad/s at
  // T = 2.5 ms, so the defaults and the explicit values give identical estimates.
  const auto automatic = kia_linear(bl34(), {.zoh = false}), explicit500 = kia_linear(bl34(), {.points = {.max = 500}, .zoh = false});
  EXPECT_EQ(automatic.parameters.values, explicit500.parameters.values);
  const std::vector<NdeTerm> q = {NdeTerm::parse("y^2")};
  EXPECT_EQ(kia_quadratic(bl34(), automatic.model, {.candidates = q}).parameters.values,
            kia_quadratic(bl34(), automatic.model, {.candidates = q, .points = {.count = 70, .max = 220}}).parameters.values);
  // Beyond the Nyquist frequency pi/T = 1256.6 rad/s the kernels alias: refused, naming the bound.
  EXPECT_NE(test::error_of([] { kia_linear(bl34(), {.points = {.max = 1300}}); }).find("Nyquist frequency pi/T = 1256.6"),
            std::string::npos);
  EXPECT_THROW(kia_quadratic(bl34(), automatic.model, {.candidates = q, .points = {.max = -1}}), InvalidOptions);
}

namespace {
// Billings & Li system (33) driven by a +-1 random sequence held per sample at 400 Hz, 1000 samples (Billings & Li 1999, eqs 33-34 and Tables 1-3
// set-up), simulated by the adaptive NDE integrator: the relative errors of the reconstructed Dy, D^2y, u, y^2, y*Dy,
// row 0 KIA, row 1 KIA refined by output error (nde_oe on the same record).
Eigen::MatrixXd end_to_end(unsigned seed, double snr_db) {
  const int N = 1000;
  const double T = 0.0025;
  std::mt19937 rng(seed);
  std::bernoulli_distribution coin(0.5);
  Eigen::VectorXd u(N);
  for (int i = 0; i < N; ++i) u(i) = coin(rng) ? 1.0 : -1.0;
  const NdeModel truth = bl33();
  Eigen::VectorXd y = truth.simulate(u, time_grid(T, N), Intersample::Zoh, {}, 1e-11).y;
  if (snr_db > 0) y = add_noise_snr(y, snr_db, 100 + seed);
  const IdData d(u, y, T);
  const auto cand = narx_candidates(2, 6, 6);
  const FrolsOptions fo{.max_terms = 20, .criterion = InformationCriterion::Aic};
  const NarxModel narx = (snr_db > 0 ? narmax(d, cand, {.frols = fo}) : frols(d, cand, fo)).model.process();
  // The library workflow (what the CLI and Python run): linear stage (hold factor on: the data were held),
  // quadratic stage, simulation, the NARX-fidelity check and the output-error refinement.
  KiaOptions ko;
  ko.linear = {.y_order = 2, .u_order = 0};
  ko.quadratic.candidates = {NdeTerm::parse("y^2"), NdeTerm::parse("y*Dy")};
  const KiaRun run = kia(d, narx, ko);
  EXPECT_TRUE(std::isfinite(run.narx_fit_percent));
  if (snr_db <= 0) {  // noise-free: the equation reproduces its NARX model (fits measured 99.9 % and 99.98 %)
    EXPECT_TRUE(run.reconstructed.usable()) << run.reconstructed.why_not_usable();
    EXPECT_GT(run.reconstructed.fit.fit_percent, 0.9 * run.narx_fit_percent);
  }
  EXPECT_EQ(run.reconstructed.parameters.size(), 5);  // Dy, D^2y, u, then y^2, y*Dy stacked
  EXPECT_TRUE(run.refined.has_value());
  const Result<NdeModel>& refined = *run.refined;
  EXPECT_TRUE(refined.usable()) << refined.why_not_usable();
  EXPECT_EQ(&run.result(), &refined);
  const NdeModel equation = run.reconstructed.model.normalized();
  Eigen::MatrixXd e(2, 5);
  int i = 0;
  for (const char* s : {"Dy", "D^2y", "u", "y^2", "y*Dy"}) {
    e(0, i) = std::abs(equation.coefficient(s) / truth.coefficient(s) - 1);
    e(1, i++) = std::abs(refined.model.coefficient(s) / truth.coefficient(s) - 1);
  }
  return e;
}
}  // namespace

TEST(Kia, EndToEndFromSimulatedData) {
  // Noise-free: NARX (FROLS, degree 2, lags 1..6, AIC) -> KIA with the hold factor: every coefficient within 1 %
  // (the target; measured <= 0.55 % on this seed).
  // Output-error refinement of that model: within 0.1 %.
  const Eigen::MatrixXd clean = end_to_end(11, 0.0);
  EXPECT_LT(clean.row(0).maxCoeff(), 0.01) << clean;
  EXPECT_LT(clean.row(1).maxCoeff(), 0.001) << clean;
  // 20 dB output noise, NARMAX, 8 seeds. KIA alone, measured upper medians (5th of 8): Dy 5.5 %, D^2y 0.5 %,
  // u 1.8 %, y*Dy 2.2 %, y^2 21.5 % (range 2-48 %): the small y^2 effect is the weak spot of the equation-error
  // chain. Refined by output error (nde_oe): measured worst over the 8 seeds 2.8 % (y^2; its standard error is
  // 0.9-1.9 %), so every coefficient of every seed must be within 10 % (the target).
  Eigen::MatrixXd E(8, 5);
  for (int s = 0; s < 8; ++s) {
    const Eigen::MatrixXd e = end_to_end(static_cast<unsigned>(s + 1), 20.0);
    E.row(s) = e.row(0);
    EXPECT_LT(e.row(1).maxCoeff(), 0.10) << "seed " << s + 1 << ": " << e.row(1);
  }
  for (int c = 0; c < 5; ++c) {
    std::vector<double> v(E.col(c).data(), E.col(c).data() + 8);
    std::nth_element(v.begin(), v.begin() + 4, v.end());
    EXPECT_LT(v[4], c == 3 ? 0.3 : 0.08) << "coefficient " << c;
  }
}

TEST(Kia, CubicStageReconstructsADuffingEquation) {
  // y + 0.002 Dy + 0.0001 D^2y - u + 0.5 y^3 = 0 driven by uniform noise in [-1, 1] held at 400 Hz, 2000 samples,
  // noise-free; NARX of degree 3 (lags 1..4, 165 candidates, AIC over 30 terms), then the linear stage and the cubic
  // stage (NdeModel::h3 for the probing expressions). Measured: every coefficient within 0.03 %.
  std::vector<NdeTerm> t;
  for (const char* s : {"y", "Dy", "D^2y", "u", "y^3"}) t.push_back(NdeTerm::parse(s));
  const NdeModel truth(t, (Eigen::VectorXd(5) << 1, 0.002, 1e-4, -1, 0.5).finished());
  const int N = 2000;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Eigen::VectorXd u(N);
  for (int i = 0; i < N; ++i) u(i) = U(rng);
  const IdData d(u, truth.simulate(u, time_grid(0.0025, N), Intersample::Zoh, {}, 1e-11).y, 0.0025);
  const auto narx = frols(d, narx_candidates(3, 4, 4), {.max_terms = 30, .criterion = InformationCriterion::Aic});
  const auto lin = kia_linear(narx.model, {.y_order = 2, .u_order = 0});
  const auto cub = kia_cubic(narx.model, lin.model, {.candidates = {NdeTerm::parse("y^3")}});
  for (const char* s : {"Dy", "D^2y", "u", "y^3"})
    EXPECT_NEAR(cub.model.coefficient(s), truth.coefficient(s), 1e-3 * std::abs(truth.coefficient(s))) << s;
  EXPECT_THROW(kia_cubic(narx.model, lin.model, {.candidates = {NdeTerm::parse("y^2")}}), InvalidOptions);
}

TEST(Kia, SilverboxRealData) {
  // ../shared/data/silverbox (Duffing-type circuit, fs = 610.35 Hz; skipped when the data are absent). NARX of degree
  // 3, lags 1..3 (AIC, at most 10 terms) on 20000 samples of the multisine part (means removed), free-run on the
  // "arrow (full)" test [100, 40575): measured 3.67 mV RMS (references in the README: SysIdentPy NARX 4.15 mV,
  // SUBNET 5.79 mV). KIA (linear + y^2 + y^3; the generator is a hold followed by a reconstruction filter, so no
  // hold factor; points up to 1000 rad/s) gives m y'' + d y' + k y + k3 y^3 = u: free-run RMS 21.7 mV with the input
  // held between samples, 7.4 mV with it interpolated linearly (closer to the filtered generator output). Refined by
  // output error (nde_oe, linear interpolation, 5000 training samples): measured 0.95 mV, better than the NARX model
  // and both references.
  const std::string path = std::string(CTID_SHARED_DATA_DIR) + "/silverbox/SNLS80mV.csv";
  if (!std::ifstream(path)) GTEST_SKIP() << path << " not available";
  const IdData all = load_iddata(path, {.inputs = {"V1"}, .outputs = {"V2"}, .ts = 1.0 / 610.3515625});
  Eigen::VectorXd u = all.u().col(0), y = all.y().col(0);
  u.array() -= u.segment(40650, 86750).mean();
  y.array() -= y.segment(40650, 86750).mean();
  const IdData train(u.segment(40650, 20000), y.segment(40650, 20000), all.ts());
  const auto narx = frols(train, narx_candidates(3, 3, 3), {.max_terms = 10, .criterion = InformationCriterion::Aic});
  const Eigen::VectorXd ua = u.segment(100, 40475), ya = y.segment(100, 40475);
  bool escaped = false;
  const Eigen::VectorXd yn = narx.model.simulate(ua, ya.head(narx.model.max_lag()), &escaped);
  ASSERT_FALSE(escaped);
  auto rms = [&](const Eigen::VectorXd& yhat) { return std::sqrt((yhat - ya).tail(40425).squaredNorm() / 40425); };
  EXPECT_LT(rms(yn), 4.5e-3);
  const auto lin = kia_linear(narx.model, {.y_order = 2, .u_order = 0, .points = {.max = 1000}, .zoh = false});
  const auto q = kia_quadratic(narx.model, lin.model, {.candidates = {NdeTerm::parse("y^2")}, .zoh = false});
  const auto c = kia_cubic(narx.model, q.model, {.candidates = {NdeTerm::parse("y^3")}, .zoh = false});
  EXPECT_GT(c.model.coefficient("y^3"), 0.0);  // a hardening spring
  const Eigen::VectorXd x0 = (Eigen::VectorXd(2) << ya(0), (ya(1) - ya(0)) / all.ts()).finished();
  const Eigen::VectorXd t = time_grid(all.ts(), 40475);
  const NdeSimulation held = c.model.simulate(ua, t, Intersample::Zoh, x0);
  ASSERT_TRUE(held.ok()) << held.message;
  EXPECT_LT(rms(held.y), 25e-3);
  const NdeSimulation linear = c.model.simulate(ua, t, Intersample::Foh, x0);
  ASSERT_TRUE(linear.ok()) << linear.message;
  EXPECT_LT(rms(linear.y), 9e-3);
  IdData short_train(u.segment(40650, 5000), y.segment(40650, 5000), all.ts());
  short_train.set_intersample(Intersample::Foh);
  const auto refined = nde_oe(short_train, c.model);
  ASSERT_TRUE(refined.usable()) << refined.why_not_usable();
  EXPECT_GT(refined.model.coefficient("y^3"), 0.0);
  const NdeSimulation sim = refined.model.simulate(ua, t, Intersample::Foh, x0);
  ASSERT_TRUE(sim.ok()) << sim.message;
  EXPECT_LT(rms(sim.y), 1.5e-3);
}

TEST(Kia, ErrChoosesTheGlsFilterOrder) {
  // BL-D6: the filter order is the smallest whose converged GLS fit explains >= 99.99 % (sum of ERR; the paper's
  // order 10 explained 99.992 %). Measured: order 11, 99.991 %, u = -0.9634 (Table 2: -0.96325). The coefficients
  // must agree with the fixed order 10 within 1 %.
  const NarxModel m = bl34();
  const auto chosen = kia_linear(m, {.y_order = 2, .u_order = 0, .gls_order = -1, .zoh = false});
  const auto ten = kia_linear(m, {.y_order = 2, .u_order = 0, .zoh = false});
  const double G = chosen.diagnostics.get(diagnostic::gls_order);
  EXPECT_GE(G, 8);
  EXPECT_LE(G, 12);
  EXPECT_GE(chosen.diagnostics.get(diagnostic::err_sum), 99.99);
  for (const char* s : {"D^2y", "Dy", "u"}) EXPECT_NEAR(value(chosen, s), value(ten, s), 0.01 * std::abs(value(ten, s))) << s;
}

// KIA on several records of one system. Two noise-free records of the BL 3.3 equation (1000 +-1
// samples each at 400 Hz, different inputs), the NARX model by FROLS on both (degree 2, lags 1..6, AIC): the workflow
// pools the equation's and the NARX model's fits over the records, and its output-error refinement fits one equation
// to both (an initial state each) — every coefficient within 0.1 % as from one record (EndToEndFromSimulatedData).
TEST(Kia, SeveralRecordsGiveOneEquation) {
  const double T = 0.0025;
  const NdeModel truth = bl33();
  std::vector<IdData> ds;
  for (unsigned seed : {21u, 22u}) {
    std::mt19937 rng(seed);
    std::bernoulli_distribution coin(0.5);
    Eigen::VectorXd u(1000);
    for (int i = 0; i < 1000; ++i) u(i) = coin(rng) ? 1.0 : -1.0;
    ds.emplace_back(u, truth.simulate(u, time_grid(T, 1000), Intersample::Zoh, {}, 1e-11).y, T);
  }
  const NarxModel narx =
      frols(ds, narx_candidates(2, 6, 6), {.max_terms = 20, .criterion = InformationCriterion::Aic}).model.process();
  KiaOptions ko;
  ko.linear = {.y_order = 2, .u_order = 0};
  ko.quadratic.candidates = {NdeTerm::parse("y^2"), NdeTerm::parse("y*Dy")};
  const KiaRun run = kia(ds, narx, ko);
  EXPECT_TRUE(run.reconstructed.usable()) << run.reconstructed.why_not_usable();
  EXPECT_EQ(run.reconstructed.diagnostics.get(diagnostic::experiments), 2.0);
  EXPECT_EQ(run.reconstructed.fit.n_samples, 2000);
  EXPECT_GT(run.reconstructed.fit.fit_percent, 0.9 * run.narx_fit_percent);
  ASSERT_TRUE(run.refined.has_value());
  const Result<NdeModel>& refined = *run.refined;
  ASSERT_TRUE(refined.usable()) << refined.why_not_usable();
  EXPECT_EQ(refined.diagnostics.get(diagnostic::experiments), 2.0);
  EXPECT_TRUE(refined.diagnostics.has(diagnostic::x0, 1));
  for (const char* s : {"Dy", "D^2y", "u", "y^2", "y*Dy"})
    EXPECT_LT(std::abs(refined.model.coefficient(s) / truth.coefficient(s) - 1), 1e-3) << s;
  // A record at another sampling period is named.
  const IdData slow(ds[1].u(), ds[1].y(), 2 * T);
  EXPECT_NE(test::error_of([&] { kia(std::vector<IdData>{ds[0], slow}, narx, ko); })
                .find("kia (record 2): the NARX model was identified at Ts = 0.0025 s"),
            std::string::npos);
}

TEST(Kia, ThePapersCentredErrAndTheHoldFactorAreOptions) {
  // Billings & Li centre the ERR denominator (BL 32) and use no hold factor; ctid's defaults are the uncentred
  // denominator (the ERRs of a complete model then sum to 100 %) and zoh = true (the NARX model was identified from
  // data with a held input). Both definitions on the Table 2 reproduction (the default points):
  const NarxModel m = bl34();
  const auto plain = kia_linear(m, {.y_order = 2, .u_order = 0, .zoh = false});
  const auto centred = kia_linear(m, {.y_order = 2, .u_order = 0, .zoh = false, .err_centred = true});
  // The same coefficients; every ERR scaled by one factor b'b / (b'b - (sum b)^2 / rows) > 1, so the same ranking.
  EXPECT_EQ(plain.parameters.values, centred.parameters.values);
  const Eigen::VectorXd ratio = centred.diagnostics.get(diagnostic::err).cwiseQuotient(plain.diagnostics.get(diagnostic::err));
  EXPECT_GT(ratio.minCoeff(), 1.0);
  EXPECT_LT(ratio.maxCoeff() - ratio.minCoeff(), 1e-12 * ratio.maxCoeff());
  // Measured: uncentred D^2y 68.56, u 28.75, Dy 2.67 % (sum 99.974); the factor is 1.00002 here (the stacked kernel
  // values have almost no mean), so the paper's centred ERRs are the same to the printed digits (Table 2: 63.9, 34.3,
  // 1.8 from other points).
  EXPECT_GT(err(centred, "D^2y"), err(centred, "u"));
  EXPECT_GT(err(centred, "u"), err(centred, "Dy"));
  EXPECT_NEAR(centred.diagnostics.get(diagnostic::err_sum), plain.diagnostics.get(diagnostic::err_sum) * ratio(0), 1e-9);
  // The hold factor: with zoh = true the kernels are divided by Z(s) = (1 - e^{-sT}) / (sT) before the fit, which
  // moves the estimate from the NARX model's own kernel (Table 2) towards the continuous system (33) it was identified
  // from, Dy 0.002, D^2y 1e-4, u -1. Measured: zoh = true 9.634e-5, 2.046e-3, -1.0082 (within 4 % of (33));
  // zoh = false 1.0002e-4, 1.9073e-3, -0.9594 (u 4 % from (33)).
  const auto held = kia_linear(m, {.y_order = 2, .u_order = 0});
  EXPECT_NEAR(value(held, "D^2y"), 1e-4, 0.05 * 1e-4);
  EXPECT_NEAR(value(held, "Dy"), 0.002, 0.05 * 0.002);
  EXPECT_NEAR(value(held, "u"), -1.0, 0.02);
  EXPECT_LT(std::abs(value(held, "u") + 1.0), std::abs(value(plain, "u") + 1.0));
}

namespace {
// Billings & Li (1999) §5, Figs 3-7: an electromagnetic suspension (force proportional to current squared)
// in a stabilising loop with an added random excitation r(t), measured every 1.5e-4 s, decimated by 3 to
// 4.5e-4 s, a quadratic NARMAX model, its continuous-time equation by KIA, and that equation simulated at the
// original 1.5e-4 s against the measured output. The paper's data are not published and it prints no number,
// so this is a simulated stand-in (its numbers are ours): a ball of gap x under a magnet,
// x'' = g - g (x0 / i0)^2 i^2 / x^2 (the weight balanced by i0 at the gap x0 = 5 mm), with the current
// i = i0 + kp (x - x0) + kd x' + r from a PD loop placing the linearised poles at wn = 250 rad/s, zeta = 0.4
// (the open-loop pole is at +sqrt(2 g / x0) = 62.6 1/s). r is uniform in +-0.3 A, held for each decimated
// sample; the gap is integrated by RK4 with 16 steps per 1.5e-4 s sample (well below the noise); 9000 samples
// (1.35 s); white noise at 40 dB SNR on the measured gap. The input of the identified equation is r, the
// output the gap deviation in mm: the loop is stable, so its equation can be simulated freely as in the paper's
// Fig. 7 (the magnet alone, from i to x, is unstable).
struct Suspension {
  static constexpr double g = 9.81, x0 = 0.005, i0 = 1.0, wn = 250.0, zeta = 0.4, h = 1.5e-4;
  static constexpr int decimation = 3;
  double kd = 2 * zeta * wn * i0 / (2 * g);
  double kp = (wn * wn + 2 * g / x0) * i0 / (2 * g);
  Eigen::VectorXd r, gap_mm, measured_mm;  // at the original 1.5e-4 s
  explicit Suspension(int n_decimated, unsigned seed) : r(n_decimated * decimation), gap_mm(r.size()) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> level(-0.3, 0.3);
    for (int k = 0; k < n_decimated; ++k) r.segment(k * decimation, decimation).setConstant(level(rng));
    const auto f = [&](const Eigen::Vector2d& s, double rk) {
      const double i = i0 + kp * s(0) + kd * s(1) + rk, x = x0 + s(0);
      return Eigen::Vector2d(s(1), g - g * (x0 * x0) / (i0 * i0) * i * i / (x * x));
    };
    Eigen::Vector2d s = Eigen::Vector2d::Zero();
    const double dt = h / 16;
    for (int k = 0; k < r.size(); ++k) {
      gap_mm(k) = 1e3 * s(0);
      for (int j = 0; j < 16; ++j) {
        const Eigen::Vector2d k1 = f(s, r(k)), k2 = f(s + dt / 2 * k1, r(k)), k3 = f(s + dt / 2 * k2, r(k)),
                              k4 = f(s + dt * k3, r(k));
        s += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      }
    }
    measured_mm = add_noise_snr(gap_mm, 40.0, 100 + seed);
  }
  IdData decimated() const {
    const int n = static_cast<int>(r.size()) / decimation;
    Eigen::VectorXd u(n), y(n);
    for (int k = 0; k < n; ++k) {
      u(k) = r(k * decimation);
      y(k) = measured_mm(k * decimation);
    }
    return IdData(u, y, h * decimation);
  }
  /// The physics' equation to second order in y = x - x0 (mm), r and their derivatives, in the implicit form
  /// y + .. = 0: from (1 + a)^2 (1 + b)^-2 = 1 + 2a - 2b + a^2 - 4ab + 3b^2 + O(3), a = (kp y + kd Dy + r) / i0,
  /// b = y / x0 (metres), divided by -wn^2 / g and scaled to mm.
  std::map<std::string, double> second_order_truth() const {
    const double c = g / (wn * wn), m = 1e-3;  // quadratic terms in y (m) become m * (terms in y in mm)
    return {{"Dy", 2 * zeta / wn},
            {"D^2y", 1 / (wn * wn)},
            {"u", 1e3 * 2 * g / i0 / (wn * wn)},
            {"y^2", m * c * (kp * kp / (i0 * i0) - 4 * kp / (i0 * x0) + 3 / (x0 * x0))},
            {"y*Dy", m * c * (2 * kp * kd / (i0 * i0) - 4 * kd / (i0 * x0))},
            {"Dy^2", m * c * kd * kd / (i0 * i0)},
            {"y*u", c * (2 * kp / (i0 * i0) - 4 / (i0 * x0))},
            {"Dy*u", c * 2 * kd / (i0 * i0)},
            {"u^2", 1e3 * c / (i0 * i0)}};
  }
};
}  // namespace

TEST(Kia, ElectromagneticSuspensionStandIn) {
  const Suspension rig(3000, 1);
  const IdData d = rig.decimated();
  const double T = d.ts();
  // Quadratic NARMAX, lags 1..4, no constant (deviations from the operating point), AIC, at most 16 process terms.
  auto narmax_of = [&](bool output_only_nonlinear) {
    std::vector<NarxTerm> cand;
    for (const NarxTerm& t : narx_candidates(2, 4, 4, false))
      if (!output_only_nonlinear || t.degree() < 2 ||
          std::all_of(t.factors.begin(), t.factors.end(), [](const NarxFactor& f) { return f.signal == NarxSignal::Output; }))
        cand.push_back(t);
    return narmax(d, cand, {.frols = {.max_terms = 16, .criterion = InformationCriterion::Aic}}).model.process();
  };
  const NarxModel narx = narmax_of(false);
  KiaOptions ko;
  ko.linear = {.y_order = 2, .u_order = 0};  // the quadratic candidates: every product of y, Dy, u (the default)
  const KiaRun run = kia(d, narx, ko);
  ASSERT_TRUE(run.reconstructed.usable()) << run.reconstructed.why_not_usable();
  const NdeModel equation = run.reconstructed.model.normalized();
  // Fig. 5: the linear kernel of the equation against the NARX model's, 50 points on each axis up to 1/T
  // (2222 rad/s, 0.32 of the Nyquist frequency): measured at most 0.80 % apart (seeds 2-4: 0.80, 0.87, 0.67 %).
  double h1_gap = 0;
  for (int k = 1; k <= 50; ++k)
    for (const Complex s : {Complex(0, 0.02 * k / T), Complex(0.02 * k / T, 0)}) {
      const Complex narx_h1 = narx_gfrf_ct(narx, {s});
      h1_gap = std::max(h1_gap, std::abs(equation.h1(s) - narx_h1) / std::abs(narx_h1));
    }
  EXPECT_LT(h1_gap, 0.015);
  // Fig. 6: the quadratic kernels on a 20 x 20 grid of the imaginary axis up to 0.5/T (the quadratic stage's range):
  // measured largest difference 3.1 % of the largest |H_2| (seeds 2-4: 3.9, 12.7, 2.3 %).
  double h2_gap = 0, h2_max = 0;
  for (int k = 1; k <= 20; ++k)
    for (int l = 1; l <= 20; ++l) {
      const Complex s1(0, 0.025 * k / T), s2(0, 0.025 * l / T), narx_h2 = narx_gfrf_ct(narx, {s1, s2});
      h2_gap = std::max(h2_gap, std::abs(equation.h2(s1, s2) - narx_h2));
      h2_max = std::max(h2_max, std::abs(narx_h2));
    }
  EXPECT_LT(h2_gap, 0.10 * h2_max);
  // Fig. 7: the equation simulated at the original 1.5e-4 s with the original input against the measured output.
  // Measured: KIA's equation 96.4 % (seeds 2-4: 96.5, 96.6, 97.9), its linear part alone 67.9 % (the quadratic
  // terms carry a quarter of the output), ctid's output-error refinement of the equation (on the decimated record)
  // 99.0 %.
  const Eigen::VectorXd t = time_grid(Suspension::h, static_cast<int>(rig.r.size()));
  const NdeSimulation sim = equation.simulate(rig.r, t, Intersample::Zoh);
  ASSERT_TRUE(sim.ok()) << sim.message;
  EXPECT_GT(fit_percent(rig.measured_mm, sim.y), 94.0);
  std::vector<NdeTerm> linear_terms;
  Eigen::VectorXd linear_coefficients(4);
  int i = 0;
  for (const char* s : {"y", "Dy", "D^2y", "u"}) {
    linear_terms.push_back(NdeTerm::parse(s));
    linear_coefficients(i++) = equation.coefficient(s);
  }
  const NdeSimulation linear = NdeModel(linear_terms, linear_coefficients).simulate(rig.r, t, Intersample::Zoh);
  EXPECT_LT(fit_percent(rig.measured_mm, linear.y), 72.0);
  ASSERT_TRUE(run.refined.has_value() && run.refined->usable());
  const NdeModel refined = run.refined->model.normalized();
  const NdeSimulation refined_sim = refined.simulate(rig.r, t, Intersample::Zoh);
  EXPECT_GT(fit_percent(rig.measured_mm, refined_sim.y), 98.5);
  // Against the physics (not in the paper): the refined equation's coefficients and the second-order expansion
  // of the magnet's force. Measured: linear terms 0.18-0.25 %, y^2, y*u, u^2 0.3 %, y*Dy 2.5 %, Dy*u 2.3 %,
  // Dy^2 7.4 % (the expansion drops the third-order terms, which the fit partly absorbs).
  for (const auto& [name, truth] : rig.second_order_truth()) {
    const double tolerance = name == "Dy^2" ? 0.15 : name == "y*Dy" || name == "Dy*u" ? 0.05 : 0.01;
    EXPECT_NEAR(refined.coefficient(name) / truth, 1.0, tolerance) << name;
  }
  // The paper kept only output nonlinear terms. Here the force is quadratic in the current, which the input
  // drives directly, so such a model explains no more than the linear equation: measured 67.8 % at 1.5e-4 s.
  const KiaRun output_only = kia(d, narmax_of(true), [] {
    KiaOptions o;
    o.linear = {.y_order = 2, .u_order = 0};
    o.quadratic.candidates = {NdeTerm::parse("y^2"), NdeTerm::parse("y*Dy"), NdeTerm::parse("Dy^2")};
    o.refine = false;
    return o;
  }());
  const NdeSimulation output_only_sim = output_only.reconstructed.model.normalized().simulate(rig.r, t, Intersample::Zoh);
  EXPECT_LT(fit_percent(rig.measured_mm, output_only_sim.y), 72.0);
}
