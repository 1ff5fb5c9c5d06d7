// ctid internal — see tf_common.hpp.
#include "estimate/tf_common.hpp"

#include <cmath>
#include <limits>

#include "ctid/simulate/lsim.hpp"

namespace ctid::tf_detail {

TransferFunction make_tf(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double delay) {
  Eigen::VectorXd den(a.size() + 1);
  den(0) = 1.0;
  den.tail(a.size()) = a;
  return TransferFunction(b, den, delay);
}

Eigen::VectorXd params_of(const TransferFunction& g, const TfOrders& o) {
  Eigen::VectorXd p(o.nf + o.nb);
  for (int i = 1; i <= o.nf; ++i) p(i - 1) = g.den().coefficient_of_power(o.nf - i);
  for (int j = 0; j < o.nb; ++j) p(o.nf + j) = g.num().coefficient_of_power(o.nb - 1 - j);
  return p;
}

TransferFunction tf_of(const Eigen::VectorXd& p, const TfOrders& o, double delay) {
  return make_tf(p.head(o.nf), p.tail(o.nb), delay);
}

double output_error_mse(const TransferFunction& g, const IdData& d) {
  const Eigen::VectorXd yhat = lsim(g, d, 0);
  if (!yhat.allFinite()) return std::numeric_limits<double>::infinity();
  return (d.y().col(0) - yhat).squaredNorm() / double(d.size());
}

TransferFunction stabilized(const TransferFunction& tf) {
  if (tf.is_stable()) return tf;
  Eigen::VectorXcd p = tf.poles();
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    if (p(i).real() > 0) p(i) = std::complex<double>(-p(i).real(), p(i).imag());
    else if (p(i).real() == 0) p(i) = std::complex<double>(-1e-6 * std::max(1.0, std::abs(p(i))), p(i).imag());
  }
  return TransferFunction(tf.num(), Polynomial::from_roots(p), tf.io_delay());
}

}  // namespace ctid::tf_detail
