// srivc_auto — SRIVC (Young & Jakeman 1980) over a small range of structures, with and without its delay search,
// the least BIC (Schwarz 1978) kept. See include/ctid/estimate/transfer_function/srivc_auto.hpp.
#include "ctid/estimate/transfer_function/srivc_auto.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "ctid/core/check.hpp"
#include "ctid/core/progress.hpp"
#include "ctid/simulate/lsim.hpp"
#include "estimate/transfer_function/tf_common.hpp"

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

namespace {
// A MISO fit's BIC (+inf when it has none) and whether it is usable: usable() and no channel pole beyond ten times
// the Nyquist frequency.
struct Scored {
  Result<MisoModel> r;
  bool usable = false;
  double bic = INFINITY;
};

Scored score(Result<MisoModel> r, const IdData& d) {
  Scored s;
  s.usable = r.usable();
  for (const TransferFunction& g : r.model.channels) s.usable = s.usable && !tf_detail::pole_beyond_bandwidth(g, d);
  s.bic = r.fit.n_samples > 0 && std::isfinite(r.fit.bic) ? r.fit.bic : INFINITY;
  s.r = std::move(r);
  return s;
}

bool better(const Scored& a, const Scored& b) { return (a.usable && !b.usable) || (a.usable == b.usable && a.bic < b.bic); }

std::string structure_text(const TfOrders& o, double delay) {
  char b[96];
  std::snprintf(b, sizeof b, "nb = %d, nf = %d, delay %.4g s", o.nb, o.nf, delay);
  return b;
}
}  // namespace

Result<MisoModel> srivc_auto_miso(const IdData& data, const SrivcAutoOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  options.validate();
  CTID_REQUIRE(data.ny() == 1, "srivc_auto_miso: needs one output (the data have {}); several outputs: ssest", data.ny());
  const int nu = data.nu();
  const auto name = [&](int i) {
    const auto& n = data.input_names();
    return i < static_cast<int>(n.size()) && !n[static_cast<size_t>(i)].empty() ? n[static_cast<size_t>(i)]
                                                                                 : "u" + std::to_string(i + 1);
  };
  // Channel i's record: its input, and the output less the other channels' simulated contributions (`parts`, one
  // column per channel, simulated once per round; none in the first round: the whole output, the other inputs
  // acting as noise).
  auto channel_record = [&](int i, const Eigen::MatrixXd* parts) {
    IdData di = data.select({i}, {0});
    if (!parts) return di;
    const Eigen::VectorXd y = data.y().col(0) - parts->rowwise().sum() + parts->col(i);
    IdData out = data.is_uniform() ? IdData(di.u(), y, data.ts(), data.t0()) : IdData(di.u(), y, data.times());
    out.set_intersample(data.intersample(i));
    return out;
  };
  SrivcMisoOptions mo;
  mo.max_iterations = std::max(options.srivc.max_iterations, 1);
  mo.tolerance = options.srivc.tolerance;
  std::vector<std::string> choices;
  std::vector<TfOrders> orders(static_cast<size_t>(nu));
  std::vector<double> delays(static_cast<size_t>(nu), 0.0);
  Scored best;
  bool have = false;
  int siso = 0, sweeps = 0;
  // Sweep 0: each input alone; then each channel on the output less the others (backfitting), until the structures
  // repeat (at most 3 sweeps after the first).
  for (; sweeps <= 3; ++sweeps) {
    std::vector<TfOrders> o(static_cast<size_t>(nu));
    std::vector<double> d(static_cast<size_t>(nu), 0.0);
    Eigen::MatrixXd parts(data.size(), nu);
    if (have) {
      for (int j = 0; j < nu; ++j) parts.col(j) = lsim(best.r.model.channels[static_cast<size_t>(j)], data, j);
      if (!parts.allFinite()) {  // a channel of the model kept diverges: nothing sound to take from the output
        choices.push_back("backfitting stopped: a channel of the model kept diverges on the record");
        break;
      }
    }
    for (int i = 0; i < nu; ++i) {
      if (!report_progress("srivc_auto_miso", ++siso, NAN)) goto done;
      const Result<TransferFunction> ri = srivc_auto(channel_record(i, have ? &parts : nullptr), options);
      o[static_cast<size_t>(i)] = {ri.model.num().degree() + 1, ri.model.den().degree(), 0};
      d[static_cast<size_t>(i)] = ri.model.io_delay();
    }
    bool same = have;
    for (int i = 0; i < nu && same; ++i)
      same = o[static_cast<size_t>(i)].nb == orders[static_cast<size_t>(i)].nb &&
             o[static_cast<size_t>(i)].nf == orders[static_cast<size_t>(i)].nf &&
             std::abs(d[static_cast<size_t>(i)] - delays[static_cast<size_t>(i)]) <= 0.5 * (data.is_uniform() ? data.ts() : 0.0);
    if (same) break;
    SrivcMisoOptions m = mo;
    m.delays = d;
    Scored s = score(srivc_miso(data, o, m), data);
    std::string text;
    for (int i = 0; i < nu; ++i)
      text += (i ? "; " : "") + name(i) + ": " + structure_text(o[static_cast<size_t>(i)], d[static_cast<size_t>(i)]);
    const bool take = !have || better(s, best);
    choices.push_back((sweeps == 0 ? "each input alone: " : "each channel on the output less the others: ") + text +
                      (s.usable ? "" : " (not usable)") + (take ? "" : " — BIC not lower, the previous kept"));
    if (!take) break;
    best = std::move(s);
    orders = o;
    delays = d;
    have = true;
    if (nu == 1) break;  // nothing to take away from the output: the next round would repeat this one
  }
done:
  if (!have) {  // interrupted during the first round: no joint fit to return
    Result<MisoModel> r;
    r.summary.termination = Termination::Interrupted;
    r.summary.message = "srivc_auto_miso: interrupted before the first joint fit";
    r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
  }
  Result<MisoModel> r = std::move(best.r);
  for (auto& c : choices) r.diagnostics.choices.push_back(std::move(c));
  if (!best.usable && r.summary.succeeded()) {
    r.summary.termination = Termination::Unidentifiable;
    r.summary.message = "srivc_auto_miso: no structure gave a usable fit (a channel pole beyond ten times the Nyquist "
                        "frequency, or failed); choose the orders with srivc_miso";
  }
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace ctid
