// Identifies 2/(s+2) from noise-free data through the installed library.
#include <cmath>
#include <cstdio>

#include <ctid/ctid.hpp>

// The project sets no C++ standard: ctid::ctid (INTERFACE_COMPILE_FEATURES cxx_std_20) and ctid.pc (-std=c++20) must.
static_assert(__cplusplus >= 202002L, "the ctid target did not carry its C++20 requirement");

int main() {
  const ctid::TransferFunction g(Eigen::VectorXd{{2.0}}, Eigen::VectorXd{{1.0, 2.0}});
  ctid::PrbsOptions po;
  po.clock_period = 5;
  const int N = 4000;
  const Eigen::VectorXd u = ctid::prbs(N, po);
  const ctid::IdData data(u, ctid::lsim(g, u, ctid::time_grid(0.005, N)), 0.005);
  ctid::LssvfOptions o;
  o.tau = 0.2;
  const auto r = ctid::lssvf(data, {1, 1, 0}, o);
  std::printf("%s\n", r.model.to_string().c_str());
  return std::abs(r.parameters.value("a1") - 2.0) < 1e-3 ? 0 : 1;
}
