// ctid — the initial state of a grey-box model that best explains a record's first samples
// (include/ctid/simulate/simulate.hpp): a small output-error search over the estimated states only, by
// Levenberg-Marquardt on the model's exact sensitivities (Ljung 1999 §7.3), from several starts.
#include <cmath>

#include "ctid/core/check.hpp"
#include "ctid/simulate/simulate.hpp"
#include "internal/levenberg_marquardt.hpp"

namespace ctid {

Eigen::VectorXd greybox_initial_state(const GreyboxModel& model, const IdData& data, int samples, double rtol) {
  CTID_REQUIRE(data.nu() == model.nu() && data.ny() == model.ny(),
               "greybox initial state: the data have {} inputs and {} outputs, the model {} and {}", data.nu(), data.ny(),
               model.nu(), model.ny());
  CTID_REQUIRE(samples >= 0, "greybox initial state: samples must be >= 0 (got {})", samples);
  const int n = samples == 0 ? data.size() : std::min(samples, data.size());
  std::vector<int> which;
  for (int i = 0; i < model.nx(); ++i)
    if (model.spec().initial[i].estimate) which.push_back(i);
  if (which.empty())
    for (int i = 0; i < model.nx(); ++i) which.push_back(i);
  CTID_REQUIRE(n * model.ny() >= static_cast<int>(which.size()),
               "greybox initial state: {} samples cannot determine {} initial states", n, which.size());
  const IdData d = data.slice(0, n);
  const Eigen::VectorXd t = d.times();
  const Intersample hold = greybox_intersample(d);
  const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(d.y().data(), d.y().size());
  Eigen::VectorXd x0 = model.initial_state_guess(data);
  auto state = [&](const Eigen::VectorXd& v) {
    Eigen::VectorXd x = x0;
    for (size_t k = 0; k < which.size(); ++k) x(which[k]) = v(static_cast<Eigen::Index>(k));
    return x;
  };
  const internal::LmEvaluate evaluate = [&](const Eigen::VectorXd& v, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    const GreyboxSensitivities s = model.sensitivities(d.u(), t, hold, state(v), {}, which, rtol);
    if (!s.ok) return false;
    r = y - Eigen::Map<const Eigen::VectorXd>(s.y.data(), s.y.size());
    if (J) {
      J->resize(r.size(), static_cast<Eigen::Index>(which.size()));
      for (int j = 0; j < model.ny(); ++j) J->middleRows(static_cast<Eigen::Index>(j) * n, n) = -s.dy[j];
    }
    return true;
  };
  // Starts: the model's guess (after a fit, the fitted initial state of its first record); then the guess with the
  // estimated states that no output measures at 0, all together and one at a time. A fast state that the fit could not
  // pin down (e.g. a velocity that relaxes within a sample) may carry a value there that no other record can start from.
  std::vector<Eigen::VectorXd> starts(1, Eigen::VectorXd(static_cast<Eigen::Index>(which.size())));
  for (size_t k = 0; k < which.size(); ++k) starts[0](static_cast<Eigen::Index>(k)) = x0(which[k]);
  std::vector<Eigen::Index> hidden;
  for (size_t k = 0; k < which.size(); ++k)
    if (model.output_of_state(which[k]) < 0 && starts[0](static_cast<Eigen::Index>(k)) != 0.0)
      hidden.push_back(static_cast<Eigen::Index>(k));
  if (!hidden.empty()) {
    starts.push_back(starts[0]);
    for (Eigen::Index k : hidden) starts.back()(k) = 0.0;
    if (hidden.size() > 1)
      for (Eigen::Index k : hidden) {
        starts.push_back(starts[0]);
        starts.back()(k) = 0.0;
      }
  }
  const Eigen::VectorXd inf = Eigen::VectorXd::Constant(starts[0].size(), INFINITY);
  internal::LmOptions o;
  o.max_iterations = 100;
  internal::LmResult lm;
  lm.cost = INFINITY;
  for (const Eigen::VectorXd& v : starts) {
    internal::LmResult r = internal::levenberg_marquardt(evaluate, v, -inf, inf, o);
    if (std::isfinite(r.cost) && !(r.cost >= lm.cost)) lm = std::move(r);
  }
  CTID_REQUIRE(std::isfinite(lm.cost), "greybox initial state: the model cannot be simulated on the first {} samples "
               "from its initial-state guess (nor with its unmeasured states at 0)", n);
  return state(lm.x);
}

}  // namespace ctid
