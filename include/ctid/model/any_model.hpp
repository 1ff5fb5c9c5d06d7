// ctid — one closed set of model types (docs/architecture.md): every front end (CLI, report, Python)
// reaches a model through AnyModel and the free functions below and simulate() (simulate/simulate.hpp),
// never by dispatching on the types itself.
//
// Adding a model type: its own file pair in model/ (the class), one line in the variant below, and the
// per-type overloads the compiler then asks for — model_type_name/describe/inputs (here), simulate_one
// (src/simulate/simulate.cpp) and its JSON form (src/io/json.cpp). docs/architecture.md walks through it.
#pragma once

#include <complex>
#include <string>
#include <variant>
#include <vector>

#include "ctid/core/types.hpp"
#include "ctid/model/fsf.hpp"
#include "ctid/model/greybox.hpp"
#include "ctid/model/miso.hpp"
#include "ctid/model/narx.hpp"
#include "ctid/model/nde.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

/// Every model type ctid fits, simulates and writes. The JSON "type" of each is model_type_name().
using AnyModel = std::variant<TransferFunction, MisoModel, StateSpace, FsfModel, NarxModel, NdeModel, GreyboxModel>;

/// A typed result as a result of any model (the same parameters, fit, summary and diagnostics).
template <class M>
Result<AnyModel> to_any(const Result<M>& r) {
  return {AnyModel(r.model), r.parameters, r.fit, r.summary, r.diagnostics};
}

/// The JSON type name: "transfer_function", "miso", "state_space", "fsf", "narx", "nde", "greybox".
const char* model_type_name(const AnyModel& model);
/// Number of inputs the model is driven by.
int model_inputs(const AnyModel& model);
/// Number of outputs it produces.
int model_outputs(const AnyModel& model);
/// Whether the model is linear (transfer function, MISO, state space, FSF).
bool is_linear(const AnyModel& model);
/// Whether models of the JSON type `type` (model_type_name) are linear: transfer_function, miso, state_space, fsf.
bool is_linear_model_type(const std::string& type);
/// Number of coefficients of the model (the parameter count of fit criteria such as AIC): transfer
/// functions num + den without the leading 1 (summed over MISO channels), all entries of A, B, C, D, FSF
/// parameters, NARX/NDE terms, grey-box parameters (held ones included).
int model_coefficient_count(const AnyModel& model);
/// One-line text of the model with `precision` significant digits.
std::string describe(const AnyModel& model, int precision = 6);
/// Poles of a continuous-time linear model (every channel's for MISO; empty for FSF and nonlinear models).
Eigen::VectorXcd model_poles(const AnyModel& model);
/// "" when no pole of the model lies in the closed right half-plane, else "; unstable poles: 0.5+0j, ..."
/// (with "uI: " per MISO channel) — for messages about diverging simulations.
std::string unstable_poles_note(const AnyModel& model);

}  // namespace ctid
