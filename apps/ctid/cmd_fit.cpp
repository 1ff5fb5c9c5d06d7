// ctid fit DATA... [--method M] ...: parse the flags, load the records, ask the library to fit (fit(),
// estimate/fit.hpp), show the result. Which methods there are, which flags and data each takes, how it runs and
// what its result is called come from the library's registry (estimate/methods.hpp); this file only reads them.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <set>
#include <tuple>
#include <type_traits>

#include "common.hpp"

namespace ctid::cli {

namespace {

struct FitArgs {
  DataArgs data;
  std::vector<std::string> paths;  ///< DATA arguments: several are several experiments of one system
  std::string method;  ///< the registry name (resolve_fit_args: the default, or the name given, aliases resolved)
  std::vector<int> nb, nf{1}, nk{0};
  std::vector<std::string> sets;
  bool delay = false;
  std::string controller, reference;
  bool frequency = false;
  std::string model_expr, via = "fsf", responses;
  std::vector<std::string> params;
  FrequencyColumns columns;  ///< --w --re --im, or the spectra --u-re --u-im --y-re --y-im
  std::string json, narx, report;
  std::string nx, initial;  ///< subspace/ssest: state dimension N or range A:B; ssest: a starting model (JSON)
  int period = 0, skip = 1;  ///< subspace/ssest: periodic records -> their FRF matrix (frf_from_periodic)
  double excited = 0.1;
  bool force = false;
  std::set<std::string> given;  ///< long names of the options given on the command line
  /// --validate DATA and/or --validate-samples A:B: a held-out record (DATA, or the estimation file), loaded with the
  /// same columns and with the estimation record's trend removed; set by run() as (description, record).
  std::string validate, validate_samples;
  std::optional<std::pair<std::string, IdData>> validation;
};

// A fit done: the library's outcome and the records it was computed on (for frequency data, the data instead).
struct Fitted {
  FitOutcome out;
  std::vector<IdData> records;
  std::optional<FrequencyData> frequency;
};

using Capability = bool MethodCapabilities::*;

// The fits that have a capability, as "a, b or c" (for messages: the registry decides, not a list here).
std::string fits_that(const std::function<bool(const MethodInfo&)>& has) { return fits_where(has); }
std::string fits_that(Capability c) {
  return fits_where([c](const MethodInfo& m) { return m.capabilities.*c; });
}
bool has_setting(const MethodInfo& m, const std::string& name) {
  return std::any_of(m.settings.begin(), m.settings.end(), [&](const OptionInfo& s) { return s.name == name; });
}
bool gives(const MethodInfo& m, const std::string& model_type) {
  const auto& t = m.capabilities.model_types;
  return std::find(t.begin(), t.end(), model_type) != t.end();
}
bool linear_fit(const MethodInfo& m) {
  const auto& t = m.capabilities.model_types;
  return std::all_of(t.begin(), t.end(), [](const std::string& x) { return is_linear_model_type(x); });
}

// Options that belong to some methods only: given to another, they are errors, never silently ignored. Which
// method takes which is the registry's capabilities.
void reject_flags_that_do_not_apply(const FitArgs& a) {
  const MethodInfo& mi = method_info(a.method);
  const MethodCapabilities& c = mi.capabilities;
  const std::string& m = mi.name;
  auto has = [&](const char* f) { return a.given.count(f) > 0; };
  auto refuse = [&](const char* f, const std::string& why) { throw UsageError("--" + std::string(f) + " " + why); };
  const std::string got = " (got " + m + ")";
  if (has("reference") && a.controller.empty()) refuse("reference", "needs --closed-loop-controller FILE (without it the fit would be open loop)");
  using Takes = std::function<bool(const MethodInfo&)>;
  const auto cap = [](Capability k) -> Takes { return [k](const MethodInfo& x) { return x.capabilities.*k; }; };
  const auto setting = [](const char* n) -> Takes { return [n](const MethodInfo& x) { return has_setting(x, n); }; };
  // A method-specific flag: what it does, and which methods take it.
  const std::vector<std::tuple<const char*, const char*, Takes>> specific{
      {"closed-loop-controller", "", cap(&MethodCapabilities::references)},
      {"responses", "writes FSF responses: it ", [](const MethodInfo& x) { return gives(x, "fsf"); }},
      {"narx", "gives KIA its NARX model: it ", cap(&MethodCapabilities::narx_model)},
      {"via", "chooses the route of --method", cap(&MethodCapabilities::physical_model)},
      {"model", "describes the model of --method",
       [](const MethodInfo& x) { return x.capabilities.physical_model || x.capabilities.greybox_model; }},
      {"param", "describes the model of --method", cap(&MethodCapabilities::physical_model)},
      {"delay", "(delay estimation) ", setting("estimate_delay")},
      {"nx", "sets a state dimension: it ", cap(&MethodCapabilities::nx)},
      {"initial", "gives ssest its starting model: it ", cap(&MethodCapabilities::initial_model)}};
  for (const auto& [flag, what, takes] : specific)
    if (has(flag) && !takes(mi)) {
      const std::string w = what;
      refuse(flag, (w.empty() || w.back() == ' ' ? w + "needs --method " : w + " ") + fits_that(takes) + got);
    }
  if (a.via != "fsf" && a.via != "frequency" && a.via != "raw") refuse("via", "must be fsf, frequency or raw (got '" + a.via + "')");
  // --period: the FRF matrix of periodic records, fitted by the methods that take frequency data of several outputs.
  const auto periodic = [](const MethodInfo& x) { return x.capabilities.frequency_data && x.capabilities.several_outputs; };
  if (has("period") && !periodic(mi)) refuse("period", "fits the FRF of periodic records: it needs --method " + fits_that(periodic) + got);
  for (const char* f : {"skip", "excited"})
    if (has(f) && !has("period")) refuse(f, "belongs to --period (periodic records)");
  if (has("period") && a.frequency) refuse("period", "computes frequency data from periodic records (not with --frequency)");
  for (const char* f : {"validate", "validate-samples"}) {
    if (!has(f)) continue;
    if (!linear_fit(mi))
      refuse(f, "is not available with --method " + m + " yet: validate its result with ctid validate RESULT.json DATA");
    if (a.frequency || has("period") || has("closed-loop-controller") || a.paths.size() > 1)
      refuse(f, "holds out a record of a single open-loop time-domain fit (not with --frequency, --period, "
                "--closed-loop-controller or several DATA files): use ctid validate RESULT.json DATA");
  }
  for (const char* f : {"nb", "nf", "nk"})
    if (has(f) && !c.orders && m == default_method(FitStructure{}))
      refuse(f, "sets transfer-function orders, which srivc-auto chooses (--set nf_max=N bounds them); give --method "
                "srivc for fixed orders");
  for (const char* f : {"nb", "nf", "nk"})
    if (has(f) && !c.orders) refuse(f, "sets transfer-function orders; " + m + " has its own structure settings (--set)");
  if (!a.frequency)
    for (const char* f : {"w", "re", "im", "u-re", "u-im", "y-re", "y-im"})
      if (has(f)) refuse(f, "names a column of frequency data: it needs --frequency");
}

// --nx N or A:B: the state dimension (and the upper end of an order range); 0 (as when not given): the subspace
// start's choice, the library's nx = 0.
std::pair<int, int> nx_of(const FitArgs& a) {
  if (a.nx.empty()) return {0, 0};
  const auto colon = a.nx.find(':');
  auto number = [&](const std::string& t, int least) {
    if (t.empty() || t.find_first_not_of("0123456789") != std::string::npos || t.size() > 4 || std::stoi(t) < least)
      throw UsageError("--nx must be a state dimension N >= 1, 0 (chosen from the singular values) or a range A:B "
                       "(got '" + a.nx + "')");
    return std::stoi(t);
  };
  if (colon == std::string::npos) return {number(a.nx, 0), 0};
  const int lo = number(a.nx.substr(0, colon), 1), hi = number(a.nx.substr(colon + 1), 1);
  if (hi < lo) throw UsageError("--nx A:B needs A <= B (got '" + a.nx + "')");
  return {lo, hi};
}

// The settings of the request: the flags that are settings (--delay, --nx), then every --set NAME=VALUE.
SettingList settings_of(const FitArgs& a) {
  SettingList s;
  if (a.delay) s.emplace_back("estimate_delay", std::string("1"));
  const auto [nx, nx_max] = nx_of(a);
  if (nx > 0) s.emplace_back("nx", std::to_string(nx));
  if (nx_max > 0) s.emplace_back("nx_max", std::to_string(nx_max));
  for (auto& kv : setting_list(a.sets)) s.push_back(std::move(kv));
  return s;
}

// Transfer-function orders from --nb/--nf/--nk for records of nu inputs: one value for every input, or one per
// input (nb defaults to nf).
std::vector<TfOrders> orders_of(const FitArgs& a, int nu) {
  if (nu == 1) {
    if (a.nf.size() != 1 || a.nb.size() > 1 || a.nk.size() != 1)
      throw UsageError("one input: one --nb, --nf and --nk value");
    return {{a.nb.empty() ? a.nf[0] : a.nb[0], a.nf[0], a.nk[0]}};
  }
  auto per_input = [&](const std::vector<int>& v, const char* flag, int i) {
    if (v.size() != 1 && static_cast<int>(v.size()) != nu)
      throw UsageError(detail::format("{} has {} values for {} inputs (give one value, or one per input)", flag, v.size(), nu));
    return v.size() == 1 ? v[0] : v[static_cast<size_t>(i)];
  };
  std::vector<TfOrders> all;
  for (int i = 0; i < nu; ++i) {
    const int nf_i = per_input(a.nf, "--nf", i);
    all.push_back({a.nb.empty() ? nf_i : per_input(a.nb, "--nb", i), nf_i, per_input(a.nk, "--nk", i)});
  }
  return all;
}

// --initial MODEL.json: ssest's starting model.
StateSpace initial_state_space(const FitArgs& a) {
  const LinearModel m = [&] {
    try {
      return read_model_json(a.initial);
    } catch (const std::exception& e) {
      throw InputError(std::string("--initial: ") + e.what());
    }
  }();
  if (!std::holds_alternative<StateSpace>(m))
    throw UsageError("--initial " + a.initial + " holds a transfer function; ssest starts from a state-space model "
                     "(\"type\": \"state_space\")");
  return std::get<StateSpace>(m);
}

// --model EXPRESSION with --param NAME=INITIAL...: the physical model; the expression is parsed here so that a
// syntax error, an undeclared symbol or a --param the expression does not use is reported naming the flag.
PhysicalStructure physical_of(const FitArgs& a) {
  if (a.model_expr.empty()) throw UsageError("--method physical needs --model EXPRESSION (e.g. \"k1/(s^2-k2)\")");
  PhysicalStructure p{a.model_expr, {}, a.via};
  std::vector<std::string> names;
  for (const auto& s : a.params) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) throw UsageError("--param needs NAME=INITIAL (got '" + s + "')");
    PhysicalParameter q;
    q.name = s.substr(0, eq);
    q.initial = to_double("--param " + q.name, s.substr(eq + 1));
    p.parameters.push_back(q);
    names.push_back(q.name);
  }
  try {
    PhysicalModel check(a.model_expr, names);
  } catch (const InvalidArgument& e) {
    throw UsageError(std::string(e.what()) + "; declare every parameter with --param NAME=INITIAL");
  }
  return p;
}

// --narx FILE: the NARX model KIA starts from.
NarxModel narx_of(const std::string& path) {
  const AnyModel m = read_result_file(path).result.model;
  if (!std::holds_alternative<NarxModel>(m))
    throw InputError(path + ": --narx needs a NARX model; this is a " + model_type_name(m) + " model");
  return std::get<NarxModel>(m);
}

// The request's structure from the flags the method takes (the others were refused before).
FitStructure structure_of(const FitArgs& a, const MethodInfo& m, int nu) {
  FitStructure s;
  if (m.capabilities.orders) s.orders = orders_of(a, nu);
  if (m.capabilities.physical_model) s.physical = physical_of(a);
  if (!a.initial.empty()) s.initial = initial_state_space(a);
  if (!a.narx.empty()) s.narx = narx_of(a.narx);
  return s;
}

// The library's fit; bad settings, orders or data for the method are usage errors of the command line (exit 2),
// naming the flag where a setting came from one (--delay, --nx).
FitOutcome fit_request(const FitArgs& a, const FitRequest& r) {
  try {
    return fit(a.method, r);
  } catch (const UnknownSetting& e) {
    const std::string flag = e.key == "estimate_delay" && a.delay ? "--delay"
                             : (e.key == "nx" || e.key == "nx_max") && !a.nx.empty() ? "--nx"
                                                                                     : "--set " + e.key;
    throw unknown_setting(flag, e, a.method);
  }
}

// Records 2.. of several DATA files, named by their files (for the report's section per record).
std::vector<std::pair<std::string, IdData>> more_records_of(const FitArgs& a, const std::vector<IdData>& ds) {
  std::vector<std::pair<std::string, IdData>> more;
  for (std::size_t e = 1; e < ds.size(); ++e) more.emplace_back(a.paths[e], ds[e]);
  return more;
}

// "experiments: 2 (a.csv: 1000 samples, b.csv: 800 samples)" before a joint fit's result (nothing for one record).
void print_experiments(const FitArgs& a, const std::vector<IdData>& ds) {
  if (ds.size() < 2) return;
  std::printf("experiments: %zu (", ds.size());
  for (std::size_t e = 0; e < ds.size(); ++e)
    std::printf("%s%s: %d samples", e ? ", " : "", a.paths[e].c_str(), ds[e].size());
  std::printf(")\n");
}

// --json: the result file, with where it came from.
void write_json(const FitArgs& a, const FitOutcome& out, const Provenance& prov) {
  if (a.json.empty()) return;
  write_result_json(a.json, out.result, out.method, &prov);
  std::printf("wrote %s\n", a.json.c_str());
}

int exit_code(const Result<AnyModel>& r) {
  if (r.usable()) return kOk;
  std::fprintf(stderr, "ctid: the estimate is not usable: %s\n", r.why_not_usable().c_str());
  return kNotUsable;
}

// A fit to frequency-response data: the library's text of it, the JSON file.
int present_frequency(const Fitted& f, const FitArgs& a, const Provenance& prov) {
  std::fputs(fit_text(f.out, *f.frequency).c_str(), stdout);
  write_json(a, f.out, prov);
  return exit_code(f.out.result);
}

// Print, write the JSON file and the HTML report if asked, and map usability to the exit code. The printed samples
// are those of the first record; the fit is over all of them; the report shows each record.
int present(const Fitted& f, const FitArgs& a, const Provenance& prov) {
  const FitOutcome& out = f.out;
  const Result<AnyModel>& r = out.result;
  if (f.frequency) return present_frequency(f, a, prov);
  const std::vector<IdData>& ds = f.records;
  const IdData& d = ds.front();
  print_experiments(a, ds);
  std::fputs(fit_text(out, d).c_str(), stdout);
  // A linear model through the origin cannot follow an offset the data kept (--detrend none).
  if (a.data.detrend == "none" && is_linear(r.model)) cli::warn_offsets(d);
  std::vector<std::pair<std::string, IdData>> more = more_records_of(a, ds);
  if (a.validation) {
    try {
      std::fputs(held_out_text(r, a.validation->first, a.validation->second).c_str(), stdout);
    } catch (const InvalidArgument& e) {
      throw UsageError(std::string("--validate: ") + e.what());
    }
    more.insert(more.begin(), {"validation, " + a.validation->first, a.validation->second});
  }
  write_json(a, out, prov);
  if (const auto* fsf = std::get_if<FsfModel>(&r.model); fsf && !a.responses.empty()) {
    write_fsf_responses(a.responses, *fsf);
    std::printf("wrote %s_time.csv and %s_freq.csv\n", a.responses.c_str(), a.responses.c_str());
  }
  write_report(a.report, d, r, out.method, out.settings, a.paths.empty() ? a.data.path : a.paths.front(), prov, more,
               a.validation ? std::optional(validation_initial_condition(r.model)) : std::nullopt);
  return exit_code(r);
}

// Time-domain records (one, or several experiments of one system) fitted by the method.
Fitted fit_records(const FitArgs& a, std::vector<IdData> ds) {
  const MethodInfo& m = method_info(a.method);
  FitRequest r;
  r.structure = structure_of(a, m, ds.front().nu());
  r.settings = settings_of(a);
  r.records = std::move(ds);
  FitOutcome out = fit_request(a, r);
  return {std::move(out), std::move(r.records), std::nullopt};
}

// Closed-loop SRIVC on one record or several (jointly, one controller): each record's reference column is loaded
// with its data and split off; the controller and the reference's intersample behaviour are settings.
Fitted run_closed_loop(const FitArgs& a) {
  if (a.reference.empty()) throw UsageError("--closed-loop-controller needs --reference COLUMN");
  if (a.data.inputs.size() != 1) throw UsageError("closed-loop identification needs exactly one --input (the plant input)");
  const LinearModel c = read_model_json(a.controller);
  if (!std::holds_alternative<TransferFunction>(c)) throw UsageError(a.controller + ": the controller must be a transfer_function");
  DataArgs da = a.data;
  da.inputs.push_back(a.reference);
  FitRequest r;
  for (const IdData& both : da.load_each(a.paths, true)) {
    r.records.push_back(both.select({0}, {0}));
    r.structure.references.push_back(both.u().col(1));
    if (r.settings.empty()) {
      r.settings.emplace_back("controller", OptionValue(std::optional(std::get<TransferFunction>(c))));
      r.settings.emplace_back("reference_intersample", std::string(to_string(both.intersample(1))));
    }
  }
  r.structure.orders = orders_of(a, 1);
  for (auto& s : settings_of(a)) r.settings.push_back(std::move(s));
  FitOutcome out = fit_request(a, r);
  return {std::move(out), std::move(r.records), std::nullopt};
}

// Frequency-response data: columns w, re, im (G) or the spectra U and Y.
Fitted run_frequency(const FitArgs& a) {
  FitRequest r;
  int rows = 0;
  try {
    r.frequency = load_frequency_data(a.data.path, a.columns, &rows);
  } catch (const ColumnSelectionError&) {
    throw;  // the options' problem (exit 2)
  } catch (const InvalidOptions&) {
    throw;
  } catch (const InvalidArgument& e) {
    throw InputError(e.what());  // the file's content
  }
  if (a.data.provenance) a.data.provenance->add_data_file(a.data.path, rows);
  const MethodInfo& m = method_info(a.method);
  if (!m.capabilities.frequency_data || m.capabilities.several_outputs)
    throw UsageError("frequency data are fitted with --method " +
                     fits_that([](const MethodInfo& x) { return x.capabilities.frequency_data && !x.capabilities.several_outputs; }) +
                     " (got " + m.name + "; --period gives subspace and ssest the FRF matrix of periodic records)");
  r.structure = structure_of(a, m, 1);
  r.settings = settings_of(a);
  FitOutcome out = fit_request(a, r);
  return {std::move(out), {}, std::move(r.frequency)};
}

// A grey-box model file fitted to one record or several (one parameter set, an initial state per record). The
// model's input and output names are the data columns unless --input/--output map them (in the model's order).
Fitted run_greybox(const FitArgs& a) {
  if (a.model_expr.empty()) throw UsageError("--method greybox needs --model FILE.json (the grey-box model file)");
  if (a.frequency) throw UsageError("--method greybox fits time-domain records (not --frequency)");
  FitRequest r;
  r.structure.greybox = read_greybox_json(a.model_expr);
  const GreyboxModel& model = *r.structure.greybox;
  const DataArgs da = columns_of(a.data, model);
  if (static_cast<int>(da.inputs.size()) != model.nu() || static_cast<int>(da.outputs.size()) != model.ny())
    throw UsageError(detail::format("--input/--output name {} and {} columns; the model has {} inputs ({}) and {} outputs ({})",
                                    da.inputs.size(), da.outputs.size(), model.nu(),
                                    options_detail::format_names(model.spec().inputs), model.ny(),
                                    options_detail::format_names(model.output_names())));
  r.records = a.paths.size() > 1 ? da.load_each(a.paths, true) : std::vector<IdData>{da.load(true)};
  r.settings = settings_of(a);
  FitOutcome out = fit_request(a, r);
  return {std::move(out), std::move(r.records), std::nullopt};
}

// Several DATA files: several experiments of one system, the same columns in each, fitted jointly.
Fitted run_experiments(const FitArgs& a) {
  const MethodInfo& m = method_info(a.method);
  if (!m.capabilities.several_records)
    throw UsageError(detail::format("{} DATA files are several experiments: fitted jointly by --method {} (got {}; the "
                                    "other estimators take one record so far)",
                                    a.paths.size(), fits_that(&MethodCapabilities::several_records), m.name));
  if (a.frequency) throw UsageError("several DATA files: time-domain data only (not --frequency)");
  return fit_records(a, a.data.load_each(a.paths, true));
}

// --period N: periodic records (one per input) -> their FRF matrix with variances -> subspace or ssest on it.
Fitted run_periodic(const FitArgs& a) {
  if (!a.report.empty()) throw UsageError("--report needs time-domain records (not --period: a fit to frequency data)");
  const std::vector<IdData> ds = a.paths.size() > 1 ? a.data.load_each(a.paths, true) : std::vector<IdData>{a.data.load(true)};
  FitRequest r;
  r.frequency = frf_from_periodic(ds, a.period, a.skip, a.excited);
  const FrequencyData& fd = *r.frequency;
  const int periods = ds.front().size() / a.period - a.skip;
  if (!a.data.quiet)
    std::printf("FRF matrix of the periodic records: %d excited frequencies from %.6g to %.6g Hz, %d period(s) of %d "
              "samples averaged (%d skipped)\n", fd.size(), fd.w()(0) / (2 * std::numbers::pi),
              fd.w()(fd.size() - 1) / (2 * std::numbers::pi), periods, a.period, a.skip);
  const MethodInfo& m = method_info(a.method);
  if (nx_of(a).second > 0 && !has_setting(m, "nx_max"))
    throw UsageError("--nx A:B (an order range) is for --method " +
                     fits_that([](const MethodInfo& x) { return has_setting(x, "nx_max"); }) + "; " + m.name + " takes one N");
  r.structure = structure_of(a, m, ds.front().nu());
  r.settings = settings_of(a);
  FitOutcome out = fit_request(a, r);
  return {std::move(out), {ds.front()}, std::nullopt};
}

// --validate / --validate-samples: the held-out record, with the estimation record's trend (none with --detrend
// none) removed, so that no statistic of the validation record enters the model.
std::pair<std::string, IdData> validation_record(const FitArgs& a, const TrendInfo& trend) {
  DataArgs v = a.data;
  v.path = a.validate.empty() ? a.data.path : a.validate;
  v.samples = a.validate_samples;
  v.samples_option = "--validate-samples";
  v.detrend = "none";
  v.announce_means = false;
  std::pair<int, int> rows;
  IdData d = v.load(true, nullptr, &rows);
  if (a.data.detrend != "none") {
    d = d.remove_trend(trend);
    if (v.provenance) {
      std::string& done = v.provenance->preprocessing.back();
      done = "validation " + done.substr(0, done.rfind("; no detrending")) + "; the estimation record's " +
             (a.data.detrend == "mean" ? "means" : "linear trends") + " removed";
    }
  } else if (v.provenance) {
    v.provenance->preprocessing.back().insert(0, "validation ");
  }
  std::string name = v.path;
  if (!v.samples.empty()) name += detail::format(" rows {}..{}", rows.first, rows.second);
  return {name, d};
}

// Parse -> library request -> fit: what `ctid fit` computes (and `ctid batch` per record), nothing shown.
Fitted fit_of(FitArgs& a) {
  const MethodInfo& m = method_info(a.method);
  if (!a.controller.empty()) return run_closed_loop(a);
  if (m.capabilities.greybox_model) return run_greybox(a);
  if (a.period > 0) return run_periodic(a);
  if (a.paths.size() > 1) return run_experiments(a);
  if (a.frequency && !a.report.empty()) throw UsageError("--report needs time-domain data (not --frequency)");
  if (a.frequency) return run_frequency(a);
  TrendInfo trend;
  const IdData d = a.data.load(true, &trend);
  if (!a.validate.empty() || !a.validate_samples.empty()) a.validation = validation_record(a, trend);
  // A constant channel carries no information on the dynamics (the library's check, made before any other).
  require_io_data(d, m.name.c_str(), -1, -1);
  if (nx_of(a).second > 0 && !has_setting(m, "nx_max"))
    throw UsageError("--nx A:B (an order range) is for --method " +
                     fits_that([](const MethodInfo& x) { return has_setting(x, "nx_max"); }) + "; " + m.name +
                     " takes one N (or none: its singular values choose)");
  return fit_records(a, {d});
}

// Every file a fit reads besides its records: the NARX model, the controller, the initial model, the validation
// record, the grey-box model file (what an output must not overwrite).
std::vector<std::string> other_input_files(const FitArgs& a) {
  return {a.narx, a.controller, a.initial, a.validate,
          method_info(a.method).capabilities.greybox_model ? a.model_expr : ""};
}

int run(FitArgs a, Provenance& prov) {
  reject_flags_that_do_not_apply(a);
  std::vector<std::string> inputs = a.paths;
  const std::vector<std::string> others = other_input_files(a);
  inputs.insert(inputs.end(), others.begin(), others.end());
  check_output_files({a.json, a.report, a.responses.empty() ? "" : a.responses + "_time.csv",
                 a.responses.empty() ? "" : a.responses + "_freq.csv"},
                inputs, a.force);
  a.data.provenance = &prov;
  const Fitted f = fit_of(a);
  return present(f, a, prov);
}

}  // namespace

namespace {
std::vector<std::string> method_choices();
}  // namespace

std::string fit_method_help(const CLI::App& fit) {
  // The --method value parsed before the --help (the option keeps it).
  const CLI::Option* opt = fit.get_option_no_throw("--method");
  if (!opt || opt->results().empty()) return "";
  const std::string& given = opt->results().front();
  const auto names = method_choices();
  if (std::find(names.begin(), names.end(), given) == names.end()) return "";
  const MethodInfo& m = method_info(given);
  std::string out = "\n" + m.name + ": " + m.summary + "\n" + settings_help(m);
  for (const auto& name : m.variants) {
    const MethodInfo& v = method_info(name);
    out += "\n" + v.name + ": " + v.summary + " (" + (v.reached_by.empty() ? "its settings apply here too" : v.reached_by) +
           ")\n" + settings_help(v);
  }
  return out;
}

namespace {
// The --method choices: every fit of the registry and its other spellings.
std::vector<std::string> method_choices() {
  std::vector<std::string> names;
  for (const auto& m : methods())
    if (m.capabilities.records) {
      names.push_back(m.name);
      names.insert(names.end(), m.aliases.begin(), m.aliases.end());
    }
  return names;
}

// The options of ctid fit on `app`; after parsing, resolve_fit_args fills the defaults that depend on what was given.
std::shared_ptr<FitArgs> add_fit_options(CLI::App& app) {
  auto a = std::make_shared<FitArgs>();
  app.add_option("DATA", a->paths,
                 "CSV/.dat table (header row optional) or .mat file; several files are several experiments of one system, "
                 "fitted jointly (" + fits_that(&MethodCapabilities::several_records) + "; the same columns in each)")
      ->required();
  app.add_option("--method", a->method,
                 "Estimator: " + fits_where([](const MethodInfo&) { return true; }) + " (with --help: its settings). Default: srivc_auto (the orders and a "
                 "delay chosen by BIC, means removed) without --nb/--nf/--nk, srivc with them, tfest with --frequency")
      ->check(CLI::IsMember(method_choices()));
  a->data.add_to(app, true);
  app.add_option("--nb", a->nb, "Number of numerator coefficients (default: nf); one per input with several inputs (1,2)")
      ->delimiter(',');
  app.add_option("--nf", a->nf, "Model order (denominator coefficients after the leading 1); per input allowed")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--nk", a->nk, "Input delay in samples; per input allowed")->delimiter(',')->capture_default_str();
  app.add_option("--set", a->sets,
                 "Method setting NAME=VALUE (repeatable); 'ctid fit --method M --help' lists M's settings with units, "
                 "ranges and defaults (the same names as the C++ options and the Python keywords). modal also "
                 "takes shift_samples=S1,..,Sn (the shifts in samples) and frequencies=w1,.. (rad/s: a generated input, its "
                 "generator fitted to the measured input)");
  app.add_flag("--delay", a->delay,
               "Estimate a (non-integer) input delay (srivc, oe, tfest): grid search over [delay_min, delay_max], then "
               "refinement");
  app.add_option("--closed-loop-controller", a->controller,
                 "Closed-loop data: JSON file of the known controller C(s) (transfer_function); with --reference");
  app.add_option("--reference", a->reference, "Closed-loop data: the reference column (added at the plant input unless --set reference_at_plant_input=0: then u = C (r - y))");
  app.add_flag("--frequency", a->frequency,
               "DATA holds frequency-response data: columns --w (rad/s), --re, --im of G(jw), or the spectra --u-re --u-im "
               "--y-re --y-im");
  app.add_option("--w", a->columns.w, "Frequency column (rad/s) of frequency data")->capture_default_str();
  app.add_option("--re", a->columns.re, "Real part of G(jw)")->capture_default_str();
  app.add_option("--im", a->columns.im, "Imaginary part of G(jw)")->capture_default_str();
  app.add_option("--u-re", a->columns.u_re, "Input spectrum, real part");
  app.add_option("--u-im", a->columns.u_im, "Input spectrum, imaginary part");
  app.add_option("--y-re", a->columns.y_re, "Output spectrum, real part");
  app.add_option("--y-im", a->columns.y_im, "Output spectrum, imaginary part");
  app.add_option("--model", a->model_expr,
                 "physical: transfer-function expression in s, e.g. \"k1/(s^2-k2)\"; greybox: the model file (JSON: inputs, "
                 "states, outputs, parameters, equations, initial; docs/methods/greybox.md)");
  app.add_option("--param", a->params, "physical: NAME=INITIAL for each parameter of --model (repeatable)");
  app.add_option("--via", a->via, "physical: fit to the FSF step response (fsf), the FSF frequency response (frequency), "
                                  "or the raw data (raw)")
      ->capture_default_str();
  app.add_option("--responses", a->responses,
                 "fsf: write PREFIX_time.csv (step and impulse with standard deviations) and PREFIX_freq.csv (G(jw) with "
                 "standard deviations of its real and imaginary parts)");
  app.add_option("--narx", a->narx, "kia: the NARX model JSON to reconstruct from (otherwise a NARX model is fitted first)");
  app.add_option("--period", a->period,
                 "subspace, ssest: DATA are periodic records (one per input) of this many samples per period: fit "
                 "the FRF matrix of the averaged periods, weighted by its variances")
      ->check(CLI::Range(2, 1 << 30));
  app.add_option("--skip", a->skip, "with --period: leading periods dropped (their transient)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1 << 20));
  app.add_option("--excited", a->excited,
                 "with --period: a frequency is used where an input's amplitude is at least this fraction of its "
                 "largest")
      ->capture_default_str();
  app.add_option("--nx", a->nx, "subspace, ssest: state dimension N (0: where the singular values drop most, as when "
                 "not given), or ssest: a range A:B (the least BIC is kept)");
  app.add_option("--initial", a->initial, "ssest: starting model, a state-space JSON file (a result of ctid fit --json); "
                 "fixed.A1_2=.. entries refer to its coordinates");
  app.add_option("--validate", a->validate,
                 "A held-out record (same columns) the model is simulated on: its fit is printed and reported; the "
                 "estimation record's means/trend are removed from it");
  app.add_option("--validate-samples", a->validate_samples,
                 "Rows A:B of the --validate file (without --validate: of the DATA file), e.g. --samples 1:500 "
                 "--validate-samples 501:");
  app.add_option("--json", a->json, "Write the result (model, parameters, fit) to this JSON file");
  app.add_option("--report", a->report, "Write a self-contained HTML report (plots, tests, parameters) to this file");
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  return a;
}

void resolve_fit_args(FitArgs& a, const CLI::App& app) {
  for (const CLI::Option* o : app.get_options())
    if (o->count() > 0)
      for (const auto& n : o->get_lnames()) a.given.insert(n);
  a.data.path = a.paths.empty() ? "" : a.paths.front();
  FitStructure orders_given;
  if (a.given.count("nb") || a.given.count("nf") || a.given.count("nk")) orders_given.orders.emplace_back();
  a.method = a.method.empty() ? default_method(orders_given, a.frequency) : method_info(a.method).name;
  // A method that takes no offset into its model and chooses everything itself removes the means unless told
  // otherwise (said on stderr by the loader).
  const std::string& detrend = method_info(a.method).capabilities.default_detrend;
  if (detrend != "none" && !a.given.count("detrend")) {
    a.data.detrend = detrend;
    a.data.announce_means = true;
  }
}
}  // namespace

void setup_fit(CLI::App& app, Command& command) {
  auto a = add_fit_options(app);
  app.callback([a, &app, &command] {
    resolve_fit_args(*a, app);
    command = [a](Provenance& prov) { return run(*a, prov); };
  });
}

void setup_batch(CLI::App& app, Command& command) {
  auto a = add_fit_options(app);
  auto job = std::make_shared<BatchJob>();
  app.get_option("DATA")->description(
      "Records: files or glob patterns (a quoted pattern is expanded by ctid, for more files than a command line "
      "holds); each record is fitted alone, with the options below, and is one row of --out");
  app.add_option("--out", job->out,
                 "Rows file, .csv or .jsonl: one row per record (id, method, model, orders, fit_percent, termination, "
                 "usable, seconds, error, then NAME and NAME_std per parameter: the columns of Python's "
                 "ctid.batch.fit_many), written as the fits finish")
      ->required();
  app.add_option("--jobs", job->jobs, "Threads fitting records at once (default: one per core)")->check(CLI::Range(1, 4096));
  app.add_flag("--resume", job->resume, "Continue an interrupted batch: fit only the records whose id is not in --out");
  app.callback([a, job, &app, &command] {
    resolve_fit_args(*a, app);
    job->patterns = a->paths;
    job->method = a->method;
    job->force = a->force;
    command = [a, job](Provenance&) {
      for (const char* f : {"json", "report", "validate", "validate-samples", "responses", "frequency", "period"})
        if (a->given.count(f))
          throw UsageError("--" + std::string(f) + " is an option of ctid fit on one record, not of ctid batch (one "
                           "row per record in --out)");
      reject_flags_that_do_not_apply(*a);  // once, before any record
      job->inputs = other_input_files(*a);
      job->fit_one = [a](const std::string& path) {
        FitArgs b = *a;
        b.paths = {path};
        b.data.path = path;
        b.data.quiet = true;
        return fit_of(b).out;
      };
      return run_batch(*job);
    };
  });
}

int run_fit(std::vector<std::string> args, Provenance& provenance) {
  CLI::App app{"ctid fit"};
  const auto a = add_fit_options(app);
  std::reverse(args.begin(), args.end());  // CLI11 parses a vector from its back
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    throw UsageError(e.what());
  }
  resolve_fit_args(*a, app);
  return run(*a, provenance);
}

}  // namespace ctid::cli

