// ctid — the registry of estimation methods (estimate/methods.hpp), built from the options tables.
#include "ctid/estimate/methods.hpp"

#include <algorithm>

#include "ctid/core/check.hpp"
#include "ctid/core/error.hpp"
#include "ctid/estimate/frequency.hpp"
#include "ctid/estimate/frols.hpp"
#include "ctid/estimate/greybox.hpp"
#include "ctid/estimate/fsf.hpp"
#include "ctid/estimate/kia.hpp"
#include "ctid/estimate/lssvf.hpp"
#include "ctid/estimate/modal.hpp"
#include "ctid/estimate/nde_oe.hpp"
#include "ctid/estimate/oe.hpp"
#include "ctid/estimate/physical.hpp"
#include "ctid/estimate/rls_svf.hpp"
#include "ctid/estimate/srivc.hpp"
#include "ctid/estimate/srivc_auto.hpp"
#include "ctid/estimate/ssest.hpp"
#include "ctid/estimate/subspace.hpp"

namespace ctid {

namespace {
template <class... O>
MethodInfo entry(std::string name, std::string summary, std::vector<std::string> structs,
                 std::vector<std::string> diagnostics) {
  for (const auto& d : diagnostics) CTID_ASSERT(find_diagnostic(d) != nullptr);
  MethodInfo m{std::move(name), std::move(summary), std::move(structs), {}, std::move(diagnostics)};
  (
      [&] {
        for (auto& i : option_table<O>().info()) {
          CTID_ASSERT(std::none_of(m.settings.begin(), m.settings.end(), [&](const OptionInfo& s) { return s.name == i.name; }));
          m.settings.push_back(std::move(i));
        }
      }(),
      ...);
  return m;
}

// The names of diagnostic keys (both types).
template <class... K>
std::vector<std::string> reports(const K&... keys) {
  return {std::string(keys.name)...};
}
}  // namespace

const std::vector<MethodInfo>& methods() {
  using namespace diagnostic;  // the keys of what each method reports
  static const std::vector<MethodInfo> all = {
      entry<LssvfOptions>("lssvf", "Johansson (1986) least squares on state-variable-filtered signals",
                          {"LssvfOptions"},
                          reports(tau, equation_error_variance, theta_tau, B_at_minus_1_over_tau, tau_grid,
                                  tau_grid_fit_percent, experiments)),
      entry<IvsvfOptions>("ivsvf", "Johansson's regression with instrumental variables from an auxiliary model",
                          {"IvsvfOptions"},
                          reports(tau, equation_error_variance, theta_tau, B_at_minus_1_over_tau, tau_grid,
                                  tau_grid_fit_percent, experiments)),
      entry<RlsSvfOptions>("rls_svf", "recursive least squares on state-variable-filtered signals (RJ 59-60)",
                           {"RlsSvfOptions"}, reports(tau, experiments)),
      entry<SrivcOptions>("srivc", "simplified refined instrumental variables, one input", {"SrivcOptions"},
                          reports(delay, noise_variance, delay_grid, delay_grid_mse, time_scale, experiments)),
      entry<SrivcAutoOptions>("srivc_auto",
                              "SRIVC over nf = 1..nf_max, nb = 1..nf, with and without a delay; the least BIC "
                              "(the default of ctid fit)",
                              {"SrivcAutoOptions"},
                              reports(delay, noise_variance, delay_grid, delay_grid_mse, time_scale, structure_nb,
                                      structure_nf, structure_delay, structure_bic)),
      entry<SrivcMisoOptions>("srivc_miso", "SRIVC with several inputs (one transfer function per input)",
                              {"SrivcMisoOptions"}, reports(noise_variance, time_scale, experiments)),
      entry<ClosedLoopOptions>(
          "srivc_closed_loop", "closed-loop SRIVC with a known controller (instruments from the reference)",
          {"ClosedLoopOptions"}, reports(noise_variance, output_error_lag1_correlation, time_scale, experiments)),
      entry<OeOptions>("oe", "continuous-time output error (Levenberg-Marquardt)", {"OeOptions"},
                       reports(delay, noise_variance, time_scale, experiments, x0, evaluations, jacobian_evaluations)),
      entry<OeOptions>("tfest", "SRIVC start, then output-error refinement", {"OeOptions"},
                       reports(delay, noise_variance, srivc_iterations, srivc_fit_percent, time_scale, experiments, x0,
                               evaluations, jacobian_evaluations)),
      entry<FrequencyFitOptions>("tf_from_frequency", "transfer function from frequency-response data (SK, then OE)",
                                 {"FrequencyFitOptions"}, reports(noise_variance, frequency_scale, sk_iterations)),
      entry<FsfOptions>("fsf", "Gawthrop & Wang (2005) frequency-sampling-filter compression", {"FsfOptions"},
                        reports(fsf_N, fsf_a, fsf_b, regression_fit_percent, residual_rms)),
      entry<FsfOptions, PhysicalFitOptions>(
          "physical", "physical parameters of a transfer-function expression (via FSF or raw data)",
          {"FsfOptions", "PhysicalFitOptions"},
          reports(shift_a, cost, cost_history, max_pole_real_part, compressed_fit_percent, experiments, x0)),
      entry<ModalOptions>(
          "modal", "El-Shafey (1987) modal functions: transfer function from a generated or piecewise-constant input",
          {"ModalOptions"}, reports(windows, condition_by_order, experiments)),
      entry<ModalResponseOptions, ModalOptions>("modal_response",
                                                "El-Shafey (1987) step, impulse or frequency response from a "
                                                "piecewise-constant or periodic input (ctid response)",
                                                {"ModalResponseOptions", "ModalOptions"},
                                                reports(windows, condition_by_order)),
      entry<PolesOptions>("poles", "El-Shafey (1987) data-matrix poles of a free response beside Prony's (ctid poles)",
                          {"PolesOptions"}, {}),
      entry<NarxOptions>("narx",
                         "Billings & Li NARX workflow: candidates from degree and lags, FROLS with a criterion, "
                         "NARMAX with noise_terms > 0",
                         {"NarxOptions"},
                         reports(err, criterion, esr, candidates, narmax_iterations, relative_change, experiments)),
      entry<FrolsOptions>("frols", "FROLS/ERR selection among given NARX candidate terms", {"FrolsOptions"},
                          reports(err, criterion, esr, candidates, experiments)),
      entry<NarmaxOptions>("narmax", "NARMAX: FROLS with noise terms by extended least squares", {"NarmaxOptions"},
                           reports(err, criterion, esr, candidates, narmax_iterations, relative_change, experiments)),
      entry<KiaOptions>(
          "kia", "Kernel Invariance Algorithm: NDE from a NARX model (stages, stacking, OE refinement)", {"KiaOptions"},
          reports(err, first_iteration, gls_iterations, gls_order, err_sum, x0, noise_variance, start_scale, experiments)),
      entry<KiaLinearOptions>("kia_linear", "KIA linear stage", {"KiaLinearOptions"},
                              reports(err, first_iteration, gls_iterations, gls_order, err_sum)),
      entry<KiaQuadraticOptions>("kia_quadratic", "KIA quadratic stage", {"KiaQuadraticOptions"},
                                 reports(err, first_iteration, gls_iterations, gls_order, err_sum)),
      entry<KiaCubicOptions>("kia_cubic", "KIA cubic stage", {"KiaCubicOptions"},
                             reports(err, first_iteration, gls_iterations, gls_order, err_sum)),
      entry<NdeOeOptions>("nde_oe", "output-error refinement of a nonlinear differential equation", {"NdeOeOptions"},
                          reports(x0, noise_variance, start_scale, experiments)),
      entry<GreyboxOptions>("greybox", "nonlinear grey-box model (state equations with named parameters) by output error",
                            {"GreyboxOptions"}, reports(x0, noise_variance, starts_cost, experiments, segments, continuity_defect)),
      entry<SubspaceOptions>("subspace",
                             "MIMO continuous-time state space by subspace identification (lambda operator or "
                             "discrete MOESP + logm)",
                             {"SubspaceOptions"},
                             reports(singular_values, output_fit_percent, x0, tau, tau_grid, tau_grid_fit_percent, frequency_scale)),
      entry<SsestOptions>("ssest",
                          "MIMO continuous-time state space by output error from the subspace start (modal form, "
                          "covariance, several records)",
                          {"SsestOptions"},
                          reports(singular_values, output_fit_percent, output_noise_variance, x0, start_fit_percent,
                                  mode_wn_std, mode_zeta_std, cost, experiments, nx_grid, nx_grid_bic, chi2_per_dof,
                                  frequency_scale)),
  };
  return all;
}

const MethodInfo& method_info(const std::string& name) {
  for (const auto& m : methods())
    if (m.name == name) return m;
  std::vector<std::string> names;
  for (const auto& m : methods()) names.push_back(m.name);
  const std::string near = closest_name(name, names);
  std::string all;
  for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
  throw InvalidOptions(detail::format("'{}' is not a method{} (methods: {})", name,
                                      near.empty() ? std::string() : "; did you mean '" + near + "'?", all));
}

std::string settings_help(const MethodInfo& m) {
  std::size_t w = 4;
  for (const auto& s : m.settings) w = std::max(w, s.name.size());
  std::string out = "settings of " + m.name + " (--set NAME=VALUE; Python: keyword arguments):\n";
  for (const auto& s : m.settings) {
    std::string line = "  " + s.name + std::string(w - s.name.size() + 2, ' ');
    const std::string d = s.default_value.empty() ? std::string("none") : s.default_value;
    line += "default " + d;
    if (!s.unit.empty() && d != "none") line += " " + s.unit;
    if (!s.unit.empty() && d == "none") line += " (" + s.unit + ")";
    if (!s.range.empty()) line += "; " + s.range;
    line += ". " + s.doc + "\n";
    out += line;
  }
  if (!m.diagnostics.empty()) {
    out += "diagnostics " + m.name + " can report (result files: diagnostics; Python: r.diagnostics):\n";
    for (const auto& name : m.diagnostics) {
      const DiagnosticInfo& d = *find_diagnostic(name);
      out += "  " + d.name + (d.unit.empty() ? "" : " [" + d.unit + "]") + ": " + d.doc + "\n";
    }
  }
  return out;
}

}  // namespace ctid
