// ctid — method-specific diagnostics of a fit, declared once (typed diagnostics).
//
// Each diagnostic an estimator can report is a typed key declared in namespace ctid::diagnostic: its name (the key
// in result files, Python's dicts and the report), its unit and its meaning. Estimators write and callers read them
// only through these keys (Diagnostics::set / get / has), so a misspelt name is a compile error and a value has one
// type and one unit everywhere; diagnostic_catalogue() lists them for the report, the CLI help and Python. Which
// method reports which is in the method registry (MethodInfo::diagnostics).
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

namespace ctid {

/// A declared diagnostic of type T (double or Eigen::VectorXd). per_record: one value per record of a joint fit,
/// named NAME for the first and NAME_2, NAME_3, .. for the others.
template <class T>
struct DiagnosticKey {
  std::string_view name;
  std::string_view unit;  ///< "" for a pure number; "y^2" / "s" / "%" / "rad/s" ...
  std::string_view doc;
  bool per_record = false;
};
using ScalarDiagnostic = DiagnosticKey<double>;
using VectorDiagnostic = DiagnosticKey<Eigen::VectorXd>;

namespace diagnostic {
// Shared by several estimators.
inline constexpr ScalarDiagnostic experiments{"experiments", "", "number of records fitted jointly (only when > 1)"};
inline constexpr ScalarDiagnostic noise_variance{"noise_variance", "y^2",
                                                 "variance of the output error (the noise estimate behind the covariance)"};
inline constexpr ScalarDiagnostic residual_ar_order{
    "residual_ar_order", "",
    "order of the AR model of the output error behind the standard deviations (the largest over the outputs; 0: "
    "white, the covariance is sigma^2 (J^T J)^-1)"};
inline constexpr VectorDiagnostic white_noise_std{
    "white_noise_std", "",
    "standard deviation of each parameter if the output error were white, sigma (J^T J)^-1/2 (in the parameter's "
    "unit; 0 for fixed ones); the reported ones allow for the error's colour"};
inline constexpr ScalarDiagnostic delay{"delay", "s", "input-output delay of the model (estimated or given)"};
inline constexpr ScalarDiagnostic time_scale{"time_scale", "s",
                                             "time unit the estimation ran in (its results are converted back to seconds)"};
inline constexpr ScalarDiagnostic tau{"tau", "s", "time constant of the state-variable filters 1/(1 + p tau)"};
inline constexpr ScalarDiagnostic cost{"cost", "", "final value of the least-squares cost"};
inline constexpr ScalarDiagnostic evaluations{"evaluations", "",
                                             "cost evaluations of the search (each a simulation pass over the records)"};
inline constexpr ScalarDiagnostic jacobian_evaluations{"jacobian_evaluations", "",
                                                      "evaluations of the search that also computed the Jacobian"};
inline constexpr VectorDiagnostic cost_history{"cost_history", "", "cost after each iteration of the search"};
inline constexpr VectorDiagnostic err{"err", "%", "error reduction ratio of each selected term, in order of selection"};
// SRIVC / output error.
inline constexpr VectorDiagnostic delay_grid{"delay_grid", "s", "delays tried by the delay search"};
inline constexpr VectorDiagnostic delay_grid_mse{"delay_grid_mse", "y^2", "output-error MSE at each delay tried"};
inline constexpr ScalarDiagnostic srivc_iterations{"srivc_iterations", "", "iterations of the SRIVC start of tfest"};
inline constexpr ScalarDiagnostic srivc_fit_percent{"srivc_fit_percent", "%", "simulation fit of the SRIVC start of tfest"};
inline constexpr ScalarDiagnostic output_error_lag1_correlation{
    "output_error_lag1_correlation", "", "lag-1 autocorrelation of the closed-loop output error"};
// Frequency-domain fit.
inline constexpr ScalarDiagnostic frequency_scale{"frequency_scale", "rad/s",
                                                  "frequency unit the fit ran in (its results are converted back)"};
inline constexpr ScalarDiagnostic sk_iterations{"sk_iterations", "", "Sanathanan-Koerner iterations of the start"};
// LSSVF / IVSVF / RLS-SVF (Johansson 1986).
inline constexpr ScalarDiagnostic equation_error_variance{"equation_error_variance", "",
                                                          "variance of the filtered equation error (RJ-A4)"};
inline constexpr VectorDiagnostic theta_tau{"theta_tau", "", "parameters of the filtered (lambda-operator) model"};
inline constexpr ScalarDiagnostic B_at_minus_1_over_tau{"B_at_minus_1_over_tau", "",
                                                        "numerator at s = -1/tau (RJ-A5: near 0, a zero cancels the filter)"};
inline constexpr VectorDiagnostic tau_grid{"tau_grid", "s", "filter time constants tried by the automatic choice"};
inline constexpr VectorDiagnostic tau_grid_fit_percent{"tau_grid_fit_percent", "%", "simulation fit at each tau tried"};
// FSF (Gawthrop & Wang 2005) and physical parameters.
inline constexpr ScalarDiagnostic fsf_N{"N", "", "FSF window length T / Ts in samples"};
inline constexpr ScalarDiagnostic fsf_a{"a", "1/s", "exponential window: the model is G(s + a)"};
inline constexpr ScalarDiagnostic fsf_b{"b", "1/s", "FSF filter pole shift b"};
inline constexpr ScalarDiagnostic regression_fit_percent{"regression_fit_percent", "%",
                                                         "fit of the FSF regression (one-step, on the filtered data)"};
inline constexpr ScalarDiagnostic residual_rms{"residual_rms", "y", "RMS of the FSF regression residual"};
inline constexpr ScalarDiagnostic compressed_fit_percent{
    "compressed_fit_percent", "%", "fit of a physical FSF-route model to the compressed (FSF) response it was fitted to"};
inline constexpr ScalarDiagnostic shift_a{"shift_a", "1/s", "exponential window a of the physical fit"};
inline constexpr ScalarDiagnostic max_pole_real_part{"max_pole_real_part", "1/s",
                                                     "largest real part of the fitted plant's poles (a must exceed it)"};
// Modal functions (El-Shafey 1987).
inline constexpr ScalarDiagnostic windows{"windows", "", "validity windows the modal equations were taken on"};
inline constexpr VectorDiagnostic condition_by_order{"condition_by_order", "",
                                                     "condition number of the modal regression of each order j"};
// FROLS / NARMAX / KIA (Billings & Li 1999).
inline constexpr VectorDiagnostic criterion{"criterion", "", "information criterion after 1, 2, .. selected terms"};
inline constexpr ScalarDiagnostic esr{"esr", "", "error-to-signal ratio 1 - sum(ERR) of the selected terms"};
inline constexpr ScalarDiagnostic candidates{"candidates", "", "number of candidate terms"};
inline constexpr ScalarDiagnostic narmax_iterations{"narmax_iterations", "", "NARMAX noise-model iterations"};
inline constexpr ScalarDiagnostic relative_change{"relative_change", "",
                                                  "relative change of the process terms in the last NARMAX iteration"};
inline constexpr VectorDiagnostic first_iteration{"first_iteration", "", "KIA stage estimate by plain least squares"};
inline constexpr ScalarDiagnostic gls_iterations{"gls_iterations", "", "generalised least-squares iterations of a KIA stage"};
inline constexpr ScalarDiagnostic gls_order{"gls_order", "", "order of the GLS noise model of a KIA stage"};
inline constexpr ScalarDiagnostic err_sum{"err_sum", "%", "sum of the ERR of a KIA stage's terms"};
inline constexpr ScalarDiagnostic narx_fit_percent{"narx_fit_percent", "%",
                                                   "free-run fit of the NARX model KIA reconstructed from, on the same "
                                                   "records (a KIA equation below half of it is not usable)"};
// NDE output error.
// Subspace identification.
inline constexpr VectorDiagnostic singular_values{"singular_values", "",
                                                  "singular values of the weighted projected output block (order choice)"};
inline constexpr VectorDiagnostic output_fit_percent{"output_fit_percent", "%", "simulation fit of each output"};
inline constexpr VectorDiagnostic x0{"x0", "", "fitted initial state of each record", true};
// State-space output error (ssest).
inline constexpr VectorDiagnostic output_noise_variance{"output_noise_variance", "y^2",
                                                        "variance of each output's error (the weights 1/variance of the cost)"};
inline constexpr VectorDiagnostic prediction_fit_percent{
    "prediction_fit_percent", "%", "one-step-ahead prediction fit of each output (a model with an innovation gain)"};
inline constexpr ScalarDiagnostic warm_up_iterations{
    "warm_up_iterations", "", "iterations on the records' beginnings before the full records (long records)"};
inline constexpr ScalarDiagnostic start_fit_percent{"start_fit_percent", "%", "simulation fit of the subspace start"};
inline constexpr VectorDiagnostic mode_wn_std{"mode_wn_std", "rad/s",
                                              "standard deviation of each mode's natural frequency (modes in model order)"};
inline constexpr VectorDiagnostic mode_zeta_std{"mode_zeta_std", "", "standard deviation of each mode's damping ratio"};
inline constexpr ScalarDiagnostic chi2_per_dof{
    "chi2_per_dof", "", "weighted residual sum of squares per degree of freedom (1: residuals at the given noise level)"};
// srivc_auto: every structure tried, in the order tried.
inline constexpr VectorDiagnostic structure_nb{"structure_nb", "", "numerator coefficients of each structure tried"};
inline constexpr VectorDiagnostic structure_nf{"structure_nf", "", "model order of each structure tried"};
inline constexpr VectorDiagnostic structure_delay{"structure_delay", "s",
                                                  "input delay of each structure tried (0: fitted without delay)"};
inline constexpr VectorDiagnostic structure_bic{"structure_bic", "", "BIC of each structure tried (NaN: not usable)"};
inline constexpr VectorDiagnostic nx_grid{"nx_grid", "", "state dimensions tried by the order search"};
inline constexpr VectorDiagnostic nx_grid_bic{"nx_grid_bic", "", "BIC of the fit at each state dimension tried"};
inline constexpr ScalarDiagnostic start_scale{"start_scale", "",
                                              "factor the NDE start was shrunk by until its simulation was finite"};
// Grey-box output error.
inline constexpr VectorDiagnostic starts_cost{"starts_cost", "",
                                              "final cost of each start of a multi-start search (grey box, NDE: 1/2 sum "
                                              "of squared weighted errors; ssest: the MSE of the outputs scaled by their "
                                              "standard deviations)"};
inline constexpr ScalarDiagnostic segments{"segments", "", "multiple-shooting segments of all records (when used)"};
inline constexpr ScalarDiagnostic continuity_defect{
    "continuity_defect", "", "largest |x_end - x_start| at a segment boundary relative to the state's RMS (multiple shooting)"};
}  // namespace diagnostic

/// One declared diagnostic, untyped (for listings).
struct DiagnosticInfo {
  std::string name, unit, doc;
  bool vector = false;
  bool per_record = false;
};
/// Every declared diagnostic, in declaration order.
const std::vector<DiagnosticInfo>& diagnostic_catalogue();
/// The declared diagnostic of a stored name (NAME_k of a per-record one included), or nullptr.
const DiagnosticInfo* find_diagnostic(const std::string& stored_name);

/// Numerical diagnostics of a fit: the condition number and warnings every estimator reports, plus the
/// method-specific values it declares (see namespace diagnostic).
class Diagnostics {
 public:
  double condition_number = 0.0;             ///< of the column-scaled regressor / information matrix
  std::vector<std::string> warnings;         ///< things the user should look at; empty when none
  /// Settings the estimator chose itself because they were left automatic, one line each:
  /// "NAME = VALUE (unit): why" (e.g. the FSF window from a pre-estimate's settling time). Empty when every
  /// setting was given.
  std::vector<std::string> choices;

  void set(const ScalarDiagnostic& key, double value) { scalars_[std::string(key.name)] = value; }
  /// record: the record of a per-record diagnostic (0 = the first).
  void set(const VectorDiagnostic& key, Eigen::VectorXd value, int record = 0) {
    vectors_[stored_name(key, record)] = std::move(value);
  }
  bool has(const ScalarDiagnostic& key) const { return scalars_.contains(std::string(key.name)); }
  bool has(const VectorDiagnostic& key, int record = 0) const { return vectors_.contains(stored_name(key, record)); }
  /// The value; throws InvalidArgument naming the diagnostic when this fit did not report it.
  double get(const ScalarDiagnostic& key) const;
  const Eigen::VectorXd& get(const VectorDiagnostic& key, int record = 0) const;
  /// A stored value by its name, as read from a result file; throws InvalidArgument for a name that is not
  /// declared, or declared with the other type.
  void set_stored(const std::string& name, double value);
  void set_stored(const std::string& name, Eigen::VectorXd value);

  /// Everything reported, by stored name (for rendering: the report, JSON, Python).
  const std::map<std::string, double>& scalars() const { return scalars_; }
  const std::map<std::string, Eigen::VectorXd>& vectors() const { return vectors_; }

 private:
  template <class T>
  static std::string stored_name(const DiagnosticKey<T>& key, int record) {
    return record == 0 ? std::string(key.name) : std::string(key.name) + "_" + std::to_string(record + 1);
  }
  std::map<std::string, double> scalars_;
  std::map<std::string, Eigen::VectorXd> vectors_;
};

}  // namespace ctid
