// ctid — the text and JSON of the library's tools (not fits): what `ctid poles`, `ctid response`, `ctid compare`
// and `ctid validate` print and write, and Python's repr of their results shows, written once here so that the
// front ends only show it (text: io/tool_text.cpp; JSON: io/tool_json.cpp, apart from io/json.cpp so that the
// readers link without the validation layer).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/modal/modal.hpp"
#include "ctid/io/json.hpp"
#include "ctid/model/any_model.hpp"
#include "ctid/validate/compare.hpp"

namespace ctid {

/// The two pole estimates of a response (compare_poles): the automatic choices, El-Shafey's data-matrix estimate
/// (characteristic polynomial, poles, condition number, warnings; with a generator also the polynomial before
/// deflation), then Prony's or why it was not computed. Lines end in '\n'.
std::string poles_text(const PolesComparison& comparison);

/// A nonparametric modal response (modal_response): the output modal parameters p_0 with their shifts, windows
/// and condition number, then the response (about twenty points of a step or impulse response; every harmonic of
/// a frequency response with its magnitude and phase). Lines end in '\n'.
std::string modal_response_text(const ModalResponse& response);

/// A nonparametric modal response as named columns: t, step | t, impulse | w (rad/s), re, im, mag, phase_deg —
/// the table `ctid response` writes to CSV and JSON.
std::pair<std::vector<std::string>, Eigen::MatrixXd> modal_response_table(const ModalResponse& response);

/// Models compared on one record (compare_models): one row per model (name, type, initial condition, fit per
/// output — "diverges" where the simulation left the finite numbers —, mean NRMSE, total AIC, the residual tests
/// passed or how many failed), then the best by mean fit. Lines end in '\n'.
std::string comparison_text(const IdData& data, const std::vector<ModelComparison>& comparisons);

/// A model's outputs scored on a record (score_outputs): per output — headed "output NAME:" when there are several —
/// the fit with NRMSE, MSE and the sample count, the residual whiteness test and each input's independence test
/// with their verdicts (`ctid validate`). Lines end in '\n'.
std::string validation_text(const IdData& data, const std::vector<OutputScore>& scores);

/// The model of r simulated on a held-out record `d` called `name`, from the initial state of the library's rule for
/// validation (simulate_options(r, SimulationPurpose::Validation)): "validation on NAME (N samples, initial state:
/// ...): fit X %" (per output with several), or the simulation's problem when it left the finite numbers. Starts
/// with an empty line and ends in '\n'. InvalidArgument for data that do not fit the model.
std::string held_out_text(const Result<AnyModel>& r, const std::string& name, const IdData& d);

/// Models compared on one record (ctid compare --json): {"ctid_version", "data": data_name, "n_samples", "best": the
/// name of the best by mean fit, "models": [{"name", "type", "initial", "outputs": [{"output", "fit_percent",
/// "nrmse", "mse", "aic", and where the tests ran "whiteness_lags_outside", "independence_lags_outside": [per
/// input]}], "problem": "" or why the simulation stopped}]} (non-finite numbers as null).
std::string comparison_to_json(const std::string& data_name, const IdData& data,
                               const std::vector<ModelComparison>& comparisons, int indent = 2);
/// A model validated on records (ctid validate --json): the first record's numbers at the top level, then
/// "ctid_version", "model" (the result's model object), "initial" (the condition simulated from) and "experiments"
/// (every record: {"data": its name, then the numbers}). The numbers of a record with one output: "fit"
/// {"fit_percent", "nrmse", "mse", "n_samples"}, "residual_autocorrelation" and "input_residual_crosscorrelation"
/// (per input) as {"lags", "values", "bound_99", "n_outside", "passed"}; with several outputs: "outputs", a list of
/// {"output": its name, then those numbers}.
std::string validation_to_json(const ResultFile& file, InitialCondition initial,
                               const std::vector<std::pair<std::string, std::vector<OutputScore>>>& records,
                               int indent = 2);
}  // namespace ctid
