// Continuous-time state space from frequency-response data (estimate/state_space/ssest_frequency.cpp): the frequency-domain
// subspace start, the weighted least-squares refinement and its covariance, the FRF of periodic records.
#include <cmath>
#include <complex>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/data/frequency_data.hpp"
#include "ctid/estimate/transfer_function/frequency.hpp"
#include "ctid/estimate/state_space/ssest.hpp"
#include "ctid/estimate/state_space/subspace.hpp"
#include "estimate/state_space_fixtures.hpp"

namespace ctid {
namespace {

using cd = std::complex<double>;

Eigen::VectorXd log_grid(double lo, double hi, int n) {
  Eigen::VectorXd w(n);
  for (int k = 0; k < n; ++k) w(k) = lo * std::pow(hi / lo, k / (n - 1.0));
  return w;
}

// The FRF matrices of m at w, with circular complex noise of variance `rel` |G_ij|^2 (floor 1e-6) per entry; the
// variances are returned with the data.
FrequencyData noisy_frf(const StateSpace& m, const Eigen::VectorXd& w, double rel, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> e(0.0, 1.0);
  const std::vector<Eigen::MatrixXcd> G0 = frequency_response(m, w);
  std::vector<Eigen::MatrixXcd> G;
  std::vector<Eigen::MatrixXd> V;
  for (const Eigen::MatrixXcd& g0 : G0) {
    const Eigen::MatrixXd v = (rel * g0.cwiseAbs2()).cwiseMax(1e-6);
    Eigen::MatrixXcd g = g0;
    for (Eigen::Index i = 0; i < g.rows(); ++i)
      for (Eigen::Index j = 0; j < g.cols(); ++j) g(i, j) += std::sqrt(v(i, j) / 2) * cd(e(rng), e(rng));
    G.push_back(g);
    V.push_back(v);
  }
  return FrequencyData(w, G, V);
}

TEST(SsestFrequency, ExactResponseGivesTheSystem) {
  // Noise-free FRF matrix of the two-mode 2x2 system at 120 lines over 0.2-30 rad/s: the subspace start alone and
  // the refinement both reproduce the poles (to 1e-7 relative: rounding of the subspace step) and the response.
  const StateSpace truth = test::ss::two_modes();
  const Eigen::VectorXd w = log_grid(0.2, 30.0, 120);
  const FrequencyData fd(w, frequency_response(truth, w));
  SubspaceOptions so;
  so.nx = 4;
  const Result<StateSpace> s = subspace(fd, so);
  ASSERT_TRUE(s.usable()) << s.why_not_usable();
  EXPECT_LT(test::ss::pole_error(truth, s.model), 1e-7);
  EXPECT_GT(s.fit.fit_percent, 99.99999);
  EXPECT_GT(s.diagnostics.get(diagnostic::frequency_scale), 0.0);
  SsestOptions o;
  o.nx = 4;
  const Result<StateSpace> r = ssest(fd, o);
  ASSERT_TRUE(r.usable()) << r.why_not_usable();
  EXPECT_LT(test::ss::pole_error(truth, r.model), 1e-8);
  const std::vector<Eigen::MatrixXcd> G = frequency_response(r.model, w);
  for (size_t k = 0; k < G.size(); ++k) EXPECT_LT((G[k] - fd.matrices()[k]).norm(), 1e-7 * fd.matrices()[k].norm()) << k;
}

TEST(SsestFrequency, MonteCarloSpreadMatchesTheReportedStandardDeviations) {
  // 200 noisy FRF matrices (3 % relative standard deviation per entry, variances given): for every mode's wn and zeta
  // the estimates' spread is within 15 % of the mean reported standard deviation ((J^T W J)^-1 with W the inverse
  // variances: the Cramer-Rao bound of circular Gaussian errors; 200 runs estimate a standard deviation to 5 %, so 15 %
  // is three of its standard errors) and the bias is below 0.3 standard deviations (the mean of 200 runs is known
  // to 0.07 of one).
  const StateSpace truth = test::ss::two_modes();
  const std::vector<Mode> tm = truth.modes();
  const Eigen::VectorXd w = log_grid(0.2, 30.0, 200);
  const int runs = 200;
  Eigen::MatrixXd wn(runs, 2), zeta(runs, 2), wn_std(runs, 2), zeta_std(runs, 2);
  SsestOptions o;
  o.nx = 4;
  o.estimate_d = false;
  for (int s = 0; s < runs; ++s) {
    const Result<StateSpace> r = ssest(noisy_frf(truth, w, 1e-3, static_cast<unsigned>(s)), o);
    ASSERT_TRUE(r.usable()) << s << ": " << r.why_not_usable();
    const std::vector<Mode> m = r.model.modes();
    ASSERT_EQ(m.size(), 2u);
    for (int k = 0; k < 2; ++k) {
      wn(s, k) = m[static_cast<size_t>(k)].wn;
      zeta(s, k) = m[static_cast<size_t>(k)].zeta;
      wn_std(s, k) = r.diagnostics.get(diagnostic::mode_wn_std)(k);
      zeta_std(s, k) = r.diagnostics.get(diagnostic::mode_zeta_std)(k);
    }
    EXPECT_NEAR(r.diagnostics.get(diagnostic::chi2_per_dof), 1.0, 0.2) << s;
  }
  auto check = [&](const Eigen::MatrixXd& x, const Eigen::MatrixXd& sd, int k, double truth_value, const char* what) {
    const double mean = x.col(k).mean();
    const double spread = std::sqrt((x.col(k).array() - mean).square().sum() / (runs - 1));
    const double reported = sd.col(k).mean();
    std::printf("mode %d %s: mean %.6g (true %.6g), spread %.4g, reported %.4g, ratio %.3f, bias/std %+.3f\n", k, what,
                mean, truth_value, spread, reported, spread / reported, (mean - truth_value) / spread);
    EXPECT_NEAR(spread / reported, 1.0, 0.15) << what << k;
    EXPECT_LT(std::abs(mean - truth_value), 0.3 * spread) << what << k;
  };
  for (int k = 0; k < 2; ++k) {
    check(wn, wn_std, k, tm[static_cast<size_t>(k)].wn, "wn");
    check(zeta, zeta_std, k, tm[static_cast<size_t>(k)].zeta, "zeta");
  }
}

TEST(SsestFrequency, VariancesThatMissASystematicErrorAreReported) {
  // The data's variances 100 times too small: chi2_per_dof near 100, a warning naming use_variance, and the covariance
  // multiplied by it, so the reported standard deviations are those of the correct variances (to 15 %, the spread of
  // chi2 over one data set being far smaller). use_variance=false estimates the variances: chi2 near 1.
  const StateSpace truth = test::ss::two_modes();
  const Eigen::VectorXd w = log_grid(0.2, 30.0, 200);
  const FrequencyData right = noisy_frf(truth, w, 1e-3, 7);
  std::vector<Eigen::MatrixXd> small;
  for (const auto& v : right.variance()) small.push_back(v / 100.0);
  const FrequencyData wrong(w, right.matrices(), small);
  SsestOptions o;
  o.nx = 4;
  o.estimate_d = false;
  const Result<StateSpace> a = ssest(right, o), b = ssest(wrong, o);
  ASSERT_TRUE(a.usable() && b.usable());
  EXPECT_NEAR(b.diagnostics.get(diagnostic::chi2_per_dof), 100.0, 20.0);
  bool warned = false;
  for (const auto& m : b.diagnostics.warnings) warned = warned || m.find("use_variance=false") != std::string::npos;
  EXPECT_TRUE(warned);
  for (int k = 0; k < 2; ++k)
    EXPECT_NEAR(b.diagnostics.get(diagnostic::mode_wn_std)(k) / a.diagnostics.get(diagnostic::mode_wn_std)(k), 1.0, 0.15);
  o.use_variance = false;
  const Result<StateSpace> c = ssest(wrong, o);
  ASSERT_TRUE(c.usable());
  EXPECT_NEAR(c.diagnostics.get(diagnostic::chi2_per_dof), 1.0, 0.2);
}

TEST(FrequencyData, PeriodAveragingAndTheFrfMatrixOfPeriodicRecords) {
  // Two records of the two-mode 2x2 system (one multisine per input, lines 2..60 of a 512-sample period at
  // Ts = 0.05 s, 6 periods, a transient in the first, output noise 0.01): the FRF matrix at the 59 excited lines
  // matches G(j w_k) within 5 of its reported standard deviations; the reported variances agree with the scatter (mean of |G_hat - G|^2 / var within
  // 30 %: 59 x 4 terms estimate it to ~10 %, each variance from 5 periods).
  const StateSpace truth = test::ss::two_modes();
  const int period = 512;
  const std::vector<IdData> recs{test::ss::periodic_record(truth, period, 6, 0.05, 0, 1, 0.01),
                                 test::ss::periodic_record(truth, period, 6, 0.05, 1, 2, 0.01)};
  const FrequencyData fd = frf_from_periodic(recs, period, 1);
  ASSERT_EQ(fd.size(), 59);
  EXPECT_NEAR(fd.w()(0), 2 * 2 * std::numbers::pi / (period * 0.05), 1e-12);
  const std::vector<Eigen::MatrixXcd> G0 = frequency_response(truth, fd.w());
  double ratio = 0.0;
  int worst_in_sd = 0;
  for (int k = 0; k < fd.size(); ++k) {
    const Eigen::MatrixXd r2 = (fd.matrices()[static_cast<size_t>(k)] - G0[static_cast<size_t>(k)]).cwiseAbs2();
    const Eigen::MatrixXd q = r2.cwiseQuotient(fd.variance()[static_cast<size_t>(k)]);
    ratio += q.sum() / (4.0 * fd.size());
    worst_in_sd = std::max(worst_in_sd, static_cast<int>(std::sqrt(q.maxCoeff())));
  }
  EXPECT_LT(worst_in_sd, 5);
  EXPECT_NEAR(ratio, 1.0, 0.3);
  // Keeping the transient's period biases the estimate: its squared error several times that without it.
  const FrequencyData with_transient = frf_from_periodic(recs, period, 0);
  double e0 = 0.0, e1 = 0.0;
  for (int k = 0; k < fd.size(); ++k) {
    e0 += (with_transient.matrices()[static_cast<size_t>(k)] - G0[static_cast<size_t>(k)]).squaredNorm();
    e1 += (fd.matrices()[static_cast<size_t>(k)] - G0[static_cast<size_t>(k)]).squaredNorm();
  }
  std::printf("squared FRF error with the transient period %.3g, without %.3g\n", e0, e1);
  EXPECT_GT(e0, 3 * e1);
  // The mean period: noise divided by the 5 periods averaged (its standard deviation 0.01 / sqrt(5) to 10 %).
  const IdData mean = average_periods(recs[0], period, 1);
  ASSERT_EQ(mean.size(), period);
  const IdData clean = test::ss::periodic_record(truth, period, 6, 0.05, 0, 1, 0.0);
  Eigen::MatrixXd steady = Eigen::MatrixXd::Zero(period, 2);
  for (int p = 1; p < 6; ++p) steady += clean.y().middleRows(p * period, period) / 5.0;
  const double sd = std::sqrt((mean.y() - steady).squaredNorm() / (2.0 * period));
  EXPECT_NEAR(sd, 0.01 / std::sqrt(5.0), 0.1 * 0.01 / std::sqrt(5.0));
  // And the state space fitted to the FRF: the modes within 4 of their standard deviations.
  SsestOptions o;
  o.nx = 4;
  const Result<StateSpace> r = ssest(fd, o);
  ASSERT_TRUE(r.usable()) << r.why_not_usable();
  const std::vector<Mode> m = r.model.modes(), tm = truth.modes();
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_LT(std::abs(m[k].wn - tm[k].wn), 4 * r.diagnostics.get(diagnostic::mode_wn_std)(static_cast<Eigen::Index>(k)));
    EXPECT_LT(std::abs(m[k].zeta - tm[k].zeta), 4 * r.diagnostics.get(diagnostic::mode_zeta_std)(static_cast<Eigen::Index>(k)));
  }
  EXPECT_NEAR(r.diagnostics.get(diagnostic::chi2_per_dof), 1.0, 0.3);
}

TEST(FrequencyData, BadInputIsNamed) {
  const Eigen::VectorXd w = log_grid(1.0, 10.0, 3);
  std::vector<Eigen::MatrixXcd> G(3, Eigen::MatrixXcd::Ones(2, 1));
  EXPECT_THROW(FrequencyData(w, G, std::vector<Eigen::MatrixXd>(3, Eigen::MatrixXd::Zero(2, 1))), InvalidArgument);
  EXPECT_THROW(FrequencyData(w, std::vector<Eigen::MatrixXcd>(2, Eigen::MatrixXcd::Ones(2, 1))), InvalidArgument);
  std::vector<Eigen::MatrixXcd> mixed = G;
  mixed[1] = Eigen::MatrixXcd::Ones(1, 1);
  EXPECT_THROW(FrequencyData(w, mixed), InvalidArgument);
  const FrequencyData mimo(w, G);
  EXPECT_THROW((void)mimo.response(), InvalidArgument);
  EXPECT_THROW((void)mimo.channel(2, 0), InvalidArgument);
  EXPECT_THROW(tf_from_frequency(mimo, TfOrders{1, 1, 0}), InvalidArgument);
  SsestOptions o;
  o.fixed["A1_1"] = 0.0;
  EXPECT_THROW(ssest(mimo, o), InvalidOptions);
  o.fixed.clear();
  o.integrators = 1;
  EXPECT_THROW(ssest(mimo, o), InvalidOptions);
  o.integrators = 0;
  o.starts = 2;  // multi-start draws around the subspace start of records
  EXPECT_THROW(ssest(mimo, o), InvalidOptions);
  // Periodic records: one per input, whole periods, two after the transient for a variance.
  const StateSpace truth = test::ss::two_modes();
  const IdData rec = test::ss::periodic_record(truth, 64, 3, 0.05, 0, 1, 0.01);
  EXPECT_THROW(frf_from_periodic({rec}, 64, 1), InvalidArgument);       // 2 inputs need 2 records
  EXPECT_THROW(frf_from_periodic({rec, rec}, 64, 2), InvalidArgument);  // one period left
  EXPECT_THROW(frf_from_periodic({rec, rec}, 64, 1), InvalidArgument);  // the same input twice: dependent
  EXPECT_THROW(average_periods(rec, 1, 0), InvalidArgument);
  EXPECT_THROW(average_periods(rec, 64, 3), InvalidArgument);
}

}  // namespace
}  // namespace ctid
