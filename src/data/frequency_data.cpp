#include "ctid/data/frequency_data.hpp"

#include <cmath>

#include "ctid/core/check.hpp"

namespace ctid {

FrequencyData::FrequencyData(Eigen::VectorXd w, Eigen::VectorXcd G) : w_(std::move(w)), g_(std::move(G)) {
  CTID_REQUIRE(w_.size() >= 1, "FrequencyData: at least one frequency is needed");
  CTID_REQUIRE(w_.size() == g_.size(), "FrequencyData: {} frequencies but {} response values", w_.size(), g_.size());
  for (Eigen::Index k = 0; k < w_.size(); ++k) {
    CTID_REQUIRE(std::isfinite(w_(k)) && w_(k) > 0, "FrequencyData: frequency {} must be positive and finite (got {} rad/s)", k,
                 w_(k));
    CTID_REQUIRE(k == 0 || w_(k) > w_(k - 1),
                 "FrequencyData: frequencies must be strictly increasing (w[{}] = {} after w[{}] = {})", k, w_(k), k - 1,
                 w_(k - 1));
    CTID_REQUIRE(std::isfinite(g_(k).real()) && std::isfinite(g_(k).imag()),
                 "FrequencyData: response value {} is not finite", k);
  }
}

FrequencyData FrequencyData::from_spectra(const Eigen::VectorXd& w, const Eigen::VectorXcd& U, const Eigen::VectorXcd& Y) {
  CTID_REQUIRE(U.size() == w.size() && Y.size() == w.size(), "FrequencyData: {} frequencies, {} input and {} output values",
               w.size(), U.size(), Y.size());
  Eigen::VectorXcd G(w.size());
  for (Eigen::Index k = 0; k < w.size(); ++k) {
    CTID_REQUIRE(std::abs(U(k)) > 0, "FrequencyData: the input spectrum is zero at w[{}] = {} rad/s", k, w(k));
    G(k) = Y(k) / U(k);
  }
  return FrequencyData(w, G);
}

}  // namespace ctid
