// ctid — the text of the library's tools (not fits): what `ctid poles`, `ctid response` and `ctid compare` print
// and Python's repr of their results shows, written once here so that the front ends only show it.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/modal/modal.hpp"
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

}  // namespace ctid
