// srivc_auto — SRIVC (Young & Jakeman 1980) over a small range of structures, with and without its delay search,
// the least BIC (Schwarz 1978) kept. See include/ctid/estimate/srivc_auto.hpp.
#include "ctid/estimate/srivc_auto.hpp"

#include <chrono>
#include <cmath>
#include <vector>

#include "ctid/core/check.hpp"
#include "ctid/core/progress.hpp"
#include "estimate/tf_common.hpp"

namespace ctid {

template <>
const OptionTable<SrivcAutoOptions>& option_table<SrivcAutoOptions>() {
  using O = SrivcAutoOptions;
  static const OptionTable<O> t =
      OptionTable<O>("srivc_auto")
          .integer("nf_max", &O::nf_max, "", between(1, 8), "largest model order tried (nf = 1..nf_max, nb = 1..nf)")
          .flag("try_delay", &O::try_delay,
                "also fit each structure with SRIVC's delay search; the delay is kept when it lowers the BIC")
          .include(&O::srivc, option_table<SrivcOptions>(),
                   {"max_iterations", "tolerance", "delay_min", "delay_max", "delay_grid", "transient_time"});
  return t;
}

void SrivcAutoOptions::validate() const {
  option_table<SrivcAutoOptions>().check(*this);
  srivc.validate();
}

Result<TransferFunction> srivc_auto(const IdData& data, const SrivcAutoOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  options.validate();
  CTID_REQUIRE(data.nu() == 1 && data.ny() == 1,
               "srivc_auto: needs one input and one output (the data have {} and {}); several inputs: srivc_miso with "
               "orders, several outputs: ssest", data.nu(), data.ny());
  Eigen::VectorXd nbs, nfs, delays, bics;
  auto add = [](Eigen::VectorXd& v, double x) {
    v.conservativeResize(v.size() + 1);
    v(v.size() - 1) = x;
  };
  Result<TransferFunction> best;
  bool have = false, best_usable = false;
  double best_bic = INFINITY;
  int tried = 0;
  for (int nf = 1; nf <= options.nf_max; ++nf)
    for (int nb = 1; nb <= nf; ++nb)
      for (int with_delay = 0; with_delay <= (options.try_delay ? 1 : 0); ++with_delay) {
        if (!report_progress("srivc_auto", ++tried, NAN)) goto done;
        SrivcOptions o = options.srivc;
        o.estimate_delay = with_delay == 1;
        Result<TransferFunction> r;
        try {
          r = srivc(data, TfOrders{nb, nf, 0}, o);
        } catch (const InvalidArgument&) {
          // An order the record is too short for ends the search at the orders before it (the first one rethrows).
          if (!have) throw;
          goto done;
        }
        const bool usable = r.usable() && !tf_detail::pole_beyond_bandwidth(r.model, data);
        const double bic = r.fit.n_samples > 0 && std::isfinite(r.fit.bic) ? r.fit.bic : INFINITY;
        add(nbs, nb);
        add(nfs, nf);
        add(delays, with_delay ? r.model.io_delay() : 0.0);
        add(bics, usable ? bic : NAN);
        if (!have || (usable && !best_usable) || (usable == best_usable && bic < best_bic)) {
          have = true;
          best_usable = usable;
          best_bic = bic;
          best = std::move(r);
        }
      }
done:
  best.diagnostics.set(diagnostic::structure_nb, nbs);
  best.diagnostics.set(diagnostic::structure_nf, nfs);
  best.diagnostics.set(diagnostic::structure_delay, delays);
  best.diagnostics.set(diagnostic::structure_bic, bics);
  if (best_usable == false && best.summary.succeeded() && best.model.poles().size() > 0) {
    best.summary.termination = Termination::Unidentifiable;
    best.summary.message = "srivc_auto: no structure gave a usable fit (each has a pole beyond ten times the Nyquist "
                           "frequency or failed); choose the orders with select_order";
  }
  best.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return best;
}

}  // namespace ctid
