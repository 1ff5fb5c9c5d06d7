// ctid — the sections every HTML report shares (private to src/io): the summary with the provenance, the data,
// parameters, diagnostics, the validation on the record with residual tests, Bode and time responses, further
// records, poles and zeros. report.cpp puts them together per model type; report_compare.cpp for ctid compare.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ctid/io/report.hpp"
#include "ctid/simulate/simulate.hpp"
#include "ctid/validate/uncertainty.hpp"
#include "report_page.hpp"

namespace ctid::report_detail {

// The rows every report's summary ends with: the provenance (preprocessing, command line, data files, when given),
// the ctid version and commit, and the UTC time the report was made.
void provenance(std::vector<std::vector<std::string>>& rows, const ReportOptions& o);

// The record: its source, size, sampling and channels, and plots of its inputs and outputs.
void data_section(Page& page, const IdData& d, const ReportOptions& o);

// Method-specific numbers (the declared diagnostics the fit reported, with their units and meanings), e.g.
// SRIVC's delay, the LSSVF filter constant, KIA's GLS iterations, and the modal-function diagnostics (condition of
// each order's regression).
void diagnostics(Page& page, const Diagnostics& g);

void parameters(Page& page, const ParameterSet& p, const Eigen::VectorXd* err = nullptr);

// Measured vs simulated output and the residual correlation tests.
void validation(Page& page, const IdData& d, const Eigen::VectorXd& yhat, const ReportOptions& o, int out = 0);

// validation() of every output of the simulation yhat (N x ny).
void validations(Page& page, const IdData& d, const Eigen::MatrixXd& yhat, const ReportOptions& o);

// Bode magnitude and (unwrapped) phase of one or more responses hs = {(label, H(jw))} on the grid w; the
// 95 % magnitude band (lo_mag, hi_mag) goes with a single response.
// The phase of h in degrees, unwrapped along the grid (no jumps of 360).
Eigen::VectorXd unwrapped_phase_deg(const Eigen::VectorXcd& h);

// 95 % bands (2.5 and 97.5 % curves) of one response, each a (lower, upper) pair.
struct Bands {
  const MagnitudeBand* magnitude = nullptr;  ///< of |G(jw)|
  const MagnitudeBand* phase = nullptr;      ///< of the unwrapped phase, degrees
};

void bode(Page& page, const Eigen::VectorXd& w, const std::vector<std::pair<std::string, Eigen::VectorXcd>>& hs,
          const Bands& bands = {});

// Step and impulse responses of a linear model (one curve per input, labelled) over `horizon` seconds; with `tf`, the
// 95 % band of the step response from its parameter covariance (response_band).
void time_responses(Page& page, const AnyModel& model, const std::vector<std::string>& labels, double horizon,
                    const Result<TransferFunction>* tf = nullptr);

double nyquist_or_zero(const IdData& d);

// The model simulated on a record for `purpose` (simulate/simulate.hpp: the library's one rule for the initial
// state), from the report's initial condition when it sets one; a diverging simulation is drawn up to where it
// stops being finite, with the reason.
Eigen::MatrixXd simulated(Page& page, const IdData& d, const Result<AnyModel>& r, SimulationPurpose purpose,
                          std::optional<InitialCondition> initial);

// The further records of ReportOptions::more_records, each in its own section: held-out records (more_records_initial
// set) as validation, the other records of a joint fit as the fit starts a record.
void more_records(Page& page, const Result<AnyModel>& r, const ReportOptions& o);

void require_siso(const IdData& d);

// A nonlinear model's response from rest to a step of the input's RMS level (it depends on the amplitude).
void step_at_input_level(Page& page, const AnyModel& m, const IdData& d, const Eigen::VectorXd& t);

// The poles of a transfer function as an engineer reads them: natural frequency and damping of each complex pair,
// time constant of each real pole, and the zeros, DC gain and delay.
void poles_and_gain(Page& page, const TransferFunction& g);

// The real and imaginary parts of v as a point set.
PointSet points(const std::string& label, const Eigen::VectorXcd& v, char marker, bool light = false);

// Pole-zero map of a transfer-function fit with the poles and zeros of 200 models drawn from its parameter covariance
// (drawn_models, seeded) as a cloud: where the cloud is wide the data pin that pole or zero down poorly. The map shows
// the dynamics: it reaches 5 times the largest pole magnitude (the zeros' when there is no pole); estimated zeros
// beyond it are listed under the map, and the drawn points beyond it counted.
void pole_zero_map(Page& page, const Result<TransferFunction>& r);

template <class M>
void overview(Page& page, const IdData& d, const Result<M>& r, const ReportOptions& o, const std::string& model_text) {
  page.section("Summary");
  page.text("Model: <code>" + escape(model_text) + "</code>");
  std::vector<std::vector<std::string>> rows = {
      {"method", o.method.empty() ? "-" : o.method},
      {"termination", std::string(to_string(r.summary.termination)) +
                          (r.summary.message.empty() ? "" : " (" + r.summary.message + ")")},
      {"usable", r.usable() ? "yes" : "no: " + r.why_not_usable()},
      {"iterations", std::to_string(r.summary.iterations)},
      {"time", fmt(r.summary.seconds, 3) + " s"},
      {"fit (simulation)", r.fit.n_samples > 0 ? fmt(r.fit.fit_percent, 4) + " %" : std::string("not computed")},
      {"MSE / AIC / BIC", fmt(r.fit.mse, 4) + " / " + fmt(r.fit.aic, 5) + " / " + fmt(r.fit.bic, 5)},
      {"condition number", fmt(r.diagnostics.condition_number, 3)}};
  provenance(rows, o);
  page.table({"", ""}, rows);
  if (!o.settings.empty()) {
    std::vector<std::vector<std::string>> s;
    for (const auto& [k, v] : o.settings) s.push_back({k, v});
    page.section("Method settings");
    page.table({"setting", "value"}, s);
  }
  if (!r.diagnostics.choices.empty()) {
    page.section("Automatic choices");
    for (const auto& c : r.diagnostics.choices) page.text(escape(c));
  }
  if (!r.diagnostics.warnings.empty()) {
    page.section("Warnings");
    for (const auto& w : r.diagnostics.warnings) page.text("<span class=\"warn\">" + escape(w) + "</span>");
  }
  data_section(page, d, o);
}

// What every report opens with: the summary, then (where the model describes the system) its simulation on the
// record and on each further record.
template <class M>
void opening(Page& page, const IdData& d, const Result<M>& r, const ReportOptions& o, bool simulate_on_records = true) {
  overview(page, d, r, o, describe(r.model));
  if (!simulate_on_records) return;
  const Result<AnyModel> any{AnyModel(r.model), {}, {}, {}, r.diagnostics};
  validations(page, d, simulated(page, d, any, SimulationPurpose::OwnFit, o.initial), o);
  more_records(page, any, o);
}

}  // namespace ctid::report_detail
