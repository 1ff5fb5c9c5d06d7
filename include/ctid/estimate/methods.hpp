// ctid — the registry of estimation methods and their settings.
//
// One entry per estimator function: its name (the C++/Python function name; the CLI's --method, where the CLI
// offers it), a one-line summary and its settings, read from the options tables (estimate/options.hpp). The CLI's
// per-method help, Python's ctid.settings() and the test that compares the CLI, Python and C++ option names all
// read this list.
#pragma once

#include <string>
#include <vector>

#include "ctid/estimate/options.hpp"

namespace ctid {

struct MethodInfo {
  std::string name;                  ///< e.g. "srivc", "srivc_miso", "rls_svf"
  std::string summary;               ///< one line: what it estimates, and from what
  std::vector<std::string> options;  ///< the options structs it takes, e.g. {"FsfOptions", "PhysicalFitOptions"}
  std::vector<OptionInfo> settings;  ///< their settings in table order (names are unique within a method)
  /// The method-specific diagnostics its results can report (names of core/diagnostics.hpp keys; a fit reports
  /// those that apply, e.g. "experiments" only for several records).
  std::vector<std::string> diagnostics;
};

/// Every registered method, in the order of docs/methods.
const std::vector<MethodInfo>& methods();
/// The method named `name`; throws InvalidOptions naming the closest registered name.
const MethodInfo& method_info(const std::string& name);
/// The settings of a method as help text: one line per setting "name  [unit]  default  range  doc", then the
/// diagnostics its results can report.
std::string settings_help(const MethodInfo& m);

}  // namespace ctid
