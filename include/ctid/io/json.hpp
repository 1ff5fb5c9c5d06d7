// ctid — JSON model and result files (docs/guide.md, "Result files").
//
// Result envelope: {"ctid_version", "method", "model": {...}, "parameters": [{name, value,
// std, fixed}], "covariance": [[..]], "fit": {...}, "summary": {...}, "diagnostics": {...}}.
// Models: {"type": "transfer_function", "num": [...], "den": [...], "io_delay": s} or
// {"type": "state_space", "A": [[..]], "B": .., "C": .., "D": ..} (row-major nested arrays) or
// {"type": "miso", "channels": [transfer_function, ...]} (y = sum of the channels); FSF, NARX and NDE
// models below.
// NaN values are written as null and read back as NaN.
#pragma once

#include <string>
#include <variant>

#include "ctid/core/types.hpp"
#include "ctid/estimate/modal/modal.hpp"
#include "ctid/estimate/transfer_function/order_selection.hpp"
#include "ctid/io/provenance.hpp"
#include "ctid/model/any_model.hpp"
#include "ctid/model/fsf.hpp"
#include "ctid/model/miso.hpp"
#include "ctid/model/narx.hpp"
#include "ctid/model/nde.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

using LinearModel = std::variant<TransferFunction, StateSpace, MisoModel>;

/// The library version string ("0.1.0").
const char* version();

std::string model_to_json(const LinearModel& model, int indent = 2);
/// Accepts a bare model object or a result envelope with a "model" member. Throws
/// FileError naming `source` and the member that is missing or malformed.
LinearModel parse_model_json(const std::string& text, const std::string& source = "<json>");
LinearModel read_model_json(const std::string& path);
void write_model_json(const std::string& path, const LinearModel& model);

/// A result written by result_to_json read back (model, parameters, covariance, fit, summary, diagnostics).
/// Throws FileError naming `source` when the model is of another type or a member is malformed.
Result<TransferFunction> parse_result_json(const std::string& text, const std::string& source = "<json>");
/// The same for a multi-input result (model type "miso").
Result<MisoModel> parse_miso_result_json(const std::string& text, const std::string& source = "<json>");
/// Order selection (ctid order --json): {"type": "order_selection", "rank_by": "yic", "interrupted": false,
/// "candidates": [{"nb", "nf", "nk", "yic", "rt2", "aic", "bic", "fit_percent", "usable", "termination"}, ...]} in
/// rank order (non-finite numbers as null).
std::string order_selection_to_json(const std::vector<OrderCandidate>& candidates, OrderCriterion rank_by,
                                    bool interrupted, int indent = 2);
/// Poles from a free response (ctid poles --json): {"type": "poles", "order": n, "ts": s, "data_matrix": E,
/// "prony": E or null, "prony_error": "" or why Prony was not computed, "shifts": [s, the data matrix's],
/// "choices": [automatic choices]}, E = {"poles": [{"re", "im"}, ...], "characteristic": [descending coefficients],
/// "augmented": [...], "condition": c, "warnings": [...]}.
std::string poles_to_json(const PolesComparison& comparison, int order, double ts, int indent = 2);
/// A computed table (ctid response --json, ctid gfrf --json): {"type": type, <each field: name -> text, or a number
/// when the text is one>, "columns": {name: [values, non-finite as null], ...}} with the columns of `values` named
/// by `names` in order. Throws InvalidArgument when names and columns differ in number.
std::string table_to_json(const std::string& type, const std::vector<std::pair<std::string, std::string>>& fields,
                          const std::vector<std::string>& names, const Eigen::MatrixXd& values, int indent = 2);
/// Any result ctid writes, or a bare model object: Result<AnyModel> in the envelope above, model "type"
/// one of model_type_name()'s — the one writer and reader of result files. Model forms besides the linear ones:
/// FSF {"type": "fsf", "delta", "N", "n", "shift", "theta": [...], "covariance": [[...]] when known} (real parameterisation); NARX/NARMAX
/// {"type": "narx", "ts": s, "terms": [{"name": "y(k-1)*u(k-2)", "value": c}, ...]}; NDE {"type": "nde", "terms":
/// [{"name": "D^2y", "value": 1e-4}, ...]}, written normalised so that the coefficient of y is +1 when the model
/// has a y term; grey-box models as parse_greybox_json reads them. write_result_json writes atomically (temporary file, then rename); throws FileError.
/// With `provenance` the envelope has a "provenance" member: {"command_line", "version", "commit", "data": [{"path",
/// "content_hash", "rows"}], "preprocessing": [...]} (io/provenance.hpp); readers ignore it.
std::string result_to_json(const Result<AnyModel>& result, const std::string& method, int indent = 2,
                           const Provenance* provenance = nullptr);
void write_result_json(const std::string& path, const Result<AnyModel>& result, const std::string& method,
                       const Provenance* provenance = nullptr);
/// Shorthands for a typed result (Result<TransferFunction>, Result<NarxModel>, ...): the same file.
template <class M>
std::string result_to_json(const Result<M>& result, const std::string& method, int indent = 2) {
  return result_to_json(to_any(result), method, indent);
}
template <class M>
void write_result_json(const std::string& path, const Result<M>& result, const std::string& method) {
  write_result_json(path, to_any(result), method);
}
/// A bare model of any type as result_to_json writes its "model" member (read back by parse_result_file). exact:
/// every coefficient as it is — an NDE is otherwise normalised so that y's coefficient is +1 — so that the text reads
/// back to the same model bit for bit (finite doubles are written with the shortest digits that round-trip; Python's
/// pickle and copy use this form).
std::string any_model_to_json(const AnyModel& model, bool exact = false, int indent = 2);
/// A file read back: the result (a bare model gets its term coefficients as parameters, without
/// uncertainty, and no fit), the method that wrote it ("" for a bare model) and whether it was bare.
struct ResultFile {
  Result<AnyModel> result;
  std::string method;
  bool bare = false;
};
/// Recognises the model type from the file. Throws FileError naming `source` and what is malformed.
ResultFile parse_result_file(const std::string& text, const std::string& source = "<json>");
ResultFile read_result_file(const std::string& path);
/// Read a NARX (or NDE) model from a bare model object or a result envelope. Throws FileError naming the
/// file and the problem (wrong type, a malformed or unknown term name with its position, a missing member).
NarxModel read_narx_json(const std::string& path);
NdeModel read_nde_json(const std::string& path);
NarxModel parse_narx_json(const std::string& text, const std::string& source = "<json>");
/// A grey-box model file (model/greybox.hpp), bare or in a result envelope:
///   {"type": "greybox", "inputs": [names], "states": [names], "outputs": {name: expression, ..},
///    "parameters": {name: value | {"value", "lower", "upper", "fixed"}, ..}, "equations": {state: dx/dt, ..},
///    "initial": {state: number | expression of parameters | "estimate" | {"estimate": true, "value": start}, ..}}
/// Members keep their order (outputs and parameters in the order declared); a state without "initial" starts at 0.
/// Throws FileError naming `source` and the problem (a missing equation, an unknown member, a parse error with the
/// expression, its column and the closest name).
GreyboxModel parse_greybox_json(const std::string& text, const std::string& source = "<json>");
GreyboxModel read_greybox_json(const std::string& path);
std::string greybox_to_json(const GreyboxModel& model, int indent = 2);
NdeModel parse_nde_json(const std::string& text, const std::string& source = "<json>");

}  // namespace ctid
