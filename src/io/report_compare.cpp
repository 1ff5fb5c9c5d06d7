// ctid — the side-by-side report of several models on one record (ctid compare; io/report.hpp).
#include "ctid/io/report.hpp"

#include <algorithm>
#include <ctime>
#include <cmath>
#include <complex>
#include <numbers>
#include <sstream>

#include "ctid/core/check.hpp"
#include "ctid/estimate/nonlinear/gfrf.hpp"
#include "ctid/io/json.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/simulate/simulate.hpp"
#include "ctid/validate/compare.hpp"
#include "ctid/validate/metrics.hpp"
#include "ctid/validate/residuals.hpp"
#include "ctid/validate/uncertainty.hpp"

#include "report_sections.hpp"

namespace ctid {

using namespace report_detail;

namespace {
// The one-line meaning of a residual test result (Ljung 1999, sec. 16.6), for the table of a comparison.
std::string test_cell(const CorrelationTest& c) {
  if (c.lags.size() == 0) return "-";
  return c.passed() ? "passed" : std::to_string(c.n_outside) + " lag(s) outside";
}

// The summary (best fit, provenance), the table of the models with their fits, NRMSE and AIC, and the record.
void comparison_tables(Page& page, const IdData& d, const std::vector<ModelComparison>& cs, const ReportOptions& o) {
  const size_t best = best_comparison(cs);
  page.section("Summary");
  std::vector<std::vector<std::string>> rows = {
      {"models", std::to_string(cs.size())},
      {"best fit", cs[best].name + " (" + fmt(cs[best].mean_fit(), 4) + " %" + (d.ny() > 1 ? ", mean over the outputs)" : ")")}};
  provenance(rows, o);
  page.table({"", ""}, rows);

  page.section("Models");
  std::vector<std::string> header = {"model", "type", "coefficients", "initial condition"};
  for (int j = 0; j < d.ny(); ++j) header.push_back(d.ny() > 1 ? "fit % (" + output_name(d, j) + ")" : "fit %");
  header.insert(header.end(), {"NRMSE", "AIC"});
  std::vector<std::vector<std::string>> table;
  for (const ModelComparison& c : cs) {
    std::vector<std::string> r = {c.name, model_type_name(c.model), std::to_string(model_coefficient_count(c.model)),
                                  to_string(c.initial)};
    for (const FitReport& f : c.fits) r.push_back(std::isfinite(f.fit_percent) ? fmt(f.fit_percent, 4) : "diverges");
    r.push_back(fmt(c.mean_nrmse(), 4));
    r.push_back(fmt(c.total_aic(), 5));
    table.push_back(r);
  }
  page.table(header, table);
  page.text("Each model is simulated from its initial condition on the record (estimated: the state that fits the "
            "record's first samples best, as MATLAB's compare; measured: the record's own past outputs) and scored on "
            "the whole record. AIC counts each model's coefficients" + std::string(d.ny() > 1 ? ", summed over the outputs" : "") +
            ": lower is better for the same data.");
  for (const ModelComparison& c : cs) {
    page.text("<code>" + escape(c.name) + "</code>: " + escape(describe(c.model, 4)));
    if (!c.simulation.ok()) page.text("<span class=\"warn\">" + escape(c.name + ": " + c.simulation.problem) + "</span>");
  }
  data_section(page, d, o);

}

// The measured output with every model's simulation overlaid, one plot per output.
void comparison_outputs(Page& page, const IdData& d, const std::vector<ModelComparison>& cs, const ReportOptions& o) {
  const auto k = keep(d.size(), o.max_points);
  for (int j = 0; j < d.ny(); ++j) {
    const std::string of = d.ny() > 1 ? " (" + output_name(d, j) + ")" : "";
    page.section("Measured and simulated output" + of);
    std::vector<Series> series = {{"measured", pick(d.y().col(j), k), false, false, true}};
    for (const ModelComparison& c : cs)
      series.push_back({c.name + " (" + (std::isfinite(c.fits[static_cast<size_t>(j)].fit_percent)
                                             ? fmt(c.fits[static_cast<size_t>(j)].fit_percent, 4) + " %"
                                             : std::string("diverges")) + ")",
                        pick(c.simulation.y.col(j), k)});
    page.plot({"Output" + of + ": measured and each model's simulation", "time (s)", "y", pick(d.times(), k), series});
  }

}

// Each model's residual tests (whiteness, independence of each input) per output, with what a failure means.
void comparison_tests(Page& page, const IdData& d, const std::vector<ModelComparison>& cs, const ReportOptions& o) {
  page.section("Residual tests");
  std::vector<std::string> th = {"model"};
  if (d.ny() > 1) th.push_back("output");
  th.push_back("whiteness");
  for (int i = 0; i < d.nu(); ++i) th.push_back("independence of " + input_name(d, i));
  std::vector<std::vector<std::string>> tests;
  for (const ModelComparison& c : cs)
    for (int j = 0; j < d.ny(); ++j) {
      std::vector<std::string> r = {c.name};
      if (d.ny() > 1) r.push_back(output_name(d, j));
      r.push_back(test_cell(c.whiteness[static_cast<size_t>(j)]));
      const auto& ind = c.independence[static_cast<size_t>(j)];
      for (int i = 0; i < d.nu(); ++i) r.push_back(i < static_cast<int>(ind.size()) ? test_cell(ind[static_cast<size_t>(i)]) : "-");
      tests.push_back(r);
    }
  page.table(th, tests);
  page.text("Whiteness fails: the residuals are correlated — the model misses dynamics, or the noise is coloured (an "
            "output-error model does not model the noise). Independence fails: the residuals depend on that input — "
            "the model misses input-output dynamics (order, delay, a nonlinearity), or the data are closed-loop. "
            "99 % bounds, lags up to " + std::to_string(std::min(o.max_lag, d.size() / 4)) + ".");

}

// The Bode plots of the linear models (those with a frequency response) up to the record's Nyquist frequency; returns
// them, and all their poles in `poles`.
std::vector<const ModelComparison*> comparison_bode(Page& page, const IdData& d, const std::vector<ModelComparison>& cs,
                                                    Eigen::VectorXcd& poles) {
  std::vector<const ModelComparison*> linear;
  std::vector<std::complex<double>> all_poles;
  for (const ModelComparison& c : cs) {
    if (!is_linear(c.model)) continue;
    try {
      (void)model_frequency_response(c.model, Eigen::VectorXd::Ones(1));
    } catch (const InvalidArgument& e) {  // a windowed FSF model
      page.text(escape(c.name + ": no frequency or step response (" + e.what() + ")"));
      continue;
    }
    linear.push_back(&c);
    const Eigen::VectorXcd p = model_poles(c.model);
    all_poles.insert(all_poles.end(), p.data(), p.data() + p.size());
  }
  poles = Eigen::Map<const Eigen::VectorXcd>(all_poles.data(), static_cast<Eigen::Index>(all_poles.size()));
  if (!linear.empty()) {
    const Eigen::VectorXd w = frequency_grid(poles, nyquist_or_zero(d));
    for (int i = 0; i < d.nu(); ++i) {
      const std::string from = d.nu() > 1 ? " from " + input_name(d, i) : "";
      std::vector<Series> mag, ph;
      for (const ModelComparison* c : linear) {
        const Eigen::VectorXcd h = model_frequency_response(c->model, w).col(i);
        mag.push_back({c->name, (20 * h.cwiseAbs().array().log10()).matrix()});
        ph.push_back({c->name, unwrapped_phase_deg(h)});
      }
      page.section("Frequency response" + from);
      page.plot({"Bode magnitude" + from + " (up to the record's Nyquist frequency)", "frequency (rad/s)", "dB", w, mag, true});
      page.plot({"Bode phase" + from, "frequency (rad/s)", "deg", w, ph, true});
    }
  }
  return linear;
}

// Step responses of every model that has one (see below), one plot per input.
void comparison_steps(Page& page, const IdData& d, const std::vector<ModelComparison>& cs,
                      const std::vector<const ModelComparison*>& linear, const Eigen::VectorXcd& poles,
                      const ReportOptions& o) {
  // Step responses: unit steps when every model is linear; otherwise every model's response to a step of each input's
  // RMS level (a nonlinear model's step response depends on the amplitude). A NARX model steps on its sampling grid.
  const bool all_linear = linear.size() == cs.size();
  double horizon = poles_response_horizon(poles, d.duration());
  Eigen::VectorXd t;
  if (d.is_uniform()) {
    const Eigen::Index n = std::min<Eigen::Index>(static_cast<Eigen::Index>(std::ceil(horizon / d.ts())), 20000);
    t = Eigen::VectorXd::LinSpaced(n + 1, 0.0, static_cast<double>(n)) * d.ts();
  } else {
    t = Eigen::VectorXd::LinSpaced(400, 0.0, horizon);
  }
  const auto kt = keep(t.size(), o.max_points);
  for (int i = 0; i < d.nu(); ++i) {
    const Eigen::VectorXd u = d.u().col(i);
    const double level = all_linear ? 1.0 : std::sqrt(u.squaredNorm() / std::max<Eigen::Index>(1, u.size()));
    std::vector<Series> steps;
    std::vector<std::string> failed;
    for (const ModelComparison& c : cs) {
      if (is_linear(c.model) && std::find(linear.begin(), linear.end(), &c) == linear.end()) continue;
      const Eigen::VectorXcd p = model_poles(c.model);
      if ((p.real().array() > 0).any()) {  // its growth would flatten every other curve
        if (i == 0) failed.push_back(c.name + ": not drawn, it is unstable (its step response grows without bound)");
        continue;
      }
      try {
        steps.push_back({c.name, pick(model_step_response(c.model, t, level).col(i), kt)});
      } catch (const InvalidArgument& e) {
        failed.push_back(c.name + ": " + e.what());
      }
    }
    const std::string from = d.nu() > 1 ? " of " + input_name(d, i) : "";
    page.section("Step response" + from);
    if (!steps.empty())
      page.plot({all_linear ? "Unit step response" + from
                            : "Response to a step" + from + " of the input's RMS level (" + fmt(level, 3) + ")",
                 "time (s)", "y", pick(t, kt), steps});
    for (const auto& f : failed) page.text("<span class=\"warn\">" + escape(f) + "</span>");
  }
}

}  // namespace

std::string html_comparison_report(const IdData& d, const std::vector<ModelComparison>& cs, const ReportOptions& o) {
  CTID_REQUIRE(!cs.empty(), "html_comparison_report: no model to compare");
  for (const ModelComparison& c : cs)
    CTID_REQUIRE(c.simulation.y.rows() == d.size() && c.simulation.y.cols() == d.ny() &&
                     static_cast<int>(c.fits.size()) == d.ny(),
                 "html_comparison_report: model {} was not compared on this record (compare_models)", c.name);
  Page page;
  comparison_tables(page, d, cs, o);
  comparison_outputs(page, d, cs, o);
  comparison_tests(page, d, cs, o);
  // Responses of the models (one output: model_frequency_response and the step responses are of the first output).
  if (d.ny() != 1) {
    page.text("The frequency and step responses are compared for single-output records only.");
    return page.render(o.title.empty() ? "ctid compare" : o.title);
  }
  Eigen::VectorXcd poles;
  const std::vector<const ModelComparison*> linear = comparison_bode(page, d, cs, poles);
  comparison_steps(page, d, cs, linear, poles, o);
  if (!linear.empty()) {
    page.section("Poles");
    std::vector<PointSet> sets;
    for (const ModelComparison* c : linear) sets.push_back(points(c->name, model_poles(c->model), 'x'));
    page.scatter({"Poles of the linear models", "real part (1/s)", "imaginary part (rad/s)", sets});
  }
  return page.render(o.title.empty() ? "ctid compare" : o.title);
}

}  // namespace ctid
