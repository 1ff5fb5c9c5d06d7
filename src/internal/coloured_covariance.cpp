#include "internal/coloured_covariance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ctid::internal {

ResidualAutocovariance::ResidualAutocovariance(int max_lag)
    : max_lag_(std::max(0, max_lag)), sums_(Eigen::VectorXd::Zero(max_lag_ + 1)), ring_(max_lag_ + 1) {}

void ResidualAutocovariance::start_sequence() { filled_ = head_ = 0; }

void ResidualAutocovariance::add(double r) {
  // ring_ holds the last max_lag_ + 1 residuals; head_ is where r goes.
  ring_(head_) = r;
  const int L = max_lag_ + 1;
  const int available = std::min(filled_ + 1, L);
  for (int l = 0; l < available; ++l) sums_(l) += r * ring_((head_ - l + L) % L);
  head_ = (head_ + 1) % L;
  filled_ = std::min(filled_ + 1, L);
  ++n_;
}

ResidualAr ResidualAutocovariance::fit(int parameters) const {
  ResidualAr best;
  if (n_ == 0) return best;
  const double N = static_cast<double>(n_);
  const double dof = N / std::max(1.0, N - parameters);
  const Eigen::VectorXd c = sums_ / N;
  if (!(c(0) > 0) || !std::isfinite(c(0))) {
    best.variance = c(0) * dof;
    return best;
  }
  // Levinson-Durbin: a of order k from order k - 1; E the prediction-error variance.
  Eigen::VectorXd a = Eigen::VectorXd::Zero(max_lag_), next(max_lag_);
  double E = c(0), best_aic = N * std::log(E);
  best.variance = E * dof;
  for (int k = 1; k <= max_lag_; ++k) {
    double acc = c(k);
    for (int i = 1; i < k; ++i) acc += a(i - 1) * c(k - i);
    const double kappa = -acc / E;
    if (!(std::abs(kappa) < 1.0)) break;
    next.head(k - 1) = a.head(k - 1);
    for (int i = 1; i < k; ++i) next(i - 1) += kappa * a(k - i - 1);
    next(k - 1) = kappa;
    a.head(k) = next.head(k);
    E *= 1.0 - kappa * kappa;
    if (!(E > 0)) break;
    const double aic = N * std::log(E) + 2.0 * k;
    if (aic < best_aic) {
      best_aic = aic;
      best.a = a.head(k);
      best.variance = E * dof;
    }
  }
  return best;
}

ColouredGram::ColouredGram(const ResidualAr& ar, int columns)
    : ar_(ar),
      past_(Eigen::MatrixXd::Zero(std::max(1, ar.order()), columns)),
      sum_(Eigen::MatrixXd::Zero(columns, columns)),
      now_(columns) {}

void ColouredGram::start_sequence() { filled_ = head_ = 0; }

void ColouredGram::add(const double* row) {
  add_row(Eigen::Map<const Eigen::RowVectorXd>(row, sum_.cols()));
}

void ColouredGram::add_row(const Row& row) {
  // j~_t = j_t - sum_i a_i j~_{t-i}; past_ row (head_ - i) mod n holds j~_{t-i}.
  const int n = ar_.order();
  now_ = row;
  for (int i = 1; i <= std::min(n, filled_); ++i) now_ -= ar_.a(i - 1) * past_.row((head_ - i + n) % n);
  sum_.selfadjointView<Eigen::Lower>().rankUpdate(now_.transpose());
  if (n > 0) {
    past_.row(head_) = now_;
    head_ = (head_ + 1) % n;
    filled_ = std::min(filled_ + 1, n);
  }
}

Eigen::MatrixXd ColouredGram::gram() const {
  return ar_.variance * Eigen::MatrixXd(sum_.selfadjointView<Eigen::Lower>());
}

Eigen::MatrixXd sandwich(const Eigen::MatrixXd& H, const Eigen::MatrixXd& Q) {
  const Eigen::Index p = H.rows();
  if (p == 0 || H.cols() != p || Q.rows() != p || Q.cols() != p || !H.allFinite() || !Q.allFinite()) return {};
  const Eigen::VectorXd d = H.diagonal().cwiseMax(std::numeric_limits<double>::min()).cwiseSqrt().cwiseInverse();
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(d.asDiagonal() * H * d.asDiagonal());
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) return {};
  const Eigen::MatrixXd Hi = ldlt.solve(Eigen::MatrixXd::Identity(p, p));
  const Eigen::MatrixXd S = Hi * (d.asDiagonal() * Q * d.asDiagonal()) * Hi;
  Eigen::MatrixXd C = d.asDiagonal() * (0.5 * (S + S.transpose())) * d.asDiagonal();
  return C.allFinite() ? C : Eigen::MatrixXd();
}

int ColouredCovariance::largest_order() const {
  int k = 0;
  for (const ResidualAr& a : noise) k = std::max(k, a.order());
  return k;
}

int residual_ar_max_lag(long long shortest_group) {
  return static_cast<int>(std::clamp<long long>(shortest_group / 10, 0, 40));
}

ColouredCovariance coloured_covariance(const Eigen::MatrixXd& J, const Eigen::VectorXd& r,
                                       const std::vector<ResidualSequence>& sequences, int parameters) {
  ColouredCovariance out;
  int groups = 0;
  for (const ResidualSequence& s : sequences) groups = std::max(groups, s.group + 1);
  if (groups == 0 || J.rows() != r.size()) return out;
  std::vector<long long> per_group(static_cast<size_t>(groups), 0);
  for (const ResidualSequence& s : sequences) per_group[static_cast<size_t>(s.group)] += s.length;
  const int max_lag = residual_ar_max_lag(*std::min_element(per_group.begin(), per_group.end()));
  // The degrees of freedom are shared among the groups in proportion to their residuals.
  long long total = 0;
  for (long long n : per_group) total += n;
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(J.cols(), J.cols());
  for (int g = 0; g < groups; ++g) {
    ResidualAutocovariance acov(max_lag);
    for (const ResidualSequence& s : sequences) {
      if (s.group != g) continue;
      acov.start_sequence();
      for (Eigen::Index k = 0; k < s.length; ++k) acov.add(r(s.start + k));
    }
    const int share = static_cast<int>(std::lround(double(parameters) * double(per_group[static_cast<size_t>(g)]) /
                                                   double(std::max<long long>(1, total))));
    out.noise.push_back(acov.fit(share));
    ColouredGram gram(out.noise.back(), static_cast<int>(J.cols()));
    for (const ResidualSequence& s : sequences) {
      if (s.group != g) continue;
      gram.start_sequence();
      for (Eigen::Index k = 0; k < s.length; ++k) gram.add(J.row(s.start + k));
    }
    Q += gram.gram();
  }
  if (Q.allFinite()) out.score = std::move(Q);
  return out;
}

}  // namespace ctid::internal
