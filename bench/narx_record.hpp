// The degree-2 NARX record of the FROLS benchmarks (SysIdentPy's benchmark system with white input and noise).
#pragma once

#include "ctid/ctid.hpp"

namespace bench {
inline ctid::IdData narx_record(int N) {
  const Eigen::VectorXd u = ctid::white_noise(N, 1.0, 1), e = ctid::white_noise(N, 0.05, 2);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(N);
  for (int k = 2; k < N; ++k)
    y(k) = 0.5 * y(k - 1) - 0.2 * y(k - 2) + 0.3 * u(k - 1) + 0.2 * u(k - 2) + 0.1 * y(k - 1) * u(k - 1) -
           0.05 * y(k - 2) * y(k - 2) + e(k);
  return ctid::IdData(u, y, 1.0);
}
}  // namespace bench
