// ctid — the text of the tools (io/tool_text.hpp): `ctid poles`, `ctid response`, `ctid compare` print it, Python's
// repr of PolesComparison and ModalResponse shows it.
#include "ctid/io/tool_text.hpp"

#include <algorithm>
#include <cmath>

#include "ctid/core/check.hpp"
#include "ctid/core/names.hpp"
#include "ctid/io/load.hpp"
#include "ctid/simulate/simulate.hpp"
#include "ctid/validate/metrics.hpp"
#include "io/appendf.hpp"

namespace ctid {

namespace {
using io_detail::appendf;

// Degrees from radians with the constant the response tables were always written with.
double degrees(double rad) { return rad * 180 / 3.14159265358979; }

void estimate_text(std::string& out, const std::string& title, const PoleEstimate& p) {
  appendf(out, "%s\n  characteristic polynomial: %s\n  poles:", title.c_str(), p.characteristic.to_string("s", 6).c_str());
  for (auto z : p.poles) appendf(out, "  %.6g%+.6gj", z.real(), z.imag());
  appendf(out, "\n  condition number: %.4g\n", p.condition);
  for (const auto& w : p.warnings) appendf(out, "  warning: %s\n", w.c_str());
}

std::string two_decimals(double v) {
  std::string s;
  appendf(s, "%.2f", v);
  return s;
}

// "passed", "N failed" or "-" (no test could be run) over every output's whiteness and independence tests.
std::string tests_text(const ModelComparison& c) {
  int failed = 0, run = 0;
  for (std::size_t j = 0; j < c.whiteness.size(); ++j) {
    if (c.whiteness[j].lags.size() == 0) continue;
    ++run;
    failed += !c.whiteness[j].passed();
    for (const auto& x : c.independence[j]) failed += !x.passed();
  }
  if (run == 0) return "-";
  return failed == 0 ? "passed" : std::to_string(failed) + " failed";
}
}  // namespace

std::string poles_text(const PolesComparison& c) {
  std::string out;
  for (const auto& choice : c.choices) appendf(out, "chosen: %s\n", choice.c_str());
  estimate_text(out, "data-matrix method (Theorem 4.3, El-Shafey 1987):", c.data_matrix);
  if (c.free_response.generator.degree() > 0)
    appendf(out, "  before deflation by the generator: %s\n", c.data_matrix.augmented.to_string("s", 6).c_str());
  const PronyOptions& po = c.prony_options;
  if (c.prony)
    estimate_text(out, detail::format("Prony (order {}, T = {} samples, {} equations):", po.order, po.spacing, po.equations),
                  *c.prony);
  else
    appendf(out, "Prony: not computed (%s)\n", c.prony_problem.c_str());
  return out;
}

std::string modal_response_text(const ModalResponse& m) {
  std::string out = "modal parameters p_0:";
  const auto n = m.modal.shifts.size();
  for (Eigen::Index i = 0; i < n; ++i) appendf(out, " %.6g", m.p0.model.P()(0, i));
  out += "   (shifts";
  for (Eigen::Index i = 0; i < n; ++i) appendf(out, " %.6g", m.modal.shifts(i));
  appendf(out, " s)   (%zu windows, condition %.3g)\n", m.modal.windows.size(), m.p0.diagnostics.condition_number);
  const auto [names, tab] = modal_response_table(m);
  if (m.kind == ResponseKind::Frequency) {
    for (Eigen::Index i = 0; i < tab.rows(); ++i)
      appendf(out, "  w = %-10.5g  H = %.6g %+.6gj   |H| = %.6g  phase = %.4g deg\n", tab(i, 0), tab(i, 1), tab(i, 2),
              tab(i, 3), tab(i, 4));
    return out;
  }
  const auto K = tab.rows();
  for (Eigen::Index i = 0; i < K; i += std::max<Eigen::Index>(1, K / 20))
    appendf(out, "  t = %-10.5g  %s = %.6g\n", tab(i, 0), names[1].c_str(), tab(i, 1));
  return out;
}

std::pair<std::vector<std::string>, Eigen::MatrixXd> modal_response_table(const ModalResponse& m) {
  if (m.kind == ResponseKind::Frequency) {
    const FrequencyData& f = m.frequency.response;
    Eigen::MatrixXd tab(f.size(), 5);
    for (int i = 0; i < f.size(); ++i) {
      const auto G = f.response()(i);
      tab.row(i) << f.w()(i), G.real(), G.imag(), std::abs(G), degrees(std::arg(G));
    }
    return {{"w", "re", "im", "mag", "phase_deg"}, tab};
  }
  Eigen::MatrixXd tab(m.time.t.size(), 2);
  tab << m.time.t, m.time.value;
  return {{"t", m.kind == ResponseKind::Impulse ? "impulse" : "step"}, tab};
}

std::string comparison_text(const IdData& d, const std::vector<ModelComparison>& cs) {
  std::string out;
  std::size_t width = 5;
  for (const auto& c : cs) width = std::max(width, c.name.size());
  const int w = static_cast<int>(width);
  appendf(out, "%-*s  %-17s  %-9s", w, "model", "type", "initial");
  for (int j = 0; j < d.ny(); ++j)
    appendf(out, "  %9s", d.ny() > 1 ? ("fit% " + channel_name(d.output_names(), j)).c_str() : "fit %");
  appendf(out, "  %9s  %10s  %s\n", "NRMSE", "AIC", "residual tests");
  for (const ModelComparison& c : cs) {
    appendf(out, "%-*s  %-17s  %-9s", w, c.name.c_str(), model_type_name(c.model), to_string(c.initial));
    for (const FitReport& f : c.fits)
      appendf(out, "  %9s", std::isfinite(f.fit_percent) ? two_decimals(f.fit_percent).c_str() : "diverges");
    appendf(out, "  %9.4g  %10.5g  %s\n", c.mean_nrmse(), c.total_aic(), tests_text(c).c_str());
  }
  if (cs.empty()) return out;
  const std::size_t best = best_comparison(cs);
  appendf(out, "best: %s (%s %%%s)\n", cs[best].name.c_str(), two_decimals(cs[best].mean_fit()).c_str(),
          d.ny() > 1 ? ", mean over the outputs" : "");
  return out;
}

std::string held_out_text(const Result<AnyModel>& r, const std::string& name, const IdData& d) {
  const SimulateOptions so = simulate_options(r, SimulationPurpose::Validation);
  const Simulation s = simulate(r.model, d, so);
  std::string out;
  appendf(out, "\nvalidation on %s (%d samples, initial state: %s):", name.c_str(), d.size(),
          so.initial == InitialCondition::Estimated ? "the one that fits them best" : to_string(so.initial));
  if (!s.ok()) {
    appendf(out, " %s\n", s.problem.c_str());
    return out;
  }
  for (int j = 0; j < d.ny(); ++j)
    appendf(out, "%s fit %s %%", d.ny() > 1 ? ("  " + channel_name(d.output_names(), j)).c_str() : "",
            fit_percent_text(fit_percent(d.y().col(j), s.y.col(j))).c_str());
  out += "\n";
  return out;
}

std::string validation_text(const IdData& d, const std::vector<OutputScore>& scores) {
  std::string out;
  for (const OutputScore& o : scores) {
    if (scores.size() > 1) appendf(out, "output %s:\n", o.output.c_str());
    const FitReport& f = o.fit;
    const CorrelationTest& ac = o.whiteness;
    const int lags = ac.lags.size() > 0 ? static_cast<int>(ac.lags(ac.lags.size() - 1)) : 0;
    appendf(out, "fit: %s %%   NRMSE %.4g   MSE %.4g   (%d samples)\n", fit_percent_text(f.fit_percent).c_str(), f.nrmse,
            f.mse, f.n_samples);
    appendf(out, "residual whiteness (lags 1..%d): %d outside the 99 %% bound %.3g -> %s\n", lags, ac.n_outside, ac.bound,
            ac.passed() ? "passed" : "not white");
    for (std::size_t i = 0; i < o.independence.size(); ++i)
      appendf(out, "input %s - residual independence (lags -%d..%d): %d outside -> %s\n",
              channel_name(d.input_names(), static_cast<int>(i)).c_str(), lags, lags, o.independence[i].n_outside,
              o.independence[i].passed() ? "passed" : "correlated (unmodelled dynamics)");
  }
  return out;
}

}  // namespace ctid
