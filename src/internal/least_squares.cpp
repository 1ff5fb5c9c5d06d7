#include "internal/least_squares.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include "ctid/core/check.hpp"

namespace ctid::internal {

double scaled_condition(const Eigen::MatrixXd& M) {
  if (M.size() == 0) return 1.0;
  Eigen::MatrixXd S = M;
  for (Eigen::Index j = 0; j < S.cols(); ++j) {
    const double nj = S.col(j).norm();
    if (nj > 0) S.col(j) /= nj;
  }
  return condition_number(S);
}

double condition_number(const Eigen::MatrixXd& M) {
  if (M.size() == 0) return 0.0;
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(M).singularValues();
  const double smin = sv(sv.size() - 1);
  return smin > 0 ? sv(0) / smin : std::numeric_limits<double>::infinity();
}

StreamingLeastSquares::StreamingLeastSquares(int p, int block)
    : p_(p), buf_(Eigen::MatrixXd::Zero(p + 1 + block, p + 1)), fill_(p + 1), qr_(p + 1 + block, p + 1) {
  CTID_ASSERT(p >= 1 && block >= 1);
}

void StreamingLeastSquares::compress() {
  if (fill_ == p_ + 1) return;
  const Eigen::Index rows = fill_;
  qr_.compute(buf_.topRows(rows));
  const Eigen::Index k = std::min<Eigen::Index>(rows, p_ + 1);
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(p_ + 1, p_ + 1);
  R.topRows(k) = qr_.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  buf_.setZero();
  buf_.topRows(p_ + 1) = R;
  fill_ = p_ + 1;
}

LinearSolution StreamingLeastSquares::solve(double tol) {
  compress();
  LinearSolution s;
  s.n_rows = rows_;
  // Rescale weights so that their sum equals the effective sample size (Kish); with
  // equal weights this is the ordinary LS covariance.
  const double neff = m_.sumw2 > 0 ? m_.sumw * m_.sumw / m_.sumw2 : 0.0;
  const double c = m_.sumw > 0 ? neff / m_.sumw : 1.0;
  const Eigen::MatrixXd Ra = buf_.topRows(p_ + 1) * std::sqrt(c);
  const Eigen::MatrixXd R = Ra.topLeftCorner(p_, p_);
  const Eigen::VectorXd z = Ra.col(p_).head(p_);
  s.rss = Ra(p_, p_) * Ra(p_, p_);
  s.tss = c * m_.m2;
  s.condition = scaled_condition(R);
  s.rank_deficient = !(s.condition < 1.0 / tol);
  if (s.rank_deficient) {
    s.theta = R.completeOrthogonalDecomposition().solve(z);
  } else {
    s.theta = R.triangularView<Eigen::Upper>().solve(z);
  }
  s.sigma2 = neff > p_ ? s.rss / (neff - p_) : std::numeric_limits<double>::quiet_NaN();
  if (!s.rank_deficient) {
    const Eigen::MatrixXd Rinv = R.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(p_, p_));
    s.covariance = s.sigma2 * Rinv * Rinv.transpose();
  } else {
    s.covariance = Eigen::MatrixXd::Constant(p_, p_, std::numeric_limits<double>::quiet_NaN());
  }
  return s;
}

GramLeastSquares::GramLeastSquares(int p, int block)
    : p_(p), g_(Eigen::MatrixXd::Zero(p + 1, p + 1)), buf_(p + 1, block) {
  CTID_ASSERT(p >= 1 && block >= 1);
}

void GramLeastSquares::flush() {
  if (fill_ == 0) return;
  g_.selfadjointView<Eigen::Lower>().rankUpdate(buf_.leftCols(fill_));
  fill_ = 0;
}

LinearSolution GramLeastSquares::solve(double tol) {
  flush();
  LinearSolution s;
  s.n_rows = rows_;
  Eigen::MatrixXd G = g_.selfadjointView<Eigen::Lower>();
  const double neff = m_.sumw2 > 0 ? m_.sumw * m_.sumw / m_.sumw2 : 0.0;
  const double c = m_.sumw > 0 ? neff / m_.sumw : 1.0;
  G *= c;
  const Eigen::MatrixXd Gxx = G.topLeftCorner(p_, p_);
  const Eigen::VectorXd gxy = G.col(p_).head(p_);
  // Scale to unit diagonal: cond(X_scaled) = sqrt(cond(D^-1/2 Gxx D^-1/2)).
  Eigen::VectorXd d = Gxx.diagonal().cwiseMax(1e-300).cwiseSqrt();
  const Eigen::MatrixXd Gs = d.cwiseInverse().asDiagonal() * Gxx * d.cwiseInverse().asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Gs, Eigen::EigenvaluesOnly);
  const double lmin = es.eigenvalues()(0), lmax = es.eigenvalues()(p_ - 1);
  s.condition = lmin > 0 ? std::sqrt(lmax / lmin) : std::numeric_limits<double>::infinity();
  s.rank_deficient = !(s.condition < 1.0 / tol);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(Gs);
  const Eigen::VectorXd ts = ldlt.solve(gxy.cwiseQuotient(d));
  s.theta = ts.cwiseQuotient(d);
  s.rss = std::max(0.0, G(p_, p_) - gxy.dot(s.theta));
  s.tss = c * m_.m2;
  s.sigma2 = neff > p_ ? s.rss / (neff - p_) : std::numeric_limits<double>::quiet_NaN();
  if (!s.rank_deficient) {
    const Eigen::MatrixXd inv = ldlt.solve(Eigen::MatrixXd::Identity(p_, p_));
    s.covariance = s.sigma2 * d.cwiseInverse().asDiagonal() * inv * d.cwiseInverse().asDiagonal();
  } else {
    s.covariance = Eigen::MatrixXd::Constant(p_, p_, std::numeric_limits<double>::quiet_NaN());
  }
  return s;
}

InstrumentalVariables::InstrumentalVariables(int p, bool with_rss)
    : p_(p), with_rss_(with_rss), zx_(Eigen::MatrixXd::Zero(p, p)), zz_(Eigen::MatrixXd::Zero(p, p)), xx_(Eigen::MatrixXd::Zero(p, p)),
      zy_(Eigen::VectorXd::Zero(p)), xy_(Eigen::VectorXd::Zero(p)) {}

void InstrumentalVariables::add(const double* z, const double* x, double y, double w) {
  // Column-major storage: (i, j) at j * p + i; the symmetric zz and xx keep their upper triangle.
  double* zx = zx_.data();
  double* zz = zz_.data();
  for (int j = 0; j < p_; ++j) {
    const double wxj = w * x[j], wzj = w * z[j];
    for (int i = 0; i < p_; ++i) zx[j * p_ + i] += z[i] * wxj;
    for (int i = 0; i <= j; ++i) zz[j * p_ + i] += z[i] * wzj;
    zy_(j) += wzj * y;
  }
  if (with_rss_) {
    double* xx = xx_.data();
    for (int j = 0; j < p_; ++j) {
      const double wxj = w * x[j];
      for (int i = 0; i <= j; ++i) xx[j * p_ + i] += x[i] * wxj;
      xy_(j) += wxj * y;
    }
  }
  yy_ += w * y * y;
  sumw_ += w;
  sumw2_ += w * w;
  ++rows_;
}

LinearSolution InstrumentalVariables::solve(double tol) const {
  LinearSolution s;
  s.n_rows = rows_;
  const double neff = sumw2_ > 0 ? sumw_ * sumw_ / sumw2_ : 0.0;
  const double c = sumw_ > 0 ? neff / sumw_ : 1.0;
  // Two-sided scaling of Z^T X: rows by the instrument norms, columns by the regressor norms, so that the
  // result does not depend on the units of u and y (a u in uV and a y in MV give the same condition).
  const Eigen::MatrixXd zzf = zz(), xxf = xx_.selfadjointView<Eigen::Upper>();
  Eigen::VectorXd d(p_), r(p_);
  for (int j = 0; j < p_; ++j) {
    d(j) = std::sqrt(std::max(with_rss_ ? xxf(j, j) : zx_.col(j).norm(), 1e-300));
    r(j) = std::sqrt(std::max(zzf(j, j), 1e-300));
  }
  const Eigen::MatrixXd A = r.cwiseInverse().asDiagonal() * zx_ * d.cwiseInverse().asDiagonal();
  s.condition = scaled_condition(A);
  s.rank_deficient = !(s.condition < 1.0 / tol);
  const Eigen::VectorXd b = zy_.cwiseQuotient(r);
  const Eigen::VectorXd ts = s.rank_deficient ? Eigen::VectorXd(A.completeOrthogonalDecomposition().solve(b))
                                               : Eigen::VectorXd(A.fullPivLu().solve(b));
  s.theta = ts.cwiseQuotient(d);
  s.rss = with_rss_ ? std::max(0.0, c * (yy_ - 2.0 * s.theta.dot(xy_) + s.theta.dot(xxf * s.theta)))
                    : std::numeric_limits<double>::quiet_NaN();
  s.sigma2 = neff > p_ ? s.rss / (neff - p_) : std::numeric_limits<double>::quiet_NaN();
  if (!s.rank_deficient) {
    const Eigen::MatrixXd inv = d.cwiseInverse().asDiagonal() * A.fullPivLu().inverse() * r.cwiseInverse().asDiagonal();
    s.covariance = s.sigma2 * inv * zzf * inv.transpose() / c;
  } else {
    s.covariance = Eigen::MatrixXd::Constant(p_, p_, std::numeric_limits<double>::quiet_NaN());
  }
  return s;
}

Eigen::MatrixXd covariance(const Eigen::MatrixXd& information, double sigma2) {
  const Eigen::Index p = information.rows();
  if (p == 0 || information.cols() != p || !std::isfinite(sigma2)) return {};
  return sigma2 * information.ldlt().solve(Eigen::MatrixXd::Identity(p, p));
}

double gram_condition(const Eigen::MatrixXd& jtj) {
  const Eigen::Index p = jtj.rows();
  if (p == 0 || jtj.cols() != p || !jtj.allFinite()) return NAN;
  const Eigen::VectorXd dg = jtj.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::VectorXd ev =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dg.asDiagonal() * jtj * dg.asDiagonal(), Eigen::EigenvaluesOnly)
          .eigenvalues();
  return ev(0) > 0 ? std::sqrt(ev(p - 1) / ev(0)) : INFINITY;
}

std::string unidentifiable(const Eigen::MatrixXd& jtj, const Eigen::VectorXd& x, const std::vector<std::string>& names) {
  const Eigen::Index p = jtj.rows();
  for (Eigen::Index i = 0; i < p; ++i)
    if (!(jtj(i, i) > 0))
      return detail::format("the output does not depend on {} at the estimate: the data cannot determine it; fix it or "
                            "remove it from the model", names[static_cast<size_t>(i)]);
  if (p < 2) return "";
  const Eigen::VectorXd d = jtj.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(d.asDiagonal() * jtj * d.asDiagonal());
  const double ratio = es.eigenvalues()(0) / es.eigenvalues()(p - 1);
  if (es.info() != Eigen::Success || ratio >= 1e-11) return "";
  // The direction in relative units of each parameter (absolute where the value is 0).
  Eigen::VectorXd rel = es.eigenvectors().col(0).cwiseProduct(d);
  for (Eigen::Index i = 0; i < p; ++i) rel(i) /= std::max(std::abs(x(i)), 1e-300);
  Eigen::Index big = 0;
  rel.cwiseAbs().maxCoeff(&big);
  rel /= rel(big);  // the largest change +1
  for (Eigen::Index i = 0; i < p; ++i)  // the first named parameter leads with +
    if (std::abs(rel(i)) > 0.05) {
      if (rel(i) < 0) rel = -rel;
      break;
    }
  std::string which, along;
  std::vector<std::string> involved;
  for (Eigen::Index i = 0; i < p; ++i)
    if (std::abs(rel(i)) > 0.05) {
      involved.push_back(names[static_cast<size_t>(i)]);
      along += (along.empty() ? "" : ", ") + std::string(rel(i) > 0 ? "+" : "-") +
               detail::format("{} {}", std::round(std::abs(rel(i)) * 100) / 100, names[static_cast<size_t>(i)]);
    }
  for (size_t k = 0; k < involved.size(); ++k)
    which += (k == 0 ? "" : k + 1 == involved.size() ? " and " : ", ") + involved[k];
  return detail::format("the data cannot separate {}: changing them together by the relative amounts ({}) leaves the "
                        "output unchanged (information ratio {}); fix one of them or reparameterise the model",
                        which, along, std::max(ratio, 0.0));
}

}  // namespace ctid::internal
