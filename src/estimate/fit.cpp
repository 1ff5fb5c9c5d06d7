// ctid — fit(method, request): the registry's methods run on a request (estimate/fit.hpp). Each run function
// applies the request's settings to the method's options through their tables, calls the estimator on one record
// (its single-record overload, as C++ and Python users call it) or on several, and returns the result with the
// registry name of the method that ran and the settings it used. The capabilities are checked in fit(), once.
#include "ctid/estimate/fit.hpp"

#include <algorithm>
#include <cmath>

#include "ctid/core/check.hpp"
#include "ctid/core/error.hpp"
#include "ctid/core/names.hpp"
#include "ctid/estimate/transfer_function/frequency.hpp"
#include "ctid/estimate/nonlinear/frols.hpp"
#include "ctid/estimate/fsf/fsf.hpp"
#include "ctid/estimate/greybox/greybox.hpp"
#include "ctid/estimate/nonlinear/kia.hpp"
#include "ctid/estimate/svf/lssvf.hpp"
#include "ctid/estimate/methods.hpp"
#include "ctid/estimate/modal/modal.hpp"
#include "ctid/estimate/transfer_function/oe.hpp"
#include "ctid/estimate/svf/rls_svf.hpp"
#include "ctid/estimate/transfer_function/srivc.hpp"
#include "ctid/estimate/transfer_function/srivc_auto.hpp"
#include "ctid/estimate/state_space/ssest.hpp"
#include "ctid/estimate/state_space/subspace.hpp"
#include "fit_runs.hpp"

namespace ctid {

std::vector<double> setting_reals(const std::string& method, const std::string& name, const SettingValue& v) {
  if (const auto* text = std::get_if<std::string>(&v)) return options_detail::parse_reals(method, name, *text);
  if (const auto* x = std::get_if<std::vector<double>>(&std::get<OptionValue>(v))) return *x;
  if (const auto* x = std::get_if<double>(&std::get<OptionValue>(v))) return {*x};
  throw InvalidOptions(detail::format("{}: {} takes a list of numbers", method, name));
}

namespace fit_detail {

// One input: the single entry of the orders.
TfOrders siso_orders(const FitRequest& r, const std::string& method) {
  CTID_REQUIRE_OPTION(r.structure.orders.size() == 1, "{}: one set of orders (nb, nf, nk) for its one input (got {})",
                      method, r.structure.orders.size());
  return r.structure.orders.front();
}

// A single-input transfer-function estimator on one record (its single-record overload) or several.
template <class O, class One, class Many>
FitOutcome tf_records(const FitRequest& r, const std::string& method, One one, Many many) {
  O o;
  apply_settings(method, r.settings, {}, o);
  const TfOrders orders = siso_orders(r, method);
  const auto res = r.records.size() == 1 ? one(r.records.front(), orders, o) : many(r.records, orders, o);
  return fit_outcome(res, method, settings_text(o));
}

std::string text_of(const std::vector<double>& v) { return options_detail::format_reals(v); }

}  // namespace fit_detail

namespace fit_runs {
using namespace fit_detail;

FitOutcome lssvf(const FitRequest& r) {
  if (r.frequency) {
    LssvfOptions o;
    apply_settings("lssvf", r.settings, {}, o);
    return fit_outcome(ctid::lssvf(*r.frequency, siso_orders(r, "lssvf"), o), "lssvf", settings_text(o));
  }
  using F1 = Result<TransferFunction> (*)(const IdData&, const TfOrders&, const LssvfOptions&);
  using FN = Result<TransferFunction> (*)(const std::vector<IdData>&, const TfOrders&, const LssvfOptions&);
  return tf_records<LssvfOptions>(r, "lssvf", static_cast<F1>(&ctid::lssvf), static_cast<FN>(&ctid::lssvf));
}

FitOutcome ivsvf(const FitRequest& r) {
  using F1 = Result<TransferFunction> (*)(const IdData&, const TfOrders&, const IvsvfOptions&);
  using FN = Result<TransferFunction> (*)(const std::vector<IdData>&, const TfOrders&, const IvsvfOptions&);
  return tf_records<IvsvfOptions>(r, "ivsvf", static_cast<F1>(&ctid::ivsvf), static_cast<FN>(&ctid::ivsvf));
}

FitOutcome rls_svf(const FitRequest& r) {
  using F1 = Result<TransferFunction> (*)(const IdData&, const TfOrders&, const RlsSvfOptions&);
  using FN = Result<TransferFunction> (*)(const std::vector<IdData>&, const TfOrders&, const RlsSvfOptions&);
  return tf_records<RlsSvfOptions>(r, "rls_svf", static_cast<F1>(&ctid::rls_svf), static_cast<FN>(&ctid::rls_svf));
}

FitOutcome srivc(const FitRequest& r) {
  const std::vector<IdData>& ds = r.records;
  if (!r.structure.references.empty()) {  // closed loop: the controller and the reference's hold are settings
    ClosedLoopOptions o;
    apply_settings("srivc_closed_loop", r.settings, {}, o);
    const Result<TransferFunction> res =
        srivc_closed_loop(ds, r.structure.references, siso_orders(r, "srivc_closed_loop"), o);
    return fit_outcome(res, "srivc_closed_loop", settings_text(o));
  }
  const int nu = ds.front().nu();
  if (nu > 1) {
    const auto& given = r.structure.orders;
    CTID_REQUIRE_OPTION(given.size() == 1 || static_cast<int>(given.size()) == nu,
                        "srivc_miso: {} sets of orders for {} inputs (give one for every input, or one per input)",
                        given.size(), nu);
    std::vector<TfOrders> orders;
    for (int i = 0; i < nu; ++i) orders.push_back(given.size() == 1 ? given[0] : given[static_cast<size_t>(i)]);
    SrivcMisoOptions o;
    apply_settings("srivc_miso", r.settings, {}, o);
    return fit_outcome(srivc_miso(ds, orders, o), "srivc_miso", settings_text(o));
  }
  using F1 = Result<TransferFunction> (*)(const IdData&, const TfOrders&, const SrivcOptions&);
  using FN = Result<TransferFunction> (*)(const std::vector<IdData>&, const TfOrders&, const SrivcOptions&);
  return tf_records<SrivcOptions>(r, "srivc", static_cast<F1>(&ctid::srivc), static_cast<FN>(&ctid::srivc));
}

FitOutcome srivc_auto(const FitRequest& r) {
  SrivcAutoOptions o;
  apply_settings("srivc_auto", r.settings, {}, o);
  const IdData& d = r.records.front();
  if (d.nu() > 1) return fit_outcome(srivc_auto_miso(d, o), "srivc_auto", settings_text(o));
  return fit_outcome(ctid::srivc_auto(d, o), "srivc_auto", settings_text(o));
}

// oe and tfest: on frequency data both are tf_from_frequency (Sanathanan-Koerner, then output error).
template <class One, class Many>
FitOutcome output_error(const FitRequest& r, const std::string& method, One one, Many many) {
  if (r.frequency) {
    FrequencyFitOptions o;
    apply_settings("tf_from_frequency", r.settings, {}, o);
    return fit_outcome(tf_from_frequency(*r.frequency, siso_orders(r, "tf_from_frequency"), o), "tf_from_frequency",
                   settings_text(o));
  }
  return tf_records<OeOptions>(r, method, one, many);
}

FitOutcome oe(const FitRequest& r) {
  using F1 = Result<TransferFunction> (*)(const IdData&, const TfOrders&, const OeOptions&);
  using FN = Result<TransferFunction> (*)(const std::vector<IdData>&, const TfOrders&, const OeOptions&);
  return output_error(r, "oe", static_cast<F1>(&ctid::oe), static_cast<FN>(&ctid::oe));
}

FitOutcome tfest(const FitRequest& r) {
  using F1 = Result<TransferFunction> (*)(const IdData&, const TfOrders&, const OeOptions&);
  using FN = Result<TransferFunction> (*)(const std::vector<IdData>&, const TfOrders&, const OeOptions&);
  return output_error(r, "tfest", static_cast<F1>(&ctid::tfest), static_cast<FN>(&ctid::tfest));
}

FitOutcome fsf(const FitRequest& r) {
  FsfOptions o;
  apply_settings("fsf", r.settings, {}, o);
  return fit_outcome(ctid::fsf(r.records.front(), o), "fsf", settings_text(o));
}

FitOutcome physical(const FitRequest& r) {
  const PhysicalStructure& p = *r.structure.physical;
  CTID_REQUIRE_OPTION(p.route == "fsf" || p.route == "frequency" || p.route == "raw",
                      "physical: the route must be fsf, frequency or raw (got '{}')", p.route);
  CTID_REQUIRE_OPTION(r.records.size() == 1 || p.route == "raw",
                      "physical: {} records: the fit of several experiments is by the raw route (the FSF routes "
                      "compress one record)",
                      r.records.size());
  std::vector<std::string> names;
  for (const auto& q : p.parameters) names.push_back(q.name);
  const PhysicalModel model(p.expression, names);
  const std::vector<std::string> symbols = PhysicalModel::symbols(p.expression);
  for (const auto& n : names)
    CTID_REQUIRE_OPTION(std::find(symbols.begin(), symbols.end(), n) != symbols.end(),
                        "physical: parameter {}: '{}' does not appear in the model \"{}\"", n, n, p.expression);
  // The raw route fits the record itself: the FSF compression's settings would be ignored, so they are refused.
  if (p.route == "raw")
    for (const auto& [name, value] : r.settings)
      for (const char* k : {"T", "n", "b", "weights", "step_points"})
        CTID_REQUIRE_OPTION(name != k,
                            "physical: {}: the raw route fits the record itself (its settings: a, unstable, "
                            "max_iterations, tolerance, fixed.NAME, bounds.NAME)",
                            name);
  FsfOptions fo;
  PhysicalFitOptions po;
  apply_settings("physical", r.settings, {}, fo, po);
  const IdData& d = r.records.front();
  if (p.route == "raw") {
    CTID_REQUIRE_OPTION(!fo.unstable || fo.a > 0,
                        "physical: the plant is declared unstable: give a window a > 0 (got a = {})", fo.a);
    SettingsText s{{"route", "raw"}, {"a", options_detail::format_real(fo.a)}};
    for (auto& x : settings_text(po)) s.push_back(std::move(x));
    return fit_outcome(fit_physical_raw(model, p.parameters, r.records, fo.a, po), "physical", std::move(s));
  }
  const Result<FsfModel> c = ctid::fsf(d, fo);
  Result<TransferFunction> q = p.route == "frequency" ? fit_physical_frequency(model, p.parameters, c.model, po, &d)
                                                      : fit_physical_step(model, p.parameters, c.model, po, &d);
  for (const auto& w : c.diagnostics.warnings) q.diagnostics.warnings.push_back("fsf: " + w);
  for (const auto& w : c.diagnostics.choices) q.diagnostics.choices.push_back("fsf: " + w);
  SettingsText s{{"route", p.route}};
  for (auto& x : settings_text(fo, po)) s.push_back(std::move(x));
  return fit_outcome(q, "physical", std::move(s));
}

FitOutcome greybox(const FitRequest& r) {
  GreyboxOptions o;
  apply_settings("greybox", r.settings, {}, o);
  return fit_outcome(ctid::greybox(r.records, *r.structure.greybox, o), "greybox", settings_text(o));
}

// El-Shafey's modal_fit: nb from the orders, the order from nf unless shifts are given, nk as the input delay;
// besides its table, shift_samples (the shifts in whole samples) and frequencies (rad/s: a generated input, its
// generator fitted to the first record's input).
FitOutcome modal(const FitRequest& r) {
  const IdData& d = r.records.front();
  const TfOrders orders = siso_orders(r, "modal");
  CTID_REQUIRE_OPTION(orders.nk >= 0, "modal: nk must be >= 0 (got {})", orders.nk);
  ModalOptions o;
  const SettingList own = apply_settings("modal", r.settings, {"shift_samples", "frequencies"}, o);
  std::vector<double> frequencies, samples;
  for (const auto& [name, value] : own)
    (name == "frequencies" ? frequencies : samples) = setting_reals("modal", name, value);
  if (!samples.empty()) o.shifts = shifts_from_samples("modal", samples, d.ts(), o.shifts);
  const int n = orders.nf;
  if (o.shifts.size() == 0)
    o.order = n;  // the shifts are chosen (and stated)
  else
    CTID_REQUIRE_OPTION(o.shifts.size() == n,
                        "modal needs one shift per pole: shifts=T1,..,T{} (s) or shift_samples=S1,..,S{} (samples; got "
                        "{} for nf = {}), or none (chosen automatically)",
                        n, n, o.shifts.size(), n);
  if (orders.nk > 0) {
    CTID_REQUIRE_OPTION(o.delay == 0, "modal: give the input delay once: nk (samples) or the setting delay (s)");
    o.delay = orders.nk * d.ts();
  }
  SettingsText s = settings_text(o);
  if (frequencies.empty()) return fit_outcome(modal_fit(r.records, orders.nb, o), "modal", std::move(s));
  const InputGenerator g = generator_fitted_to_input(frequencies, d);
  s.emplace_back("frequencies", text_of(frequencies));
  return fit_outcome(modal_fit(r.records, orders.nb, o, &g), "modal", std::move(s));
}

FitOutcome narx(const FitRequest& r) {
  NarxOptions o;
  apply_settings("narx", r.settings, {}, o);
  return fit_outcome(ctid::narx(r.records, o), "narx", settings_text(o));
}

// KIA from the NARX model given, or from one fitted here with the narx settings; the stages are kept.
FitOutcome kia(const FitRequest& r) {
  const IdData& d = r.records.front();
  KiaOptions ko;
  NarxOptions no;
  ko.linear.zoh = ko.quadratic.zoh = ko.cubic.zoh = d.intersample(0) == Intersample::Zoh;
  FitOutcome out;
  NarxModel start;
  if (r.structure.narx) {
    apply_settings("kia", r.settings, {}, ko);
    start = r.structure.narx->process();
    out.settings = settings_text(ko);
  } else {
    apply_settings("kia", r.settings, {}, ko, no);
    const Result<NarxModel> n = ctid::narx(r.records, no);
    out.stages.emplace_back("narx", to_any(n));
    start = n.model.process();
    out.settings = settings_text(ko, no);
  }
  const KiaRun run = ctid::kia(r.records, start, ko);
  out.stages.emplace_back("reconstructed", to_any(run.reconstructed));
  if (run.refined) out.stages.emplace_back("refined", to_any(*run.refined));
  out.result = to_any(run.result());
  out.method = "kia";
  return out;
}

FitOutcome subspace(const FitRequest& r) {
  SubspaceOptions o;
  apply_settings("subspace", r.settings, {}, o);
  return fit_outcome(r.frequency ? ctid::subspace(*r.frequency, o) : ctid::subspace(r.records.front(), o), "subspace",
                 settings_text(o));
}

FitOutcome ssest(const FitRequest& r) {
  SsestOptions o;
  apply_settings("ssest", r.settings, {}, o);
  const auto& start = r.structure.initial;
  Result<StateSpace> res = r.frequency ? (start ? ctid::ssest(*r.frequency, *start, o) : ctid::ssest(*r.frequency, o))
                                       : (start ? ctid::ssest(r.records, *start, o) : ctid::ssest(r.records, o));
  return fit_outcome(res, "ssest", settings_text(o));
}

}  // namespace fit_runs

std::string default_method(const FitStructure& structure, bool frequency_data) {
  if (frequency_data) return "tfest";
  return structure.orders.empty() ? "srivc_auto" : "srivc";
}

namespace fit_detail {
// The fits that have a capability, as "a, b or c" (for messages).
std::string fits_with(bool MethodCapabilities::*has) {
  return fits_where([has](const MethodInfo& m) { return m.capabilities.*has; });
}

// The request against what the method takes: each refusal names the method and what it takes.
void check_request(const MethodInfo& m, const FitRequest& r) {
  const MethodCapabilities& c = m.capabilities;
  const FitStructure& s = r.structure;
  auto refuse = [&](const std::string& what) { throw InvalidOptions(m.name + ": " + what); };
  if (!c.records || !m.run)
    refuse(m.reached_by.empty() ? std::string("is not a fit of records (ctid.methods() lists the fits)")
                                : "runs as " + m.reached_by);
  if (r.frequency) {
    if (!c.frequency_data) refuse("fits time-domain records, not frequency data");
    if (!r.records.empty()) refuse("give frequency data or records, not both");
  } else {
    if (r.records.empty()) throw InvalidArgument(m.name + ": no record to fit");
    if (r.records.size() > 1 && !c.several_records)
      throw InvalidArgument(detail::format("{}: fits one record (got {}); several records are fitted jointly by {}",
                                           m.name, r.records.size(), fits_with(&MethodCapabilities::several_records)));
    const IdData& d = r.records.front();
    if (d.nu() > 1 && !c.several_inputs)
      throw InvalidArgument(
          detail::format("{} estimates single-input models (the record has {} inputs)", m.name, d.nu()));
    if (d.ny() > 1 && !c.several_outputs)
      throw InvalidArgument(
          detail::format("{} estimates single-output models (the record has {} outputs; {} take several)", m.name,
                         d.ny(), fits_with(&MethodCapabilities::several_outputs)));
    for (std::size_t e = 1; e < r.records.size(); ++e)
      if (r.records[e].nu() != d.nu() || r.records[e].ny() != d.ny())
        throw InvalidArgument(detail::format("{}: record {} has {} inputs and {} outputs, record 1 has {} and {}",
                                             m.name, e + 1, r.records[e].nu(), r.records[e].ny(), d.nu(), d.ny()));
    // Each record is an experiment: the same one twice would count its information twice (every standard deviation
    // shrunk by sqrt(2)) without a second experiment.
    for (std::size_t e = 1; e < r.records.size(); ++e)
      for (std::size_t f = 0; f < e; ++f) {
        const IdData& a = r.records[f];
        const IdData& b = r.records[e];
        if (a.size() == b.size() && a.u() == b.u() && a.y() == b.y() && a.times() == b.times())
          throw InvalidArgument(detail::format("{}: records {} and {} are the same data (the same file given twice?); "
                                               "each record counts as an experiment, so a repeated one would count its "
                                               "information twice: give it once",
                                               m.name, f + 1, e + 1));
      }
  }
  if (!s.orders.empty() && !c.orders) refuse("has its own structure settings; it takes no transfer-function orders");
  if (s.orders.empty() && c.needs_orders) refuse("needs transfer-function orders (nb, nf, nk)");
  if (s.initial && !c.initial_model) refuse("takes no starting state-space model");
  if (s.greybox && !c.greybox_model) refuse("takes no grey-box model");
  if (!s.greybox && c.greybox_model) refuse("needs a grey-box model (the model file)");
  if (s.physical && !c.physical_model) refuse("takes no physical-model expression");
  if (!s.physical && c.physical_model) refuse("needs a physical model (an expression in s and its parameters)");
  if (!s.references.empty()) {
    if (!c.references) refuse("takes no references (closed loop is srivc's)");
    if (s.references.size() != r.records.size())
      refuse(detail::format("{} references for {} records (one per record)", s.references.size(), r.records.size()));
  }
  if (s.narx && !c.narx_model) refuse("takes no NARX model to start from");
}
}  // namespace fit_detail

FitOutcome fit(const std::string& method, const FitRequest& request) {
  const MethodInfo& m = method_info(method);
  fit_detail::check_request(m, request);
  return m.run(request);
}

}  // namespace ctid
