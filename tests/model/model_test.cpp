#include <cmath>
#include <complex>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/model/transfer_function.hpp"

using namespace ctid;

TEST(TransferFunction, PolesZerosGainFrequencyResponse) {
  // (-6400 s + 1600) / (s^4 + 5 s^3 + 408 s^2 + 416 s + 1600): the Rao-Garnier system.
  const TransferFunction g(Eigen::VectorXd{{-6400.0, 1600.0}}, Eigen::VectorXd{{1.0, 5.0, 408.0, 416.0, 1600.0}}, 0.1);
  EXPECT_DOUBLE_EQ(g.dc_gain(), 1.0);
  EXPECT_TRUE(g.is_stable());
  EXPECT_NEAR(g.zeros()(0).real(), 0.25, 1e-14);
  // Poles: s^2 + s + 4 and s^2 + 4 s + 400 (Rao & Garnier 2002).
  for (auto p : g.poles()) {
    const double r = std::abs(p);
    EXPECT_TRUE(std::abs(r - 2.0) < 1e-10 || std::abs(r - 20.0) < 1e-10) << p;
  }
  const Eigen::VectorXcd h = g.frequency_response(Eigen::VectorXd{{2.0}});
  const std::complex<double> s(0, 2.0);
  const std::complex<double> ref = (-6400.0 * s + 1600.0) / (((s * s + s + 4.0) * (s * s + 4.0 * s + 400.0))) * std::exp(-0.2 * std::complex<double>(0, 1));
  EXPECT_NEAR(std::abs(h(0) - ref), 0.0, 1e-12 * std::abs(ref));
  EXPECT_THROW(TransferFunction(Eigen::VectorXd{{1.0, 1.0, 1.0}}, Eigen::VectorXd{{1.0, 1.0}}), InvalidArgument);
  EXPECT_THROW(TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 1.0}}, -1.0), InvalidArgument);
  EXPECT_FALSE(TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, -1.0}}).is_stable());
}

TEST(StateSpace, CanonicalFormsAndBackToTransferFunction) {
  const TransferFunction g(Eigen::VectorXd{{2.0, 3.0, 1.0, 5.0}}, Eigen::VectorXd{{1.0, 5.0, 408.0, 416.0}});  // biproper
  for (const StateSpace& ss : {StateSpace::controllable_canonical(g), StateSpace::observable_canonical(g)}) {
    const TransferFunction back = ss.to_transfer_function();
    EXPECT_LT((back.num().coefficients() - g.num().coefficients()).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT((back.den().coefficients() - g.den().coefficients()).cwiseAbs().maxCoeff(), 1e-9);
    const Eigen::VectorXd w = Eigen::VectorXd::LinSpaced(7, 0.1, 50);
    EXPECT_LT((ss.frequency_response(w) - g.frequency_response(w)).cwiseAbs().maxCoeff(), 1e-10);
  }
  // MIMO channel selection.
  const StateSpace m(Eigen::MatrixXd{{-1, 0}, {0, -2}}, Eigen::MatrixXd{{1, 0}, {0, 1}}, Eigen::MatrixXd{{1, 1}},
                     Eigen::MatrixXd{{0, 0}});
  EXPECT_NEAR(m.to_transfer_function(0, 1).dc_gain(), 0.5, 1e-14);
  EXPECT_EQ(m.to_transfer_function(0, 1).order(), 2);  // realisation order (no cancellation)
  EXPECT_THROW(m.to_transfer_function(1, 0), InvalidArgument);
  EXPECT_THROW(StateSpace(Eigen::MatrixXd::Zero(2, 3), Eigen::MatrixXd::Zero(2, 1), Eigen::MatrixXd::Zero(1, 2),
                          Eigen::MatrixXd::Zero(1, 1)),
               InvalidArgument);
}
