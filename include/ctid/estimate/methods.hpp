// ctid — the registry of estimation methods: their settings, what they take and how they run.
//
// One entry per estimator function: its name (the C++/Python function name and the CLI's --method), a one-line
// summary, its settings read from the options tables (estimate/options.hpp), its capabilities and, for the methods
// that fit records, how it runs (fit(), estimate/fit.hpp). The CLI's method list, flag checks and per-method help,
// Python's ctid.methods()/ctid.settings()/ctid.fit(), ctid batch and ctid.batch.fit_many all read this list.
// Adding an estimator: its function, its options table, and one entry in src/estimate/methods.cpp (or, outside
// the library, one CTID_REGISTER_METHOD line in its own source file).
#pragma once

#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "ctid/estimate/fit.hpp"
#include "ctid/estimate/options.hpp"

namespace ctid {

/// What a method takes and gives. The front ends check a request against it before anything runs, and list it.
struct MethodCapabilities {
  bool records = false;          ///< fits time-domain records (ctid fit, ctid.fit); false: a stage or a tool
  bool several_records = false;  ///< several records are several experiments, fitted jointly
  bool frequency_data = false;   ///< also fits frequency-response data
  bool several_inputs = false;   ///< more than one input
  bool several_outputs = false;  ///< more than one output
  bool orders = false;           ///< takes transfer-function orders (--nb/--nf/--nk; Python nb, nf, nk)
  bool needs_orders = false;     ///< ... and needs them
  bool nx = false;               ///< takes a state dimension (--nx)
  bool initial_model = false;    ///< takes a starting state-space model (--initial)
  bool greybox_model = false;    ///< needs a grey-box model (--model FILE)
  bool physical_model = false;   ///< needs a physical model (--model EXPRESSION, --param)
  bool references = false;       ///< takes a reference per record (closed loop, with a known controller)
  bool narx_model = false;       ///< takes a NARX model to start from (--narx)
  std::vector<std::string> model_types;  ///< model_type_name() of its results, e.g. {"transfer_function", "miso"}
  /// What is removed from the records before the fit when the user does not say (ctid fit's --detrend): "none",
  /// or "mean" for a method that takes no offset into its model and chooses everything itself (srivc_auto).
  std::string default_detrend = "none";
};

struct MethodInfo {
  std::string name;                  ///< e.g. "srivc", "srivc_miso", "rls_svf"
  std::string summary;               ///< one line: what it estimates, and from what
  std::vector<std::string> options;  ///< the options structs it takes, e.g. {"FsfOptions", "PhysicalFitOptions"}
  std::vector<OptionInfo> settings;  ///< their settings in table order (names are unique within a method)
  /// The method-specific diagnostics its results can report (names of core/diagnostics.hpp keys; a fit reports
  /// those that apply, e.g. "experiments" only for several records).
  std::vector<std::string> diagnostics;
  MethodCapabilities capabilities;
  /// For an entry that does not run on its own: how it is reached (e.g. "srivc on records with several inputs"; a
  /// command, "ctid poles", for the tools of their own command).
  std::string reached_by;
  /// Entries whose settings this method's run takes in some cases (srivc: srivc_miso with several inputs,
  /// srivc_closed_loop with references; kia: narx when it fits its NARX model itself): its help lists them too.
  std::vector<std::string> variants;
  /// Other spellings accepted for the name (e.g. "srivc-auto"); results always record `name`.
  std::vector<std::string> aliases;
  /// Runs the method (capabilities.records); empty for stages and tools. Called by fit(), which has checked the
  /// request against the capabilities.
  std::function<FitOutcome(const FitRequest&)> run;
};

/// Every registered method: the library's in the order of docs/methods, then those added by register_method.
/// (A deque: adding a method keeps every reference to an entry valid.)
const std::deque<MethodInfo>& methods();

/// Adds an estimator from outside the library (an experiment, a plugin, the worked example of
/// docs/architecture.md) to the registry, after the library's methods: from then on fit(), the CLI's --method,
/// its help, ctid batch and Python's ctid.fit reach it by its name. Call it before methods run on several threads;
/// CTID_REGISTER_METHOD calls it from a static initialiser of the method's source file. Throws InvalidArgument when
/// the name or an alias is taken, when a fit of records has no run, or for an undeclared diagnostic.
bool register_method(MethodInfo m);

/// The registry entry of an estimator of records whose settings are the tables of its options structs `O...`
/// (estimate/options.hpp): its name, summary, capabilities (records is set) and run.
template <class... O>
MethodInfo fit_method(std::string name, std::string summary, MethodCapabilities capabilities,
                      std::function<FitOutcome(const FitRequest&)> run) {
  MethodInfo m;
  m.name = std::move(name);
  m.summary = std::move(summary);
  (
      [&] {
        for (auto& i : option_table<O>().info()) m.settings.push_back(std::move(i));
      }(),
      ...);
  capabilities.records = true;
  m.capabilities = std::move(capabilities);
  m.run = std::move(run);
  return m;
}

/// Registers a method at static initialisation: CTID_REGISTER_METHOD(fit_method<MyOptions>(...)); in its source file.
#define CTID_REGISTER_METHOD_CAT2(a, b) a##b
#define CTID_REGISTER_METHOD_CAT(a, b) CTID_REGISTER_METHOD_CAT2(a, b)
#define CTID_REGISTER_METHOD(...) \
  [[maybe_unused]] static const bool CTID_REGISTER_METHOD_CAT(ctid_registered_, __LINE__) = ::ctid::register_method(__VA_ARGS__)
/// The method named `name` or one of its aliases; throws InvalidOptions naming the closest registered name.
const MethodInfo& method_info(const std::string& name);
/// The methods that fit records (capabilities.records), in registry order: ctid fit's --method choices.
std::vector<std::string> fit_method_names();
/// The fits (capabilities.records) for which `has` holds, in registry order, as "a, b or c" (for messages and help).
std::string fits_where(const std::function<bool(const MethodInfo&)>& has);
/// The settings of a method as help text: one line per setting "name  [unit]  default  range  doc", then the
/// diagnostics its results can report.
std::string settings_help(const MethodInfo& m);

}  // namespace ctid
