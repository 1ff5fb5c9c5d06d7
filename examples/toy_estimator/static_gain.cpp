// static_gain — the toy estimator of docs/architecture.md: its options table, the estimator, its run and the one
// line that registers it.
#include "static_gain.hpp"

#include <cmath>

template <>
const ctid::OptionTable<toy::StaticGainOptions>& ctid::option_table<toy::StaticGainOptions>() {
  using O = toy::StaticGainOptions;
  static const OptionTable<O> t =
      OptionTable<O>("static_gain").real("ridge", &O::ridge, "", at_least(0), "added to u'u: shrinks K towards 0");
  return t;
}

namespace toy {

ctid::Result<ctid::TransferFunction> static_gain(const ctid::IdData& d, const StaticGainOptions& o) {
  ctid::option_table<StaticGainOptions>().check(o);
  if (d.nu() != 1 || d.ny() != 1)
    throw ctid::InvalidArgument("static_gain: one input and one output (got " + std::to_string(d.nu()) + " and " +
                                std::to_string(d.ny()) + ")");
  const Eigen::VectorXd u = d.u().col(0), y = d.y().col(0);
  const double uu = u.squaredNorm() + o.ridge;
  const double k = u.dot(y) / uu;
  const Eigen::VectorXd e = y - k * u;
  const int n = d.size();
  ctid::Result<ctid::TransferFunction> r;
  r.model = ctid::TransferFunction({k}, {1.0});
  r.parameters.names = {"b0"};
  r.parameters.values = Eigen::VectorXd::Constant(1, k);
  r.parameters.fixed = {false};
  r.parameters.set_covariance(Eigen::MatrixXd::Constant(1, 1, e.squaredNorm() / (n - 1) / uu));
  r.fit = ctid::fit_report_or_inf(y, k * u, 1);
  r.summary.iterations = 1;
  return r;
}

// The registry's run: the settings applied to the options, the estimator, the outcome.
ctid::FitOutcome run_static_gain(const ctid::FitRequest& r) {
  StaticGainOptions o;
  ctid::apply_settings("static_gain", r.settings, {}, o);
  return ctid::fit_outcome(static_gain(r.records.front(), o), "static_gain", ctid::settings_text(o));
}

}  // namespace toy

CTID_REGISTER_METHOD(ctid::fit_method<toy::StaticGainOptions>("static_gain", "toy: y = K u by least squares",
                                                              {.model_types = {"transfer_function"}},
                                                              toy::run_static_gain));
