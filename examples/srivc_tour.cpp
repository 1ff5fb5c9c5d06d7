// The examples of docs/methods/srivc.md, run by ctest: SRIVC, a delay search, tfest with a
// fixed parameter and a bound, and order selection on the Rao-Garnier benchmark system.
#include <cmath>
#include <cstdio>

#include <ctid/ctid.hpp>

int main() {
  using namespace ctid;
  const TransferFunction truth(Polynomial{-6400.0, 1600.0}, Polynomial{1.0, 5.0, 408.0, 416.0, 1600.0});
  const Eigen::VectorXd u = prbs(7161, {.register_length = 10, .clock_period = 7});
  const IdData data(u, add_noise_snr(lsim(truth, u, time_grid(0.01, 7161)), 10.0, /*seed=*/1), 0.01);

  const Result<TransferFunction> r = srivc(data, {.nb = 2, .nf = 4});
  std::printf("srivc:  %s   (%d iterations, %.1f ms)\n", r.model.to_string(5).c_str(), r.summary.iterations, 1e3 * r.summary.seconds);
  const Eigen::MatrixXd bound = crlb(truth, 2, data, r.diagnostics.get(diagnostic::noise_variance));
  for (int i = 0; i < r.parameters.size(); ++i)
    std::printf("  %s = %10.4f +- %8.4f   (CRLB std %8.4f)\n", r.parameters.names[i].c_str(), r.parameters.values(i),
                r.parameters.std(i), std::sqrt(bound(i, i)));

  OeOptions oo{.fixed = {{"a4", 1600.0}}, .bounds = {{"a1", {0.0, 10.0}}}};
  const Result<TransferFunction> t = tfest(data, {.nb = 2, .nf = 4}, oo);
  std::printf("tfest with a4 fixed: %s\n", t.model.to_string(5).c_str());

  // A delayed first-order-plus-second-order plant: the delay is searched, then refined.
  const TransferFunction delayed(Polynomial{12.0}, Polynomial{1.0, 4.0, 4.0}, 8.037);
  const Eigen::VectorXd ud = prbs(255 * 20, {.register_length = 8, .clock_period = 20});
  const IdData dd(ud, add_noise_snr(lsim(delayed, ud, time_grid(0.1, 255 * 20)), 15.0, 2), 0.1);
  SrivcOptions so{.estimate_delay = true, .delay_max = 15};
  const Result<TransferFunction> d = srivc(dd, {.nb = 1, .nf = 2}, so);
  std::printf("srivc with delay search: %s\n", d.model.to_string(5).c_str());

  const std::vector<OrderCandidate> ranked = select_order(data, {1, 2}, {3, 5}, {0, 0});
  std::printf("best structure by YIC: [%d %d %d]\n", ranked[0].orders.nb, ranked[0].orders.nf, ranked[0].orders.nk);

  const bool ok = r.usable() && t.usable() && std::abs(d.model.io_delay() - 8.037) < 0.05 && ranked[0].orders.nb == 2 &&
                  ranked[0].orders.nf == 4;
  return ok ? 0 : 1;
}
