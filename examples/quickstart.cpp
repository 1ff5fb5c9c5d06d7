// README quick start: identify (s + 3)/(s^2 + 1.2 s + 4) from simulated, noisy data.
#include <cstdio>

#include <ctid/ctid.hpp>

int main() {
  using namespace ctid;
  const TransferFunction truth(Polynomial{1.0, 3.0}, Polynomial{1.0, 1.2, 4.0});
  const Eigen::VectorXd u = prbs(6000, {.register_length = 10, .clock_period = 10});
  const Eigen::VectorXd y = add_noise_snr(lsim(truth, u, time_grid(0.01, 6000)), 20.0, /*seed=*/1);
  const IdData data(u, y, /*Ts=*/0.01);

  const Result<TransferFunction> r = srivc(data, {.nb = 2, .nf = 2});
  std::printf("G(s) = %s, fit %.1f %%\n", r.model.to_string(4).c_str(), r.fit.fit_percent);
  for (int i = 0; i < r.parameters.size(); ++i)
    std::printf("  %s = %.4f +- %.4f\n", r.parameters.names[i].c_str(), r.parameters.values(i), r.parameters.std(i));
  return r.usable() ? 0 : 1;
}
