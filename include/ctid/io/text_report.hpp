// ctid — the text report of a fit: one text, written by the library, that `ctid fit` prints and Python's
// result.report() returns, so that the front ends show a result and decide nothing about its text.
#pragma once

#include <string>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/fit.hpp"

namespace ctid {

/// The full text report of a fit on `data` (the first record it was fitted to): the structure a method chose
/// itself (srivc_auto), the method, samples and sampling, the model, parameters with one standard deviation, tau,
/// the fit measures, condition number, termination and time, the automatic choices, notes and warnings; for state
/// space the matrices and each mode (pole, natural frequency, damping, shape, standard deviations); for FSF the
/// compressed step response; for NARX the selected terms with their ERR; for KIA each stage (the NARX model it
/// fitted, the reconstructed equation, the refinement). Lines end in '\n'.
std::string fit_text(const FitOutcome& outcome, const IdData& data);
/// The text report of a fit to frequency-response data: the method, the band, the model, the parameters with one
/// standard deviation, the fit of the complex response and the termination.
std::string fit_text(const FitOutcome& outcome, const FrequencyData& data);

/// The parts of a result as text (Python's repr of each): the parameter table (name, value, one standard deviation
/// or "fixed"), "FitReport(fit F %, nrmse, mse, aic, bic, N samples)", "Summary(termination, iterations, seconds:
/// message)", and the diagnostics (condition number, each method-specific number and vector (its first 8
/// values), the automatic choices, the warnings). No trailing newline.
std::string parameters_text(const ParameterSet& parameters);
std::string fit_report_text(const FitReport& fit);
std::string summary_text(const Summary& summary);
std::string diagnostics_text(const Diagnostics& diagnostics);

/// A brief text report of a result of any model type (what Python's repr of a result shows): `model` (a line naming
/// the model), the termination with its message, iterations, time and usability, the parameters with one standard
/// deviation ("fixed" for held ones), the fit with its MSE, AIC and sample count, and the warnings.
std::string brief_text(const std::string& model, const ParameterSet& parameters, const FitReport& fit,
                       const Summary& summary, const Diagnostics& diagnostics, bool usable);
template <class M>
std::string brief_text(const Result<M>& r, const std::string& model) {
  return brief_text(model, r.parameters, r.fit, r.summary, r.diagnostics, r.usable());
}

}  // namespace ctid
