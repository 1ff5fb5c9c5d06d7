#include "ctid/validate/crlb.hpp"

#include <cmath>

#include "ctid/core/check.hpp"
#include "ctid/signal/prefilter.hpp"

namespace ctid {

Eigen::MatrixXd crlb(const TransferFunction& truth, int nb, const IdData& d, double sigma2, bool with_delay) {
  CTID_REQUIRE(std::isfinite(sigma2) && sigma2 > 0, "crlb: the noise variance must be > 0 (got {})", sigma2);
  const Eigen::MatrixXd S = output_sensitivities(truth, nb, d, with_delay);
  const Eigen::MatrixXd F = S.transpose() * S;
  const Eigen::VectorXd dg = F.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd Fs = dg.asDiagonal() * F * dg.asDiagonal();
  Eigen::LDLT<Eigen::MatrixXd> ldlt(Fs);
  CTID_REQUIRE(ldlt.info() == Eigen::Success && ldlt.isPositive() && ldlt.vectorD().minCoeff() > 1e-14 * ldlt.vectorD().maxCoeff(),
               "crlb: the information matrix is singular; the input does not identify all {} parameters", S.cols());
  return sigma2 * dg.asDiagonal() * ldlt.solve(Eigen::MatrixXd::Identity(S.cols(), S.cols())) * dg.asDiagonal();
}

}  // namespace ctid
