// ctid — the registry of estimation methods (estimate/methods.hpp), built from the options tables.
#include "ctid/estimate/methods.hpp"

#include <algorithm>

#include "ctid/core/check.hpp"
#include "ctid/core/error.hpp"
#include "ctid/estimate/frequency.hpp"
#include "ctid/estimate/frols.hpp"
#include "ctid/estimate/fsf.hpp"
#include "ctid/estimate/kia.hpp"
#include "ctid/estimate/lssvf.hpp"
#include "ctid/estimate/modal.hpp"
#include "ctid/estimate/nde_oe.hpp"
#include "ctid/estimate/oe.hpp"
#include "ctid/estimate/physical.hpp"
#include "ctid/estimate/rls_svf.hpp"
#include "ctid/estimate/srivc.hpp"

namespace ctid {

namespace {
template <class... O>
MethodInfo entry(std::string name, std::string summary, std::vector<std::string> structs) {
  MethodInfo m{std::move(name), std::move(summary), std::move(structs), {}};
  (
      [&] {
        for (auto& i : option_table<O>().info()) {
          CTID_ASSERT(std::none_of(m.settings.begin(), m.settings.end(), [&](const OptionInfo& s) { return s.name == i.name; }));
          m.settings.push_back(std::move(i));
        }
      }(),
      ...);
  return m;
}
}  // namespace

const std::vector<MethodInfo>& methods() {
  static const std::vector<MethodInfo> all = {
      entry<LssvfOptions>("lssvf", "Johansson (1986) least squares on state-variable-filtered signals", {"LssvfOptions"}),
      entry<IvsvfOptions>("ivsvf", "Johansson's regression with instrumental variables from an auxiliary model",
                          {"IvsvfOptions"}),
      entry<RlsSvfOptions>("rls_svf", "recursive least squares on state-variable-filtered signals (RJ 59-60)",
                           {"RlsSvfOptions"}),
      entry<SrivcOptions>("srivc", "simplified refined instrumental variables, one input", {"SrivcOptions"}),
      entry<SrivcMisoOptions>("srivc_miso", "SRIVC with several inputs (one transfer function per input)",
                              {"SrivcMisoOptions"}),
      entry<ClosedLoopOptions>("srivc_closed_loop", "closed-loop SRIVC with a known controller (instruments from the reference)",
                               {"ClosedLoopOptions"}),
      entry<OeOptions>("oe", "continuous-time output error (Levenberg-Marquardt)", {"OeOptions"}),
      entry<OeOptions>("tfest", "SRIVC start, then output-error refinement", {"OeOptions"}),
      entry<FrequencyFitOptions>("tf_from_frequency", "transfer function from frequency-response data (SK, then OE)",
                                 {"FrequencyFitOptions"}),
      entry<FsfOptions>("fsf", "Gawthrop & Wang (2005) frequency-sampling-filter compression", {"FsfOptions"}),
      entry<FsfOptions, PhysicalFitOptions>("physical",
                                            "physical parameters of a transfer-function expression (via FSF or raw data)",
                                            {"FsfOptions", "PhysicalFitOptions"}),
      entry<ModalOptions>("modal",
                          "El-Shafey (1987) modal functions: transfer function from a generated or piecewise-constant input",
                          {"ModalOptions"}),
      entry<ModalResponseOptions, ModalOptions>(
          "modal_response",
          "El-Shafey (1987) step, impulse or frequency response from a piecewise-constant or periodic input (ctid response)",
          {"ModalResponseOptions", "ModalOptions"}),
      entry<PolesOptions>("poles", "El-Shafey (1987) data-matrix poles of a free response beside Prony's (ctid poles)",
                          {"PolesOptions"}),
      entry<NarxOptions>("narx", "Billings & Li NARX workflow: candidates from degree and lags, FROLS with a criterion, "
                                 "NARMAX with noise_terms > 0",
                         {"NarxOptions"}),
      entry<FrolsOptions>("frols", "FROLS/ERR selection among given NARX candidate terms", {"FrolsOptions"}),
      entry<NarmaxOptions>("narmax", "NARMAX: FROLS with noise terms by extended least squares", {"NarmaxOptions"}),
      entry<KiaOptions>("kia", "Kernel Invariance Algorithm: NDE from a NARX model (stages, stacking, OE refinement)",
                        {"KiaOptions"}),
      entry<KiaLinearOptions>("kia_linear", "KIA linear stage", {"KiaLinearOptions"}),
      entry<KiaQuadraticOptions>("kia_quadratic", "KIA quadratic stage", {"KiaQuadraticOptions"}),
      entry<KiaCubicOptions>("kia_cubic", "KIA cubic stage", {"KiaCubicOptions"}),
      entry<NdeOeOptions>("nde_oe", "output-error refinement of a nonlinear differential equation", {"NdeOeOptions"}),
  };
  return all;
}

const MethodInfo& method_info(const std::string& name) {
  for (const auto& m : methods())
    if (m.name == name) return m;
  std::vector<std::string> names;
  for (const auto& m : methods()) names.push_back(m.name);
  const std::string near = closest_name(name, names);
  std::string all;
  for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
  throw InvalidOptions(detail::format("'{}' is not a method{} (methods: {})", name,
                                      near.empty() ? std::string() : "; did you mean '" + near + "'?", all));
}

std::string settings_help(const MethodInfo& m) {
  std::size_t w = 4;
  for (const auto& s : m.settings) w = std::max(w, s.name.size());
  std::string out = "settings of " + m.name + " (--set NAME=VALUE; Python: keyword arguments):\n";
  for (const auto& s : m.settings) {
    std::string line = "  " + s.name + std::string(w - s.name.size() + 2, ' ');
    const std::string d = s.default_value.empty() ? std::string("none") : s.default_value;
    line += "default " + d;
    if (!s.unit.empty() && d != "none") line += " " + s.unit;
    if (!s.unit.empty() && d == "none") line += " (" + s.unit + ")";
    if (!s.range.empty()) line += "; " + s.range;
    line += ". " + s.doc + "\n";
    out += line;
  }
  return out;
}

}  // namespace ctid
