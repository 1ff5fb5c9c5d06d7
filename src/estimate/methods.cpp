// ctid — the registry of estimation methods (estimate/methods.hpp), built from the options tables.
#include "ctid/estimate/methods.hpp"

#include <algorithm>
#include <deque>
#include <map>

#include "ctid/core/check.hpp"
#include "ctid/core/error.hpp"
#include "ctid/estimate/transfer_function/frequency.hpp"
#include "ctid/estimate/nonlinear/frols.hpp"
#include "ctid/estimate/fsf/fsf.hpp"
#include "ctid/estimate/greybox/greybox.hpp"
#include "ctid/estimate/nonlinear/kia.hpp"
#include "ctid/estimate/svf/lssvf.hpp"
#include "ctid/estimate/modal/modal.hpp"
#include "ctid/estimate/nonlinear/nde_oe.hpp"
#include "ctid/estimate/transfer_function/oe.hpp"
#include "ctid/estimate/fsf/physical.hpp"
#include "ctid/estimate/svf/rls_svf.hpp"
#include "ctid/estimate/transfer_function/srivc.hpp"
#include "ctid/estimate/transfer_function/srivc_auto.hpp"
#include "ctid/estimate/state_space/ssest.hpp"
#include "ctid/estimate/state_space/subspace.hpp"
#include "fit_runs.hpp"

namespace ctid {

namespace {
template <class... O>
MethodInfo entry(std::string name, std::string summary, std::vector<std::string> structs,
                 std::vector<std::string> diagnostics) {
  for (const auto& d : diagnostics) CTID_ASSERT(find_diagnostic(d) != nullptr);
  MethodInfo m;
  m.name = std::move(name);
  m.summary = std::move(summary);
  m.options = std::move(structs);
  m.diagnostics = std::move(diagnostics);
  (
      [&] {
        for (auto& i : option_table<O>().info()) {
          CTID_ASSERT(std::none_of(m.settings.begin(), m.settings.end(),
                                   [&](const OptionInfo& s) { return s.name == i.name; }));
          m.settings.push_back(std::move(i));
        }
      }(),
      ...);
  return m;
}

// A method that fits records: its capabilities, its run and the other spellings of its name.
MethodInfo fits(MethodInfo m, MethodCapabilities c, std::function<FitOutcome(const FitRequest&)> run,
                std::vector<std::string> aliases = {}) {
  c.records = true;
  m.capabilities = std::move(c);
  m.run = std::move(run);
  m.aliases = std::move(aliases);
  static const std::map<std::string, std::vector<std::string>> variants = {
      {"srivc", {"srivc_miso", "srivc_closed_loop"}}, {"oe", {"tf_from_frequency"}}, {"tfest", {"tf_from_frequency"}},
      {"kia", {"narx"}}};
  if (variants.count(m.name)) m.variants = variants.at(m.name);
  return m;
}

// An entry that does not run on its own (a variant, a stage or a tool), and how it is reached.
MethodInfo reached(MethodInfo m, std::string by) {
  m.reached_by = std::move(by);
  return m;
}


// The names of diagnostic keys (both types).
template <class... K>
std::vector<std::string> reports(const K&... keys) {
  return {std::string(keys.name)...};
}

// The library's methods, in the order of docs/methods.
std::deque<MethodInfo> library_methods() {
  using namespace diagnostic;  // the keys of what each method reports
  const std::vector<std::string> tf{"transfer_function"};
  return {
      fits(entry<LssvfOptions>("lssvf", "Johansson (1986) least squares on state-variable-filtered signals",
                               {"LssvfOptions"},
                               reports(tau, equation_error_variance, theta_tau, B_at_minus_1_over_tau, tau_grid,
                                       tau_grid_fit_percent, experiments)),
           {.several_records = true, .frequency_data = true, .orders = true, .needs_orders = true, .model_types = tf},
           fit_runs::lssvf),
      fits(entry<IvsvfOptions>("ivsvf", "Johansson's regression with instrumental variables from an auxiliary model",
                               {"IvsvfOptions"},
                               reports(tau, equation_error_variance, theta_tau, B_at_minus_1_over_tau, tau_grid,
                                       tau_grid_fit_percent, experiments)),
           {.several_records = true, .orders = true, .needs_orders = true, .model_types = tf}, fit_runs::ivsvf),
      fits(entry<RlsSvfOptions>("rls_svf", "recursive least squares on state-variable-filtered signals (RJ 59-60)",
                                {"RlsSvfOptions"}, reports(tau, experiments)),
           {.several_records = true, .orders = true, .needs_orders = true, .model_types = tf}, fit_runs::rls_svf,
           {"rls-svf"}),
      fits(entry<SrivcOptions>("srivc", "simplified refined instrumental variables, one input", {"SrivcOptions"},
                               reports(delay, noise_variance, delay_grid, delay_grid_mse, time_scale, experiments)),
           {.several_records = true,
            .several_inputs = true,
            .orders = true,
            .needs_orders = true,
            .references = true,
            .model_types = {"transfer_function", "miso"}},
           fit_runs::srivc),
      fits(entry<SrivcAutoOptions>("srivc_auto",
                                   "SRIVC over nf = 1..nf_max, nb = 1..nf, with and without a delay; the least BIC "
                                   "(the default of ctid fit)",
                                   {"SrivcAutoOptions"},
                                   reports(delay, noise_variance, delay_grid, delay_grid_mse, time_scale, structure_nb,
                                           structure_nf, structure_delay, structure_bic)),
           {.several_inputs = true, .model_types = {"transfer_function", "miso"}, .default_detrend = "mean"}, fit_runs::srivc_auto,
           {"srivc-auto"}),
      reached(entry<SrivcMisoOptions>("srivc_miso", "SRIVC with several inputs (one transfer function per input)",
                                      {"SrivcMisoOptions"}, reports(noise_variance, time_scale, experiments)),
              "srivc on records with several inputs"),
      reached(entry<ClosedLoopOptions>("srivc_closed_loop",
                                       "closed-loop SRIVC with a known controller (instruments from the reference)",
                                       {"ClosedLoopOptions"},
                                       reports(noise_variance, output_error_lag1_correlation, time_scale, experiments)),
              "srivc with a reference per record (closed loop)"),
      fits(entry<OeOptions>(
               "oe", "continuous-time output error (Levenberg-Marquardt)", {"OeOptions"},
               reports(delay, noise_variance, residual_ar_order, white_noise_std, time_scale, experiments, x0, evaluations,
                       jacobian_evaluations)),
           {.several_records = true, .frequency_data = true, .orders = true, .needs_orders = true, .model_types = tf},
           fit_runs::oe),
      fits(entry<OeOptions>("tfest", "SRIVC start, then output-error refinement", {"OeOptions"},
                            reports(delay, noise_variance, residual_ar_order, white_noise_std, srivc_iterations,
                                    srivc_fit_percent, time_scale, experiments, x0, evaluations, jacobian_evaluations)),
           {.several_records = true, .frequency_data = true, .orders = true, .needs_orders = true, .model_types = tf},
           fit_runs::tfest),
      reached(entry<FrequencyFitOptions>(
                  "tf_from_frequency", "transfer function from frequency-response data (SK, then OE)",
                  {"FrequencyFitOptions"}, reports(noise_variance, frequency_scale, sk_iterations)),
              "tfest or oe on frequency data"),
      fits(entry<FsfOptions>("fsf", "Gawthrop & Wang (2005) frequency-sampling-filter compression", {"FsfOptions"},
                             reports(fsf_N, fsf_a, fsf_b, regression_fit_percent, residual_rms)),
           {.model_types = {"fsf"}}, fit_runs::fsf),
      fits(entry<FsfOptions, PhysicalFitOptions>(
               "physical", "physical parameters of a transfer-function expression (via FSF or raw data)",
               {"FsfOptions", "PhysicalFitOptions"},
               reports(shift_a, cost, cost_history, max_pole_real_part, compressed_fit_percent, experiments, x0,
                       residual_ar_order, white_noise_std)),
           {.several_records = true, .physical_model = true, .model_types = tf}, fit_runs::physical),
      fits(entry<ModalOptions>(
               "modal",
               "El-Shafey (1987) modal functions: transfer function from a generated or piecewise-constant input",
               {"ModalOptions"}, reports(windows, condition_by_order, experiments)),
           {.several_records = true, .orders = true, .needs_orders = true, .model_types = tf}, fit_runs::modal),
      reached(entry<ModalResponseOptions, ModalOptions>("modal_response",
                                                        "El-Shafey (1987) step, impulse or frequency response from a "
                                                        "piecewise-constant or periodic input (ctid response)",
                                                        {"ModalResponseOptions", "ModalOptions"},
                                                        reports(windows, condition_by_order)),
              "ctid response --method modal"),
      reached(entry<PolesOptions>("poles",
                                  "El-Shafey (1987) data-matrix poles of a free response beside Prony's (ctid poles)",
                                  {"PolesOptions"}, {}),
              "ctid poles"),
      fits(
          entry<NarxOptions>("narx",
                             "Billings & Li NARX workflow: candidates from degree and lags, FROLS with a criterion, "
                             "NARMAX with noise_terms > 0",
                             {"NarxOptions"},
                             reports(err, criterion, esr, candidates, narmax_iterations, relative_change, experiments)),
          {.several_records = true, .model_types = {"narx"}}, fit_runs::narx),
      reached(entry<FrolsOptions>("frols", "FROLS/ERR selection among given NARX candidate terms", {"FrolsOptions"},
                                  reports(err, criterion, esr, candidates, experiments)),
              "narx (Python: frols with candidate terms)"),
      reached(entry<NarmaxOptions>(
                  "narmax", "NARMAX: FROLS with noise terms by extended least squares", {"NarmaxOptions"},
                  reports(err, criterion, esr, candidates, narmax_iterations, relative_change, experiments)),
              "narx with noise_terms > 0 (Python: narmax with candidate terms)"),
      fits(entry<KiaOptions>("kia",
                             "Kernel Invariance Algorithm: NDE from a NARX model (stages, stacking, OE refinement)",
                             {"KiaOptions"},
                             reports(err, first_iteration, gls_iterations, gls_order, err_sum, narx_fit_percent, x0,
                                     noise_variance, residual_ar_order, white_noise_std, start_scale, experiments)),
           {.several_records = true, .narx_model = true, .model_types = {"nde"}}, fit_runs::kia),
      reached(entry<KiaLinearOptions>("kia_linear", "KIA linear stage", {"KiaLinearOptions"},
                                      reports(err, first_iteration, gls_iterations, gls_order, err_sum)),
              "kia (its linear stage)"),
      reached(entry<KiaQuadraticOptions>("kia_quadratic", "KIA quadratic stage", {"KiaQuadraticOptions"},
                                         reports(err, first_iteration, gls_iterations, gls_order, err_sum)),
              "kia (its quadratic stage)"),
      reached(entry<KiaCubicOptions>("kia_cubic", "KIA cubic stage", {"KiaCubicOptions"},
                                     reports(err, first_iteration, gls_iterations, gls_order, err_sum)),
              "kia (its cubic stage)"),
      reached(entry<NdeOeOptions>("nde_oe", "output-error refinement of a nonlinear differential equation",
                                  {"NdeOeOptions"},
                                  reports(x0, noise_variance, residual_ar_order, white_noise_std, start_scale, experiments)),
              "kia (its refinement; Python: nde_oe from a given equation)"),
      fits(entry<GreyboxOptions>(
               "greybox", "nonlinear grey-box model (state equations with named parameters) by output error",
               {"GreyboxOptions"},
               reports(x0, noise_variance, residual_ar_order, white_noise_std, starts_cost, experiments, segments,
                       continuity_defect)),
           {.several_records = true,
            .several_inputs = true,
            .several_outputs = true,
            .greybox_model = true,
            .model_types = {"greybox"}},
           fit_runs::greybox),
      fits(entry<SubspaceOptions>(
               "subspace",
               "MIMO continuous-time state space by subspace identification (lambda operator or "
               "discrete MOESP + logm)",
               {"SubspaceOptions"},
               reports(singular_values, output_fit_percent, x0, tau, tau_grid, tau_grid_fit_percent, frequency_scale)),
           {.frequency_data = true,
            .several_inputs = true,
            .several_outputs = true,
            .nx = true,
            .model_types = {"state_space"}},
           fit_runs::subspace),
      fits(entry<SsestOptions>(
               "ssest",
               "MIMO continuous-time state space by output error from the subspace start (modal form, "
               "covariance, several records)",
               {"SsestOptions"},
               reports(singular_values, output_fit_percent, output_noise_variance, residual_ar_order, white_noise_std, x0,
                       start_fit_percent, mode_wn_std, mode_zeta_std, cost, experiments, nx_grid, nx_grid_bic,
                       chi2_per_dof, frequency_scale)),
           {.several_records = true,
            .frequency_data = true,
            .several_inputs = true,
            .several_outputs = true,
            .nx = true,
            .initial_model = true,
            .model_types = {"state_space"}},
           fit_runs::ssest),
  };
}

// Built on first use, so that a register_method() of another file's static initialiser finds it complete.
std::deque<MethodInfo>& registry() {
  static std::deque<MethodInfo> all = library_methods();
  return all;
}
}  // namespace

const std::deque<MethodInfo>& methods() { return registry(); }

bool register_method(MethodInfo m) {
  std::deque<MethodInfo>& all = registry();
  std::vector<std::string> names = m.aliases;
  names.push_back(m.name);
  for (const auto& n : names) {
    CTID_REQUIRE(!n.empty(), "register_method: a method needs a name");
    for (const auto& x : all)
      CTID_REQUIRE(x.name != n && std::find(x.aliases.begin(), x.aliases.end(), n) == x.aliases.end(),
                   "register_method: '{}' is already a method's name", n);
  }
  CTID_REQUIRE(!m.capabilities.records || m.run, "register_method: {} fits records but has no run", m.name);
  for (const auto& d : m.diagnostics)
    CTID_REQUIRE(find_diagnostic(d) != nullptr, "register_method: {} reports '{}', which is not a declared diagnostic",
                 m.name, d);
  all.push_back(std::move(m));
  return true;
}

const MethodInfo& method_info(const std::string& name) {
  for (const auto& m : methods())
    if (m.name == name || std::find(m.aliases.begin(), m.aliases.end(), name) != m.aliases.end()) return m;
  std::vector<std::string> names;
  for (const auto& m : methods()) names.push_back(m.name);
  const std::string near = closest_name(name, names);
  std::string all;
  for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
  throw InvalidOptions(detail::format("'{}' is not a method{} (methods: {})", name,
                                      near.empty() ? std::string() : "; did you mean '" + near + "'?", all));
}

std::vector<std::string> fit_method_names() {
  std::vector<std::string> out;
  for (const auto& m : methods())
    if (m.capabilities.records) out.push_back(m.name);
  return out;
}

std::string fits_where(const std::function<bool(const MethodInfo&)>& has) {
  std::vector<std::string> names;
  for (const auto& m : methods())
    if (m.capabilities.records && has(m)) names.push_back(m.name);
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return out;
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
