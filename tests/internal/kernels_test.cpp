// The numerical kernels of src/internal, each against an independent reference: Levenberg-Marquardt on the
// Rosenbrock problem (known optimum, with and without a bound) and on a linear problem (the normal equations); the
// streaming, Gram and instrumental-variable least squares against Eigen's column-pivoting QR of the stacked rows;
// Dormand-Prince and the BDF integrator (CVODES) against closed-form solutions, a stiff one and a sensitivity
// included. The estimators' tests exercise the kernels through the methods; these pin each kernel alone.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "internal/least_squares.hpp"
#include "internal/levenberg_marquardt.hpp"
#include "internal/ode.hpp"

namespace {
using namespace ctid::internal;

// Rosenbrock in least-squares form: r = [10 (x2 - x1^2), 1 - x1]; the minimum is x = (1, 1), cost 0.
bool rosenbrock(const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
  r.resize(2);
  r << 10 * (x(1) - x(0) * x(0)), 1 - x(0);
  if (J) {
    J->resize(2, 2);
    *J << -20 * x(0), 10, -1, 0;
  }
  return true;
}

const Eigen::VectorXd kFree = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());

TEST(Kernels, LevenbergMarquardtFindsTheRosenbrockMinimum) {
  LmOptions o;
  o.max_iterations = 200;
  const LmResult r = levenberg_marquardt(LmEvaluate(rosenbrock), Eigen::Vector2d(-1.2, 1.0), -kFree, kFree, o);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_NEAR(r.x(0), 1.0, 1e-8);
  EXPECT_NEAR(r.x(1), 1.0, 1e-8);
  EXPECT_LT(r.cost, 1e-16);
  // J^T J at the optimum: J = [-20 10; -1 0].
  EXPECT_NEAR(r.jtj(0, 0), 401.0, 1e-5);
  EXPECT_NEAR(r.jtj(0, 1), -200.0, 1e-5);
  EXPECT_NEAR(r.jtj(1, 1), 100.0, 1e-8);
  // The same problem through the normal equations (J^T J and J^T r from the caller) reaches the same point.
  const LmNormalEvaluate normal = [](const Eigen::VectorXd& x, double& cost, Eigen::MatrixXd* jtj, Eigen::VectorXd* jtr) {
    Eigen::VectorXd r;
    Eigen::MatrixXd J;
    rosenbrock(x, r, &J);
    cost = 0.5 * r.squaredNorm();
    if (jtj) *jtj = J.transpose() * J;
    if (jtr) *jtr = J.transpose() * r;
    return true;
  };
  const LmResult n = levenberg_marquardt(normal, Eigen::Vector2d(-1.2, 1.0), -kFree, kFree, o);
  ASSERT_TRUE(n.converged) << n.message;
  EXPECT_NEAR(n.x(0), 1.0, 1e-8);
  EXPECT_NEAR(n.x(1), 1.0, 1e-8);
}

TEST(Kernels, LevenbergMarquardtRespectsABound) {
  // With x1 <= 0.5 the minimum of 100 (x2 - x1^2)^2 + (1 - x1)^2 is on the bound: x = (0.5, 0.25), cost 1/2 * 0.25.
  LmOptions o;
  o.max_iterations = 200;
  const Eigen::Vector2d upper(0.5, std::numeric_limits<double>::infinity());
  const LmResult r = levenberg_marquardt(LmEvaluate(rosenbrock), Eigen::Vector2d(-1.2, 1.0), -kFree, upper, o);
  EXPECT_NEAR(r.x(0), 0.5, 1e-8);
  EXPECT_NEAR(r.x(1), 0.25, 1e-8);
  EXPECT_NEAR(r.cost, 0.125, 1e-12);
}

TEST(Kernels, LevenbergMarquardtOnALinearProblemIsTheLeastSquaresSolution) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  const int n = 200, p = 3;
  Eigen::MatrixXd A(n, p);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < p; ++j) A(i, j) = g(rng);
    b(i) = 1.5 * A(i, 0) - 2 * A(i, 1) + 0.25 * A(i, 2) + 0.1 * g(rng);
  }
  const LmEvaluate linear = [&](const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    r = A * x - b;
    if (J) *J = A;
    return true;
  };
  const Eigen::VectorXd inf = Eigen::VectorXd::Constant(p, std::numeric_limits<double>::infinity());
  const LmResult r = levenberg_marquardt(linear, Eigen::VectorXd::Zero(p), -inf, inf, {});
  const Eigen::VectorXd reference = A.colPivHouseholderQr().solve(b);
  EXPECT_LE((r.x - reference).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LE((r.jtj - A.transpose() * A).cwiseAbs().maxCoeff(), 1e-9 * (A.transpose() * A).norm());
}

// A weighted least-squares problem and its reference by QR of the weighted rows.
struct Problem {
  Eigen::MatrixXd X;
  Eigen::VectorXd y, w;
};
Problem problem(int n, int p, bool weighted, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> uw(0.2, 3.0);
  Problem q{Eigen::MatrixXd(n, p), Eigen::VectorXd(n), Eigen::VectorXd::Ones(n)};
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < p; ++j) q.X(i, j) = g(rng) * (1.0 + j);  // columns of different scales
    q.y(i) = q.X.row(i).sum() + 0.05 * g(rng);
    if (weighted) q.w(i) = uw(rng);
  }
  return q;
}

TEST(Kernels, StreamingAndGramLeastSquaresEqualQrOfTheStackedRows) {
  for (bool weighted : {false, true}) {
    const Problem q = problem(1500, 4, weighted, 11);
    const Eigen::VectorXd sw = q.w.cwiseSqrt();
    const Eigen::MatrixXd Xw = sw.asDiagonal() * q.X;
    const Eigen::VectorXd yw = sw.asDiagonal() * q.y;
    const Eigen::VectorXd theta = Xw.colPivHouseholderQr().solve(yw);
    // The kernels scale the weights to sum to the effective number of rows, (sum w)^2 / sum w^2, so that the
    // covariance is the ordinary one for equal weights: their rss is the weighted one times sum w / sum w^2.
    const double rss = (yw - Xw * theta).squaredNorm() * q.w.sum() / q.w.squaredNorm();
    StreamingLeastSquares s(4, 100);  // a block smaller than the record: several compressions
    GramLeastSquares gls(4, 64);
    for (int i = 0; i < q.X.rows(); ++i) {
      const Eigen::RowVectorXd row = q.X.row(i);
      s.add(row.data(), q.y(i), q.w(i));
      gls.add(row.data(), q.y(i), q.w(i));
    }
    for (const LinearSolution& sol : {s.solve(), gls.solve()}) {
      EXPECT_LE((sol.theta - theta).cwiseAbs().maxCoeff(), 1e-10 * theta.cwiseAbs().maxCoeff()) << weighted;
      EXPECT_NEAR(sol.rss, rss, 1e-8 * rss) << weighted;
      EXPECT_FALSE(sol.rank_deficient);
      if (!weighted) {  // sigma^2 (X^T X)^-1 with sigma^2 = rss / (n - p)
        const Eigen::MatrixXd cov = rss / (q.X.rows() - 4) * (q.X.transpose() * q.X).inverse();
        EXPECT_LE((sol.covariance - cov).cwiseAbs().maxCoeff(), 1e-8 * cov.cwiseAbs().maxCoeff());
      }
    }
  }
}

TEST(Kernels, InstrumentalVariablesWithTheRegressorsAsInstrumentsIsLeastSquares) {
  const Problem q = problem(800, 3, false, 5);
  InstrumentalVariables iv(3);
  for (int i = 0; i < q.X.rows(); ++i) {
    const Eigen::RowVectorXd row = q.X.row(i);
    iv.add(row.data(), row.data(), q.y(i));
  }
  const LinearSolution sol = iv.solve();
  const Eigen::VectorXd theta = q.X.colPivHouseholderQr().solve(q.y);
  EXPECT_LE((sol.theta - theta).cwiseAbs().maxCoeff(), 1e-10 * theta.cwiseAbs().maxCoeff());
  // With Z = X the IV sandwich sigma^2 (Z'X)^-1 Z'Z (X'Z)^-1 is the least-squares covariance.
  const double rss = (q.y - q.X * theta).squaredNorm();
  const Eigen::MatrixXd cov = rss / (q.X.rows() - 3) * (q.X.transpose() * q.X).inverse();
  EXPECT_LE((sol.covariance - cov).cwiseAbs().maxCoeff(), 1e-8 * cov.cwiseAbs().maxCoeff());
  // A rank-deficient problem (a column twice) is said to be.
  StreamingLeastSquares s(2);
  for (int i = 0; i < 50; ++i) {
    const double x[2] = {q.X(i, 0), q.X(i, 0)};
    s.add(x, q.y(i));
  }
  EXPECT_TRUE(s.solve().rank_deficient);
}

TEST(Kernels, DormandPrinceFollowsClosedFormSolutions) {
  // dx/dt = -2 x + u, u = 1 held: x(t) = (1 - e^{-2t}) / 2; and the oscillator x'' = -9 x, x(0) = 1: x = cos 3t.
  const int N = 201;
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(N, 0.0, 4.0);
  const Eigen::MatrixXd u = Eigen::MatrixXd::Ones(N, 1);
  double err = 0;
  const OdeOutcome a = dopri45([](double, const Eigen::VectorXd& x, const double* in, Eigen::VectorXd& dx) { dx(0) = -2 * x(0) + in[0]; },
                               Eigen::VectorXd::Zero(1), u, t, Between::Hold, 1e-11, 1e-13, 1,
                               [&](Eigen::Index k, const Eigen::VectorXd& x) {
                                 err = std::max(err, std::abs(x(0) - 0.5 * (1 - std::exp(-2 * t(k)))));
                               });
  ASSERT_TRUE(a.ok);
  EXPECT_LT(err, 1e-9);
  err = 0;
  const OdeOutcome b = dopri45([](double, const Eigen::VectorXd& x, const double*, Eigen::VectorXd& dx) {
                                 dx(0) = x(1);
                                 dx(1) = -9 * x(0);
                               },
                               Eigen::Vector2d(1.0, 0.0), Eigen::MatrixXd::Zero(N, 0), t, Between::Hold, 1e-11, 1e-13, 2,
                               [&](Eigen::Index k, const Eigen::VectorXd& x) {
                                 err = std::max(err, std::abs(x(0) - std::cos(3 * t(k))));
                               });
  ASSERT_TRUE(b.ok);
  EXPECT_LT(err, 1e-8);
  // A solution that escapes is reported, with where.
  const OdeOutcome c = dopri45([](double, const Eigen::VectorXd& x, const double*, Eigen::VectorXd& dx) { dx(0) = x(0) * x(0); },
                               Eigen::VectorXd::Ones(1), Eigen::MatrixXd::Zero(N, 0), t, Between::Hold, 1e-8, 1e-10, 1,
                               [](Eigen::Index, const Eigen::VectorXd&) {});
  EXPECT_FALSE(c.ok);
  EXPECT_NEAR(c.t, 1.0, 1e-3);  // x = 1 / (1 - t) blows up at t = 1
}

TEST(Kernels, BdfSolvesAStiffProblemAndItsSensitivity) {
  // dx/dt = -1000 (x - cos t) - sin t, x(0) = 1: x = cos t; stiff (eigenvalue -1000) over 5 s.
  const int N = 101;
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(N, 0.0, 5.0);
  double err = 0;
  const OdeOutcome a = bdf(
      [](double tt, const double* x, const double*, double* dx, Eigen::MatrixXd* J, Eigen::MatrixXd*) {
        dx[0] = -1000 * (x[0] - std::cos(tt)) - std::sin(tt);
        if (J) (*J)(0, 0) = -1000;
      },
      1, Eigen::VectorXd::Ones(1), Eigen::MatrixXd::Zero(N, 0), t, Between::Hold, 1e-9, 1e-12,
      [&](Eigen::Index k, const Eigen::VectorXd& x) { err = std::max(err, std::abs(x(0) - std::cos(t(k)))); });
  ASSERT_TRUE(a.ok);
  EXPECT_LT(err, 1e-6);
  // dx/dt = -q x, x(0) = 1 with the sensitivity S = dx/dq: x = e^{-q t}, S = -t e^{-q t} (q = 3).
  double xerr = 0, serr = 0;
  const OdeOutcome b = bdf(
      [](double, const double* x, const double*, double* dx, Eigen::MatrixXd* J, Eigen::MatrixXd* B) {
        dx[0] = -3 * x[0];
        if (J) (*J)(0, 0) = -3;
        if (B) (*B)(0, 0) = -x[0];
      },
      1, Eigen::Vector2d(1.0, 0.0), Eigen::MatrixXd::Zero(N, 0), t, Between::Hold, 1e-10, 1e-13,
      [&](Eigen::Index k, const Eigen::VectorXd& x) {
        const double e = std::exp(-3 * t(k));
        xerr = std::max(xerr, std::abs(x(0) - e));
        serr = std::max(serr, std::abs(x(1) + t(k) * e));
      });
  ASSERT_TRUE(b.ok);
  EXPECT_LT(xerr, 1e-7);
  EXPECT_LT(serr, 1e-6);
}

}  // namespace
