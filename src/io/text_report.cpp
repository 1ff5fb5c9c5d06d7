// ctid — the text report of a fit (io/text_report.hpp): what `ctid fit` prints and Python's report() returns,
// written once here from the outcome of fit() and the record it was fitted to.
#include "ctid/io/text_report.hpp"

#include <algorithm>

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include "ctid/core/check.hpp"
#include "ctid/core/diagnostics.hpp"
#include "ctid/core/names.hpp"
#include "ctid/estimate/methods.hpp"
#include "ctid/io/load.hpp"
#include "ctid/validate/metrics.hpp"
#include "io/appendf.hpp"

namespace ctid {

namespace {
using io_detail::appendf;

// The automatic choices, the summary's note and the warnings: the lines after every result.
void notes_text(std::string& out, const Summary& s, const Diagnostics& dg) {
  for (const auto& c : dg.choices) appendf(out, "chosen: %s\n", c.c_str());
  if (!s.message.empty()) appendf(out, "note: %s\n", s.message.c_str());
  for (const auto& w : dg.warnings) appendf(out, "warning: %s\n", w.c_str());
}

template <class M>
void any_text(std::string& out, const Result<M>& r, const std::string& method, const IdData& d, const std::string& model) {
  appendf(out, "method: %s   samples: %d   %s\n", method.c_str(), d.size(),
              d.is_uniform() ? ("Ts = " + detail::format("{}", d.ts()) + " s").c_str() : "irregular sampling");
  appendf(out, "model:  %s\n", model.c_str());
  appendf(out, "parameters (value +- one standard deviation):\n");
  for (int i = 0; i < r.parameters.size(); ++i) {
    const bool fixed = r.parameters.fixed[i];
    const double sd = i < r.parameters.std.size() ? r.parameters.std(i) : NAN;
    if (fixed)
      appendf(out, "  %-4s = %14.6g   (fixed)\n", r.parameters.names[i].c_str(), r.parameters.values(i));
    else if (std::isfinite(sd))
      appendf(out, "  %-4s = %14.6g +- %-12.4g\n", r.parameters.names[i].c_str(), r.parameters.values(i), sd);
    else
      appendf(out, "  %-4s = %14.6g\n", r.parameters.names[i].c_str(), r.parameters.values(i));
  }
  if (r.diagnostics.has(diagnostic::tau))
    appendf(out, "filter time constant tau = %.6g s\n", r.diagnostics.get(diagnostic::tau));
  appendf(out, "fit: %s %%   NRMSE %.4g   MSE %.4g   AIC %.6g   BIC %.6g\n", fit_percent_text(r.fit.fit_percent).c_str(), r.fit.nrmse, r.fit.mse,
              r.fit.aic, r.fit.bic);
  if (r.diagnostics.condition_number > 0) appendf(out, "condition number %.3g   ", r.diagnostics.condition_number);
  appendf(out, "termination: %s   %.3g s\n", to_string(r.summary.termination), r.summary.seconds);
  notes_text(out, r.summary, r.diagnostics);
}
void result_text(std::string& out, const Result<TransferFunction>& r, const std::string& method, const IdData& d) {
  any_text(out, r, method, d, "G(s) = " + r.model.to_string(6));
}
void result_text(std::string& out, const Result<MisoModel>& r, const std::string& method, const IdData& d) {
  any_text(out, r, method, d, "y = " + r.model.to_string(6));
}
void result_text(std::string& out, const Result<GreyboxModel>& r, const std::string& method, const IdData& d) {
  std::string text = r.model.to_string();
  for (std::size_t i = text.find('\n'); i != std::string::npos && i + 1 < text.size(); i = text.find('\n', i + 1))
    text.insert(i + 1, "        ");
  any_text(out, r, method, d, text.substr(0, text.size() - 1));
}

void result_text(std::string& out, const Result<StateSpace>& r, const std::string& method, const IdData& d) {
  const StateSpace& m = r.model;
  appendf(out, "method: %s   samples: %d   %s   %d inputs, %d outputs, %d states\n", method.c_str(), d.size(),
              d.is_uniform() ? ("Ts = " + detail::format("{}", d.ts()) + " s").c_str() : "irregular sampling", m.nu(),
              m.ny(), m.nx());
  if (r.diagnostics.has(diagnostic::singular_values)) {
    const Eigen::VectorXd& sv = r.diagnostics.get(diagnostic::singular_values);
    appendf(out, "singular values (the order is where they drop):");
    for (Eigen::Index i = 0; i < std::min<Eigen::Index>(sv.size(), 12); ++i) appendf(out, " %.3g", sv(i) / sv(0));
    appendf(out, "\n");
  }
  if (m.nx() == 0) {
    appendf(out, "termination: %s\nnote: %s\n", to_string(r.summary.termination), r.summary.message.c_str());
    return;
  }
  auto matrix = [&out](const char* name, const Eigen::MatrixXd& M) {
    for (Eigen::Index i = 0; i < M.rows(); ++i) {
      appendf(out, "  %s%s", i == 0 ? name : " ", i == 0 ? " = [" : "     ");
      for (Eigen::Index j = 0; j < M.cols(); ++j) appendf(out, " %11.5g", M(i, j));
      appendf(out, "%s\n", i + 1 == M.rows() ? " ]" : "");
    }
  };
  appendf(out, "model:  dx/dt = A x + B u,  y = C x + D u\n");
  matrix("A", m.A());
  matrix("B", m.B());
  matrix("C", m.C());
  matrix("D", m.D());
  appendf(out, "modes: pole, natural frequency, damping ratio; shape = |C v| per output (phase, degrees)\n");
  const std::vector<Mode> modes = m.modes();
  const bool with_std = r.diagnostics.has(diagnostic::mode_wn_std) &&
                        r.diagnostics.get(diagnostic::mode_wn_std).size() == static_cast<Eigen::Index>(modes.size()) &&
                        r.diagnostics.get(diagnostic::mode_wn_std).allFinite();
  for (size_t k = 0; k < modes.size(); ++k) {
    const Mode& mode = modes[k];
    if (with_std)
      appendf(out, "  %12.6g %+12.6gj   wn = %.6g +- %.2g rad/s (%.6g Hz)   zeta = %.4g +- %.2g   shape", mode.pole.real(),
                  mode.pole.imag(), mode.wn, r.diagnostics.get(diagnostic::mode_wn_std)(static_cast<Eigen::Index>(k)),
                  mode.wn / (2 * std::numbers::pi), mode.zeta,
                  r.diagnostics.get(diagnostic::mode_zeta_std)(static_cast<Eigen::Index>(k)));
    else
      appendf(out, "  %12.6g %+12.6gj   wn = %.6g rad/s (%.6g Hz)   zeta = %.4g   shape", mode.pole.real(), mode.pole.imag(),
                  mode.wn, mode.wn / (2 * std::numbers::pi), mode.zeta);
    for (Eigen::Index j = 0; j < mode.shape.size(); ++j) {
      // Whole degrees in (-180, 180], without a "-0".
      double deg = std::round(std::arg(mode.shape(j)) * 180 / std::numbers::pi);
      if (deg == 0.0 || deg == -180.0) deg = std::abs(deg);
      appendf(out, " %.3f (%.0f)", std::abs(mode.shape(j)), deg);
    }
    appendf(out, "\n");
  }
  if (r.diagnostics.has(diagnostic::tau)) appendf(out, "filter time constant tau = %.6g s\n", r.diagnostics.get(diagnostic::tau));
  if (r.diagnostics.has(diagnostic::start_fit_percent))
    appendf(out, "subspace start: fit %s %%; ", fit_percent_text(r.diagnostics.get(diagnostic::start_fit_percent)).c_str());
  if (r.diagnostics.has(diagnostic::cost)) appendf(out, "output-error refinement: %d iterations\n", r.summary.iterations);
  if (r.diagnostics.has(diagnostic::nx_grid)) {
    const Eigen::VectorXd& g = r.diagnostics.get(diagnostic::nx_grid);
    const Eigen::VectorXd& b = r.diagnostics.get(diagnostic::nx_grid_bic);
    appendf(out, "order search (BIC):");
    for (Eigen::Index i = 0; i < g.size(); ++i) appendf(out, "  nx = %.0f: %.6g", g(i), b(i));
    appendf(out, "\n");
  }
  appendf(out, "fit: %s %% (every output scaled alike)", fit_percent_text(r.fit.fit_percent).c_str());
  if (r.diagnostics.has(diagnostic::output_fit_percent)) {
    const Eigen::VectorXd& f = r.diagnostics.get(diagnostic::output_fit_percent);
    for (Eigen::Index j = 0; j < f.size(); ++j)
      appendf(out, "   %s %s %%",
                  j < static_cast<Eigen::Index>(d.output_names().size()) ? d.output_names()[static_cast<size_t>(j)].c_str()
                                                                          : "y",
                  fit_percent_text(f(j)).c_str());
  }
  appendf(out, "\ntermination: %s   %.3g s\n", to_string(r.summary.termination), r.summary.seconds);
  notes_text(out, r.summary, r.diagnostics);
}

void result_text(std::string& out, const Result<FsfModel>& r, const std::string& method, const IdData& d) {
  const FsfModel& f = r.model;
  appendf(out, "method: %s   samples: %d   Ts = %g s   T = %g s (N = %d)   n = %d filters   window a = %g\n", method.c_str(),
              d.size(), f.delta(), f.T(), f.N(), f.n(), f.shift());
  appendf(out, "steady-state gain theta0 = %.6g +- %.3g   residual RMS %.4g   condition number %.3g\n", f.theta()(0),
              r.parameters.std(0), r.diagnostics.has(diagnostic::residual_rms) ? r.diagnostics.get(diagnostic::residual_rms) : NAN,
              r.diagnostics.condition_number);
  appendf(out, "compressed step response%s:\n", f.shift() > 0 ? " (of the shifted system G(s + a))" : "");
  for (int i = 0; i <= 10; ++i) {
    const double t = f.T() * i / 10.0;
    const Eigen::VectorXd tv{{t}};
    appendf(out, "  t = %8.4g s   y = %10.5g +- %.3g\n", t, f.step_response(tv)(0), f.step_response_std(tv)(0));
  }
  appendf(out, "termination: %s   %.3g s\n", to_string(r.summary.termination), r.summary.seconds);
  notes_text(out, r.summary, r.diagnostics);
}


// The value of one of the settings a fit used ("" when it has none of that name).
std::string used(const FitOutcome& fo, const std::string& name) {
  for (const auto& [k, v] : fo.settings)
    if (k == name) return v;
  return "";
}

// A transfer-function structure chosen by the fit itself (a method that takes no orders: srivc_auto): said on the
// first line, before the result.
void choice_text(std::string& out, const FitOutcome& fo, const IdData& d) {
  const Result<AnyModel>& r = fo.result;
  if (method_info(fo.method).capabilities.orders) return;
  if (const auto* m = std::get_if<TransferFunction>(&r.model); m && r.diagnostics.has(diagnostic::structure_nb)) {
    char delay[64] = "";
    if (m->io_delay() > 0) std::snprintf(delay, sizeof delay, " and an input delay of %.3g s", m->io_delay());
    appendf(out, "srivc-auto chose SRIVC with nb = %d, nf = %d%s: the least BIC of %d structures (nf = 1..%s, nb = 1..nf%s)\n",
                m->num().degree() + 1, m->den().degree(), delay,
                static_cast<int>(r.diagnostics.get(diagnostic::structure_nb).size()), used(fo, "nf_max").c_str(),
                used(fo, "try_delay") == "true" || used(fo, "try_delay") == "1" ? ", each with and without a delay" : "");
  } else if (const auto* mm = std::get_if<MisoModel>(&r.model)) {
    appendf(out, "srivc-auto chose, per input:");
    for (int i = 0; i < d.nu(); ++i) {
      const TransferFunction& g = mm->channels[static_cast<size_t>(i)];
      char delay[48] = "";
      if (g.io_delay() > 0) std::snprintf(delay, sizeof delay, ", delay %.3g s", g.io_delay());
      appendf(out, "%s %s nb = %d, nf = %d%s", i ? ";" : "", channel_name(d.input_names(), i).c_str(), g.num().degree() + 1,
                  g.den().degree(), delay);
    }
    appendf(out, " (each input alone, then each channel on the output less the others; the least BIC)\n");
  }
}


// The selected terms of a NARX fit with their ERR, preceded by the candidate count.
void narx_text(std::string& out, const Result<AnyModel>& r, const FitOutcome& fo) {
  auto used = [&](const char* name) {
    for (const auto& [k, v] : fo.settings)
      if (k == name) return v;
    return std::string("?");
  };
  appendf(out, "candidates: %.0f (degree %s, ylag %s, ulag %s)\n", r.diagnostics.get(diagnostic::candidates),
              used("degree").c_str(), used("ylag").c_str(), used("ulag").c_str());
  appendf(out, "selected terms (in order of selection) with their error reduction ratio:\n");
  const Eigen::VectorXd& err = r.diagnostics.get(diagnostic::err);
  for (int i = 0; i < r.parameters.size(); ++i)
    appendf(out, "  %-22s %14.6g +- %-11.3g ERR %8.4f %%\n", r.parameters.names[i].c_str(), r.parameters.values(i),
                r.parameters.std(i), i < err.size() ? err(i) : NAN);
  appendf(out, "1 - sum(ERR) = %.3g   free-run fit %s %%\n", r.diagnostics.get(diagnostic::esr),
              fit_percent_text(r.fit.fit_percent).c_str());
}

const Result<AnyModel>* stage(const FitOutcome& fo, const std::string& name) {
  for (const auto& [n, r] : fo.stages)
    if (n == name) return &r;
  return nullptr;
}

void kia_text(std::string& out, const FitOutcome& fo) {
  if (const Result<AnyModel>* n = stage(fo, "narx")) narx_text(out, *n, fo);
  const Result<AnyModel>& k = *stage(fo, "reconstructed");
  for (const auto& c : k.diagnostics.choices) appendf(out, "chosen: %s\n", c.c_str());
  appendf(out, "NDE: %s\n", describe(k.model, 5).c_str());
  const Eigen::VectorXd& err = k.diagnostics.get(diagnostic::err);
  for (int i = 0; i < k.parameters.size(); ++i)
    appendf(out, "  %-10s %14.6g   ERR %8.4f %%\n", k.parameters.names[i].c_str(), k.parameters.values(i), err(i));
  bool zoh = true;
  for (const auto& [name, value] : fo.settings)
    if (name == "zoh") zoh = value == "1";
  appendf(out, "simulated output fit: %s %%   (hold factor %s)\n", fit_percent_text(k.fit.fit_percent).c_str(),
              zoh ? "on" : "off");
  const double narx_fit = k.diagnostics.has(diagnostic::narx_fit_percent) ? k.diagnostics.get(diagnostic::narx_fit_percent)
                                                                           : -std::numeric_limits<double>::infinity();
  appendf(out, "NARX model's free-run fit on the same record%s: %s %%\n",
              k.diagnostics.has(diagnostic::experiments) ? "s" : "", fit_percent_text(narx_fit).c_str());
  const Result<AnyModel>* refined = stage(fo, "refined");
  if (refined && refined->usable()) {
    const Result<AnyModel>& oe = *refined;
    appendf(out, "refined by output error (%d iterations): %s\n", oe.summary.iterations, describe(oe.model, 5).c_str());
    for (int i = 0; i < oe.parameters.size(); ++i)
      appendf(out, "  %-10s %14.6g +- %.3g%s\n", oe.parameters.names[i].c_str(), oe.parameters.values(i),
                  oe.parameters.std(i), oe.parameters.fixed[static_cast<size_t>(i)] ? "  (reference)" : "");
    for (const auto& w : oe.diagnostics.warnings) appendf(out, "  note: %s\n", w.c_str());
    appendf(out, "simulated output fit: %s %%\n", fit_percent_text(oe.fit.fit_percent).c_str());
  } else if (refined) {
    appendf(out, "ctid: warning: the output-error refinement failed (%s); keeping the KIA model\n",
                 refined->why_not_usable().c_str());
  }
}


}  // namespace

std::string parameters_text(const ParameterSet& p) {
  std::string out;
  appendf(out, "%-16s%14s%12s", "parameter", "value", "std");
  for (int i = 0; i < p.size(); ++i) {
    char sd[32] = "-";
    if (i < static_cast<int>(p.fixed.size()) && p.fixed[static_cast<std::size_t>(i)]) std::snprintf(sd, sizeof sd, "fixed");
    else if (i < p.std.size()) std::snprintf(sd, sizeof sd, "%.4g", p.std(i));
    appendf(out, "\n%-16s%14.6g%12s", p.names[static_cast<std::size_t>(i)].c_str(), p.values(i), sd);
  }
  return out;
}

std::string fit_report_text(const FitReport& f) {
  std::string out;
  appendf(out, "FitReport(fit %s %%, nrmse %.4g, mse %.4g, aic %.6g, bic %.6g, %d samples)",
          fit_percent_text(f.fit_percent).c_str(), f.nrmse, f.mse, f.aic, f.bic, f.n_samples);
  return out;
}

std::string summary_text(const Summary& s) {
  std::string out;
  appendf(out, "Summary(%s, %d iteration(s), %.3g s%s)", to_string(s.termination), s.iterations, s.seconds,
          s.message.empty() ? "" : (": " + s.message).c_str());
  return out;
}

std::string diagnostics_text(const Diagnostics& d) {
  std::string out;
  appendf(out, "Diagnostics(condition number %.3g)", d.condition_number);
  for (const auto& [k, v] : d.scalars()) appendf(out, "\n  %s = %.6g", k.c_str(), v);
  for (const auto& [k, v] : d.vectors()) {
    appendf(out, "\n  %s = [", k.c_str());
    for (Eigen::Index i = 0; i < std::min<Eigen::Index>(v.size(), 8); ++i) appendf(out, "%s%.4g", i ? ", " : "", v(i));
    appendf(out, "%s]", v.size() > 8 ? ", ..." : "");
  }
  for (const auto& c : d.choices) appendf(out, "\n  chosen: %s", c.c_str());
  for (const auto& w : d.warnings) appendf(out, "\n  warning: %s", w.c_str());
  return out;
}

std::string brief_text(const std::string& model, const ParameterSet& p, const FitReport& f, const Summary& s,
                       const Diagnostics& d, bool usable) {
  std::string out = model + "\n";
  appendf(out, "termination: %s%s, %d iteration(s), %.3g s, usable: %s\n", to_string(s.termination),
          s.message.empty() ? "" : (" (" + s.message + ")").c_str(), s.iterations, s.seconds, usable ? "True" : "False");
  if (p.size() > 0) out += parameters_text(p) + "\n";
  appendf(out, "fit: %s %%  (mse %.4g, aic %.4g, %d samples)", fit_percent_text(f.fit_percent).c_str(), f.mse, f.aic,
          f.n_samples);
  for (const auto& w : d.warnings) appendf(out, "\nwarning: %s", w.c_str());
  return out;
}

std::string fit_text(const FitOutcome& fo, const IdData& data) {
  std::string out;
  choice_text(out, fo, data);
  std::visit(
      [&](const auto& m) {
        using M = std::decay_t<decltype(m)>;
        const Result<AnyModel>& r = fo.result;
        if constexpr (std::is_same_v<M, NarxModel>) narx_text(out, r, fo);
        else if constexpr (std::is_same_v<M, NdeModel>) kia_text(out, fo);
        else result_text(out, Result<M>{m, r.parameters, r.fit, r.summary, r.diagnostics}, fo.method, data);
      },
      fo.result.model);
  return out;
}

std::string fit_text(const FitOutcome& fo, const FrequencyData& data) {
  std::string out;
  const Result<AnyModel>& r = fo.result;
  appendf(out, "method: %s (frequency data)   frequencies: %d   from %.4g to %.4g rad/s\n", fo.method.c_str(), data.size(),
          data.w()(0), data.w()(data.size() - 1));
  if (const auto* g = std::get_if<TransferFunction>(&r.model)) appendf(out, "model:  G(s) = %s\n", g->to_string(6).c_str());
  else appendf(out, "model:  %s\n", describe(r.model).c_str());
  for (int i = 0; i < r.parameters.size(); ++i)
    appendf(out, "  %-5s = %14.6g +- %-12.4g\n", r.parameters.names[static_cast<size_t>(i)].c_str(),
            r.parameters.values(i), r.parameters.std(i));
  appendf(out, "fit (complex response): %s %%   termination: %s\n", fit_percent_text(r.fit.fit_percent).c_str(),
          to_string(r.summary.termination));
  return out;
}

}  // namespace ctid
