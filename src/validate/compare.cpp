// Several models on one record (include/ctid/validate/compare.hpp): simulate() from each model's validation initial
// condition, fit_report_or_inf per output, the residual tests of validate/residuals.hpp.
#include "ctid/validate/compare.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "ctid/core/check.hpp"
#include "ctid/validate/metrics.hpp"

namespace ctid {

double ModelComparison::mean_fit() const {
  if (fits.empty()) return -std::numeric_limits<double>::infinity();
  double s = 0;
  for (const FitReport& f : fits) s += f.fit_percent;
  return s / static_cast<double>(fits.size());
}

double ModelComparison::mean_nrmse() const {
  double s = 0;
  for (const FitReport& f : fits) s += f.nrmse;
  return fits.empty() ? std::numeric_limits<double>::quiet_NaN() : s / static_cast<double>(fits.size());
}

double ModelComparison::total_aic() const {
  double s = 0;
  for (const FitReport& f : fits) s += f.aic;
  return s;
}

std::size_t best_comparison(const std::vector<ModelComparison>& comparisons) {
  std::size_t best = 0;
  for (std::size_t k = 1; k < comparisons.size(); ++k)
    if (comparisons[k].mean_fit() > comparisons[best].mean_fit()) best = k;
  return best;
}

std::vector<ModelComparison> compare_models(const IdData& data,
                                            const std::vector<std::pair<std::string, AnyModel>>& models,
                                            std::optional<InitialCondition> initial, int max_lag) {
  CTID_REQUIRE(!models.empty(), "compare_models: no model to compare");
  CTID_REQUIRE(max_lag >= 1, "compare_models: max_lag must be >= 1 (got {})", max_lag);
  std::vector<ModelComparison> out;
  for (const auto& [name, model] : models) {
    CTID_REQUIRE(model_inputs(model) == data.nu() && model_outputs(model) == data.ny(),
                 "compare_models: model {} ({}) has {} input(s) and {} output(s); the record has {} and {}", name,
                 model_type_name(model), model_inputs(model), model_outputs(model), data.nu(), data.ny());
    ModelComparison c{name, model, initial ? *initial : validation_initial_condition(model), {}, {}, {}, {}};
    SimulateOptions so;
    so.initial = c.initial;
    try {
      c.simulation = simulate(model, data, so);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument("compare_models: model " + name + ": " + e.what());
    }
    const int n_coefficients = model_coefficient_count(model);
    const int lags = std::min(max_lag, data.size() / 4);
    for (int j = 0; j < data.ny(); ++j) {
      const Eigen::VectorXd y = data.y().col(j), yhat = c.simulation.y.col(j);
      c.fits.push_back(fit_report_or_inf(y, yhat, n_coefficients));
      const Eigen::VectorXd e = y - yhat;
      std::vector<CorrelationTest> cross;
      if (lags < 1 || !std::isfinite(e.squaredNorm()) || e.squaredNorm() == 0) {
        c.whiteness.emplace_back();
      } else {
        c.whiteness.push_back(residual_autocorrelation(e, lags));
        for (int i = 0; i < data.nu(); ++i) cross.push_back(input_residual_crosscorrelation(data.u().col(i), e, lags));
      }
      c.independence.push_back(std::move(cross));
    }
    out.push_back(std::move(c));
  }
  return out;
}

std::vector<OutputScore> score_outputs(const IdData& data, const Eigen::MatrixXd& yhat, int n_coefficients,
                                       int max_lag) {
  CTID_REQUIRE(max_lag >= 1 && max_lag < data.size(), "score_outputs: max_lag must be in [1, {}] (got {})",
               data.size() - 1, max_lag);
  CTID_REQUIRE(yhat.rows() == data.size() && yhat.cols() == data.ny(),
               "score_outputs: the simulation is {} x {}; the record has {} samples of {} output(s)", yhat.rows(),
               yhat.cols(), data.size(), data.ny());
  std::vector<OutputScore> out;
  for (int j = 0; j < data.ny(); ++j) {
    OutputScore s;
    s.output = j < static_cast<int>(data.output_names().size()) ? data.output_names()[static_cast<size_t>(j)]
                                                                : std::to_string(j + 1);
    const Eigen::VectorXd y = data.y().col(j), e = y - yhat.col(j);
    s.fit = fit_report(y, yhat.col(j), n_coefficients);
    s.whiteness = residual_autocorrelation(e, max_lag);
    for (int i = 0; i < data.nu(); ++i) s.independence.push_back(input_residual_crosscorrelation(data.u().col(i), e, max_lag));
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace ctid
