#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/data/input_design.hpp"

using namespace ctid;

TEST(IdData, UniformAndIrregularTimes) {
  IdData d(Eigen::VectorXd::LinSpaced(5, 0, 4), Eigen::VectorXd::Ones(5), 0.5, 2.0);
  EXPECT_TRUE(d.is_uniform());
  EXPECT_DOUBLE_EQ(d.time(4), 4.0);
  EXPECT_DOUBLE_EQ(d.duration(), 2.0);
  IdData r(Eigen::VectorXd::Ones(3), Eigen::VectorXd::Ones(3), Eigen::VectorXd{{0.0, 0.1, 0.35}});
  EXPECT_FALSE(r.is_uniform());
  EXPECT_THROW(r.ts(), InvalidArgument);
  EXPECT_DOUBLE_EQ(r.time(2), 0.35);
  // from_times: steps of 0.1 with rounding (0.30000000000000004) are uniform; so is a time 1e-6 s = 1e-5 Ts off the
  // grid (a logger's jitter, reported as the deviation); 2e-3 Ts off (above kUniformTimeTolerance = 1e-3) is not.
  Eigen::VectorXd t(5);
  for (int k = 0; k < 5; ++k) t(k) = 1.0 + k * 0.1;
  const IdData f = IdData::from_times(Eigen::VectorXd::Ones(5), Eigen::VectorXd::Ones(5), t);
  ASSERT_TRUE(f.is_uniform());
  EXPECT_NEAR(f.ts(), 0.1, 1e-15);
  EXPECT_DOUBLE_EQ(f.t0(), 1.0);
  EXPECT_LT(f.uniform_time_deviation(), 1e-12);
  t(2) += 1e-6;
  const IdData jittered = IdData::from_times(Eigen::VectorXd::Ones(5), Eigen::VectorXd::Ones(5), t);
  ASSERT_TRUE(jittered.is_uniform());
  EXPECT_NEAR(jittered.uniform_time_deviation(), 1e-5, 1e-12);
  EXPECT_NEAR(jittered.ts(), 0.1, 1e-15);
  t(2) += 2e-4 - 1e-6;
  EXPECT_FALSE(IdData::from_times(Eigen::VectorXd::Ones(5), Eigen::VectorXd::Ones(5), t).is_uniform());
  // A clock drift (steps growing from 0.1 to 0.101 s): the middle sample is 1.24 Ts off the uniform grid through the
  // ends: irregular.
  Eigen::VectorXd drift(1001);
  for (int k = 0; k <= 1000; ++k) drift(k) = 0.1 * k + 0.1 * 1e-5 * k * k / 2;
  const IdData dr = IdData::from_times(Eigen::VectorXd::Ones(1001), Eigen::VectorXd::Ones(1001), drift);
  EXPECT_FALSE(dr.is_uniform());
  EXPECT_EQ(dr.uniform_time_deviation(), 0.0);
  EXPECT_THROW(IdData::from_times(Eigen::VectorXd::Ones(2), Eigen::VectorXd::Ones(2), Eigen::Vector2d(1.0, 1.0)),
               InvalidArgument);
}

TEST(IdData, BadInputMessagesNameTheValues) {
  try {
    IdData(Eigen::VectorXd::Ones(1000), Eigen::VectorXd::Ones(999), 0.1);
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_STREQ(e.what(), "IdData: u and y need the same number of samples (u has 1000, y has 999)");
  }
  Eigen::VectorXd y = Eigen::VectorXd::Ones(4);
  y(2) = NAN;
  EXPECT_THROW(IdData(Eigen::VectorXd::Ones(4), y, 0.1), InvalidArgument);
  EXPECT_THROW(IdData(Eigen::VectorXd::Ones(4), Eigen::VectorXd::Ones(4), 0.0), InvalidArgument);
  try {
    IdData(Eigen::VectorXd::Ones(3), Eigen::VectorXd::Ones(3), Eigen::VectorXd{{0.0, 0.2, 0.1}});
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("t[2] = 0.1 follows t[1] = 0.2"), std::string::npos) << e.what();
  }
}

TEST(IdData, SliceSplitSelectDetrend) {
  const int N = 100;
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(N, 0, 9.9);
  Eigen::MatrixXd u(N, 2);
  u.col(0) = 3.0 + 2.0 * t.array();
  u.col(1) = Eigen::VectorXd::Constant(N, 5.0);
  IdData d(u, Eigen::VectorXd(1.0 + t.array().sin()), 0.1);
  d.set_input_names({"flow", "valve"});
  EXPECT_EQ(d.input_index("valve"), 1);
  EXPECT_THROW(d.input_index("temp"), InvalidArgument);
  const auto [est, val] = d.split(0.7);
  EXPECT_EQ(est.size(), 70);
  EXPECT_EQ(val.size(), 30);
  EXPECT_DOUBLE_EQ(val.time(0), 7.0);
  const IdData s = d.select({1}, {0});
  EXPECT_EQ(s.nu(), 1);
  EXPECT_EQ(s.input_names()[0], "valve");
  TrendInfo info;
  const IdData lin = d.detrend(Detrend::Linear, &info);
  EXPECT_NEAR(info.u_slope(0), 2.0, 1e-12);
  EXPECT_NEAR(info.u_offset(0), 3.0, 1e-12);
  EXPECT_LT(lin.u().col(0).cwiseAbs().maxCoeff(), 1e-12);
  const IdData mean = d.detrend(Detrend::Mean);
  EXPECT_NEAR(mean.y().mean(), 0.0, 1e-14);
  EXPECT_THROW(d.slice(50, 40), InvalidArgument);
  // The trend of the first 70 samples removed from the last 30 (a held-out record): input 1 is the line 3 + 2 t
  // (slope 2, offset 3 at t = 0), so the estimation record's line removes it exactly from the later samples too,
  // while the validation record's own mean would not be used.
  TrendInfo est_trend;
  (void)est.detrend(Detrend::Linear, &est_trend);
  const IdData held = val.remove_trend(est_trend);
  EXPECT_LT(held.u().col(0).cwiseAbs().maxCoeff(), 1e-11);
  TrendInfo est_mean;
  (void)est.detrend(Detrend::Mean, &est_mean);
  EXPECT_NEAR(val.remove_trend(est_mean).y()(0, 0), val.y()(0, 0) - est.y().mean(), 1e-14);
  EXPECT_THROW((void)s.remove_trend(est_trend), InvalidArgument);  // 1 input, the trend has 2
}

TEST(InputDesign, PrbsHasMaximalPeriod) {
  // A maximum-length sequence repeats after exactly 2^n - 1 bits and has 2^(n-1) ones per period.
  for (int n = 2; n <= 16; ++n) {
    PrbsOptions o;
    o.register_length = n;
    const int P = (1 << n) - 1;
    const Eigen::VectorXd s = prbs(2 * P, o);
    EXPECT_EQ(s.head(P), s.tail(P)) << n;
    EXPECT_EQ(static_cast<int>((s.head(P).array() > 0).count()), 1 << (n - 1)) << n;
    for (int p = 1; p < P; ++p)  // no shorter period
      if (P % p == 0) EXPECT_NE(s.head(P - p), s.segment(p, P - p)) << n << " " << p;
  }
  PrbsOptions o;
  o.register_length = 10;
  o.clock_period = 7;
  EXPECT_EQ(prbs(7161, o).size(), 7161);  // 1023 bits x 7 samples (Rao-Garnier set-up)
  o.register_length = 40;
  EXPECT_THROW(prbs(10, o), InvalidArgument);
}

TEST(InputDesign, NoiseAtRequestedSnrIsReproducible) {
  const Eigen::VectorXd x = (Eigen::VectorXd::LinSpaced(20000, 0, 200)).array().sin();
  const Eigen::VectorXd y1 = add_noise_snr(x, 10.0, 42), y2 = add_noise_snr(x, 10.0, 42);
  EXPECT_EQ(y1, y2);
  const double snr = 10 * std::log10((x.array() - x.mean()).square().mean() / (y1 - x).array().square().mean());
  EXPECT_NEAR(snr, 10.0, 0.1);  // 20000 samples: the noise-variance estimate has ~1 % error (0.04 dB)
  EXPECT_THROW(add_noise_snr(Eigen::VectorXd::Ones(10), 10, 1), InvalidArgument);
}

TEST(InputDesign, MultisineStepsRandomBinary) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(11, 0, 1);
  const Eigen::VectorXd m = multisine(t, {2.0}, {3.0}, {0.0});
  EXPECT_NEAR(m(10), 3 * std::sin(2.0), 1e-15);
  const Eigen::VectorXd s = steps(t, {0.25, 0.55}, {1.0, -2.0});
  EXPECT_EQ(s(2), 0.0);
  EXPECT_EQ(s(3), 1.0);
  EXPECT_EQ(s(6), -2.0);
  const Eigen::VectorXd rb = random_binary(1000, 9, 5, 2.0);
  EXPECT_EQ(std::set<double>(rb.begin(), rb.end()), (std::set<double>{-2.0, 2.0}));
  for (int k = 0; k < 1000; ++k) EXPECT_EQ(rb(k), rb(k - k % 5));
}
