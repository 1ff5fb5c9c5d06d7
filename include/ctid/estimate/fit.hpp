// ctid — one entry point for every fit of records: fit(method, request) runs a registered method
// (estimate/methods.hpp) on time-domain records or frequency-response data with a structure and settings, and
// returns its result as a result of any model, with the registry name of the method that ran and every setting it
// used. The command line (`ctid fit`, `ctid batch`), Python (`ctid.fit`, `ctid.batch.fit_many`) and the tests
// that walk the registry all call it; none of them dispatches on method names itself.
#pragma once

#include <algorithm>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "ctid/core/error.hpp"
#include "ctid/core/names.hpp"
#include "ctid/core/types.hpp"
#include "ctid/data/frequency_data.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/options.hpp"
#include "ctid/estimate/orders.hpp"
#include "ctid/estimate/fsf/physical.hpp"
#include "ctid/model/any_model.hpp"

namespace ctid {

/// A setting given by name: as text (the CLI's --set NAME=VALUE, parsed by the setting's table) or typed (Python
/// keywords, converted by the binding).
using SettingValue = std::variant<std::string, OptionValue>;
/// Settings in the order given; a name may be NAME.KEY for the named settings (fixed.a1=2).
using SettingList = std::vector<std::pair<std::string, SettingValue>>;
/// Every setting of the options a fit used, as NAME/VALUE text (the report's "settings"; defaults included).
using SettingsText = std::vector<std::pair<std::string, std::string>>;

/// A physical-parameter model: a transfer-function expression in s with named parameters (estimate/fsf/physical.hpp)
/// and the route of the fit.
struct PhysicalStructure {
  std::string expression;                     ///< e.g. "k1/(s^2 - k2)"
  std::vector<PhysicalParameter> parameters;  ///< every parameter of the expression, with its initial value
  std::string route = "fsf";                  ///< fsf (the FSF step response), frequency (its frequency response), raw
};

/// What a fit is asked for besides its settings. Each field belongs to the methods whose capabilities name it
/// (MethodCapabilities); fit() refuses a field given to a method that does not take it, naming both.
struct FitStructure {
  /// Transfer-function orders: one entry for every input, or one per input; empty: not given (a method that needs
  /// them refuses, srivc_auto chooses them).
  std::vector<TfOrders> orders;
  std::optional<StateSpace> initial;           ///< ssest: the starting model (instead of the subspace start)
  std::optional<GreyboxModel> greybox;         ///< greybox: the model
  std::optional<PhysicalStructure> physical;   ///< physical: the expression, its parameters and the route
  /// srivc: one reference signal per record (on the record's sample times): the fit is closed loop
  /// (srivc_closed_loop, whose settings hold the known controller and the reference's intersample behaviour).
  std::vector<Eigen::VectorXd> references;
  std::optional<NarxModel> narx;  ///< kia: the NARX model to reconstruct from (otherwise one is fitted first)
};

/// One fit: the data, the structure and the settings.
struct FitRequest {
  /// Time-domain records of one system; several are several experiments fitted jointly (one parameter set).
  std::vector<IdData> records;
  std::optional<FrequencyData> frequency;  ///< frequency-response data, instead of records
  FitStructure structure;
  SettingList settings;
};

/// What fit() returns.
struct FitOutcome {
  Result<AnyModel> result;
  /// The registry name of the method that ran: the one asked for, or the variant its data called for (srivc_miso
  /// for srivc with several inputs, srivc_closed_loop with a controller, tf_from_frequency for tfest or oe on
  /// frequency data).
  std::string method;
  SettingsText settings;  ///< every setting of the options it used, defaults included
  /// Results of the stages a method ran on the way, by name (kia: "narx" when it fitted one, "reconstructed",
  /// "refined"); empty for single-stage methods.
  std::vector<std::pair<std::string, Result<AnyModel>>> stages;
};

/// The method `ctid fit` and `ctid.fit` run when none is named: on frequency data tfest; on records srivc when
/// orders are given, srivc_auto otherwise.
std::string default_method(const FitStructure& structure, bool frequency_data = false);

/// Runs the registered method `method` (a registry name, or an accepted alias such as "srivc-auto") on the request.
/// Throws UnknownSetting for a setting the method does not have, InvalidOptions for an unknown method, a setting's
/// bad value or a structure field the method does not take, InvalidArgument for data the method cannot fit (several
/// records, inputs or outputs, frequency data: each names the method and what it takes). A fit that ran but cannot
/// be trusted returns normally with result.usable() false.
FitOutcome fit(const std::string& method, const FitRequest& request);

// For the run of a method (estimate/methods.hpp: MethodInfo::run): its settings applied to its options structs, the
// settings it used as text, and the outcome.

/// Applies `settings` to the options structs `o...` through their tables: each name goes to the first struct whose
/// table has it. `own` names settings the run handles itself: they are returned, not applied. An unknown name throws
/// UnknownSetting naming the closest setting of the method; a bad value InvalidOptions.
template <class... O>
SettingList apply_settings(const std::string& method, const SettingList& settings, const std::vector<std::string>& own,
                           O&... o) {
  SettingList rest;
  for (const auto& [name, value] : settings) {
    if (std::find(own.begin(), own.end(), name) != own.end()) {
      rest.emplace_back(name, value);
      continue;
    }
    bool done = false;
    (
        [&, &name = name, &value = value] {
          if (done || !option_table<O>().find(name)) return;
          if (const auto* text = std::get_if<std::string>(&value))
            option_table<O>().set(o, name, *text);
          else
            option_table<O>().set_value(o, name, std::get<OptionValue>(value));
          done = true;
        }(),
        ...);
    if (done) continue;
    std::vector<std::string> names = own;
    (
        [&] {
          for (const auto& n : option_table<O>().names()) names.push_back(n);
        }(),
        ...);
    const std::string near = closest_name(name, names);
    throw UnknownSetting(method + ": '" + name + "' is not a setting" +
                             (near.empty() ? std::string() : "; did you mean '" + near + "'?"),
                         method, name, near);
  }
  return rest;
}

/// A setting's value as a list of numbers: text "1,2,3" (parsed as the tables parse lists), or typed reals or one
/// real. Throws InvalidOptions naming `method` and `name` otherwise (a method's own settings, apply_settings' `own`).
std::vector<double> setting_reals(const std::string& method, const std::string& name, const SettingValue& value);

/// Every setting of the options structs `o...` as NAME/VALUE text, defaults included (FitOutcome::settings).
template <class... O>
SettingsText settings_text(const O&... o) {
  SettingsText s;
  (
      [&] {
        for (auto& p : option_table<O>().settings(o)) s.push_back(std::move(p));
      }(),
      ...);
  return s;
}

/// The outcome of a run: the result as Result<AnyModel>, the registry name of the method that ran, its settings.
template <class M>
FitOutcome fit_outcome(const Result<M>& r, std::string method, SettingsText settings) {
  FitOutcome out;
  out.result = to_any(r);
  out.method = std::move(method);
  out.settings = std::move(settings);
  return out;
}

}  // namespace ctid
