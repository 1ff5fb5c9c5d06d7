// ctid — polynomial NARX / NARMAX models (Billings & Li 1999, eqs 7-10):
//     y(k) = sum_m theta_m prod_{f in term m} x_f(k - lag_f) + e(k),
// x_f one of the output y, the input u, or the noise e (NARMAX moving-average terms); a term with no
// factors is the constant. Output and noise lags are >= 1, input lags >= 0.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

namespace ctid {

enum class NarxSignal { Output, Input, Noise };

struct NarxFactor {
  NarxSignal signal = NarxSignal::Output;
  int lag = 1;
  bool operator==(const NarxFactor&) const = default;
};

/// A monomial in lagged signals; no factors = the constant term.
struct NarxTerm {
  std::vector<NarxFactor> factors;
  int degree() const { return static_cast<int>(factors.size()); }
  int max_lag() const;
  bool has_noise() const;
  /// "1", "y(k-1)", "y(k-1)*u(k-2)", "e(k-3)".
  std::string name() const;
  /// Inverse of name(); throws InvalidArgument naming the text and the position of the problem.
  static NarxTerm parse(const std::string& text);
  bool operator==(const NarxTerm&) const = default;
};

/// Every monomial of degree 1..degree (and the constant when `constant`) in y(k-1..ylag) and
/// u(k-umin..ulag), in a fixed order (by degree, then lexicographically: y lags before u lags).
/// degree 2, ylag = ulag = 16, constant: 561 candidates. Throws InvalidArgument for degree < 1,
/// ylag < 0, ulag < umin, umin < 0 or no variable.
std::vector<NarxTerm> narx_candidates(int degree, int ylag, int ulag, bool constant = true, int umin = 1);

/// Noise (moving-average) candidates for NARMAX: e(k-1..elag), and with degree 2 also e(k-i)e(k-j),
/// e(k-i)y(k-j) and e(k-i)u(k-j) for i <= elag, j <= cross_lag.
std::vector<NarxTerm> narx_noise_candidates(int elag, int degree = 1, int cross_lag = 0);

class NarxModel {
 public:
  NarxModel() = default;
  /// Throws InvalidArgument for size mismatches, non-finite coefficients or invalid terms.
  NarxModel(std::vector<NarxTerm> terms, Eigen::VectorXd coefficients, double Ts);

  const std::vector<NarxTerm>& terms() const { return terms_; }
  const Eigen::VectorXd& coefficients() const { return theta_; }
  double ts() const { return Ts_; }
  int max_lag() const;
  int degree() const;
  bool has_noise_terms() const;
  /// The process part: noise terms removed (what is simulated and used for GFRFs).
  NarxModel process() const;

  /// Free-run simulation driven by u: y(k) for k >= max_lag from the model's own past outputs; the first
  /// max_lag outputs are taken from y0 (size >= max_lag; zeros when empty). Noise terms are zero.
  /// Stops at the first non-finite value: the rest is NaN and *escaped (if given) is set to true.
  /// (u is read in place: a column or segment of a record is not copied.)
  Eigen::VectorXd simulate(const Eigen::Ref<const Eigen::VectorXd>& u, const Eigen::VectorXd& y0 = {},
                           bool* escaped = nullptr) const;
  /// k-step-ahead prediction from measured (u, y): y^(k | k - steps); steps = 1 is the one-step predictor.
  /// Noise terms use the one-step residuals. The first max_lag values are the measured ones.
  Eigen::VectorXd predict(const Eigen::VectorXd& u, const Eigen::VectorXd& y, int steps = 1) const;
  /// "y(k) = 0.5 y(k-1) - 0.1 y(k-1)*u(k-2) + ...".
  std::string to_string(int precision = 6) const;

 private:
  std::vector<NarxTerm> terms_;
  Eigen::VectorXd theta_;
  double Ts_ = 1.0;
};

}  // namespace ctid
