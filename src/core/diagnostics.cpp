// ctid — the catalogue of declared diagnostics (include/ctid/core/diagnostics.hpp).
#include "ctid/core/diagnostics.hpp"

#include "ctid/core/check.hpp"

namespace ctid {

namespace {
template <class T>
DiagnosticInfo info(const DiagnosticKey<T>& k) {
  return {std::string(k.name), std::string(k.unit), std::string(k.doc), std::is_same_v<T, Eigen::VectorXd>, k.per_record};
}
}  // namespace

const std::vector<DiagnosticInfo>& diagnostic_catalogue() {
  static const std::vector<DiagnosticInfo> all = {
      info(diagnostic::experiments),
      info(diagnostic::noise_variance),
      info(diagnostic::residual_ar_order),
      info(diagnostic::white_noise_std),
      info(diagnostic::delay),
      info(diagnostic::time_scale),
      info(diagnostic::tau),
      info(diagnostic::cost),
      info(diagnostic::cost_history),
      info(diagnostic::evaluations),
      info(diagnostic::jacobian_evaluations),
      info(diagnostic::err),
      info(diagnostic::delay_grid),
      info(diagnostic::delay_grid_mse),
      info(diagnostic::srivc_iterations),
      info(diagnostic::srivc_fit_percent),
      info(diagnostic::output_error_lag1_correlation),
      info(diagnostic::frequency_scale),
      info(diagnostic::sk_iterations),
      info(diagnostic::equation_error_variance),
      info(diagnostic::theta_tau),
      info(diagnostic::B_at_minus_1_over_tau),
      info(diagnostic::tau_grid),
      info(diagnostic::tau_grid_fit_percent),
      info(diagnostic::fsf_N),
      info(diagnostic::fsf_a),
      info(diagnostic::fsf_b),
      info(diagnostic::regression_fit_percent),
      info(diagnostic::residual_rms),
      info(diagnostic::compressed_fit_percent),
      info(diagnostic::shift_a),
      info(diagnostic::max_pole_real_part),
      info(diagnostic::windows),
      info(diagnostic::condition_by_order),
      info(diagnostic::criterion),
      info(diagnostic::esr),
      info(diagnostic::candidates),
      info(diagnostic::narmax_iterations),
      info(diagnostic::relative_change),
      info(diagnostic::first_iteration),
      info(diagnostic::gls_iterations),
      info(diagnostic::gls_order),
      info(diagnostic::err_sum),
      info(diagnostic::narx_fit_percent),
      info(diagnostic::x0),
      info(diagnostic::start_scale),
      info(diagnostic::starts_cost), info(diagnostic::segments), info(diagnostic::continuity_defect),
      info(diagnostic::singular_values), info(diagnostic::output_fit_percent),
      info(diagnostic::output_noise_variance), info(diagnostic::start_fit_percent), info(diagnostic::mode_wn_std),
      info(diagnostic::prediction_fit_percent), info(diagnostic::warm_up_iterations),
      info(diagnostic::mode_zeta_std), info(diagnostic::chi2_per_dof), info(diagnostic::nx_grid), info(diagnostic::nx_grid_bic),
      info(diagnostic::structure_nb), info(diagnostic::structure_nf), info(diagnostic::structure_delay),
      info(diagnostic::structure_bic)};
  return all;
}

const DiagnosticInfo* find_diagnostic(const std::string& stored) {
  for (const DiagnosticInfo& d : diagnostic_catalogue()) {
    if (stored == d.name) return &d;
    // NAME_k (k >= 2) of a per-record diagnostic.
    if (d.per_record && stored.size() > d.name.size() + 1 && stored.compare(0, d.name.size(), d.name) == 0 &&
        stored[d.name.size()] == '_' && stored.find_first_not_of("0123456789", d.name.size() + 1) == std::string::npos)
      return &d;
  }
  return nullptr;
}

double Diagnostics::get(const ScalarDiagnostic& key) const {
  const auto it = scalars_.find(std::string(key.name));
  CTID_REQUIRE(it != scalars_.end(), "diagnostic '{}' was not reported by this fit", key.name);
  return it->second;
}

const Eigen::VectorXd& Diagnostics::get(const VectorDiagnostic& key, int record) const {
  const auto it = vectors_.find(stored_name(key, record));
  CTID_REQUIRE(it != vectors_.end(), "diagnostic '{}' was not reported by this fit", stored_name(key, record));
  return it->second;
}

void Diagnostics::set_stored(const std::string& name, double value) {
  const DiagnosticInfo* d = find_diagnostic(name);
  CTID_REQUIRE(d && !d->vector, "'{}' is not a declared scalar diagnostic", name);
  scalars_[name] = value;
}

void Diagnostics::set_stored(const std::string& name, Eigen::VectorXd value) {
  const DiagnosticInfo* d = find_diagnostic(name);
  CTID_REQUIRE(d && d->vector, "'{}' is not a declared vector diagnostic", name);
  vectors_[name] = std::move(value);
}

}  // namespace ctid
