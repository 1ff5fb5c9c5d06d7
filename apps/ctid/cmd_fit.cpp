// ctid fit DATA [--method srivc-auto|srivc|tfest|oe|lssvf|ivsvf|rls-svf|fsf|physical|greybox|modal|narx|kia|subspace|ssest] ...
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <set>
#include <type_traits>

#include "common.hpp"

namespace ctid::cli {
extern std::function<int()> g_run;

namespace {

struct FitArgs {
  DataArgs data;
  std::vector<std::string> paths;  ///< DATA arguments: several are several experiments of one system (srivc)
  std::string method;  ///< empty: srivc-auto, or srivc when orders are given (resolved after parsing)
  std::vector<int> nb, nf{1}, nk{0};
  std::vector<std::string> sets;
  bool delay = false;
  std::string controller, reference;
  bool frequency = false;
  std::string model_expr, via = "fsf", responses;
  std::vector<std::string> params;
  std::string w = "w", re = "re", im = "im", u_re, u_im, y_re, y_im;
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

// A method of `ctid fit`: the library registry entries whose settings --set takes (estimate/methods.hpp; empty:
// settings not yet in a table, listed in the --set help), and how it runs.
struct FitMethod {
  std::vector<std::string> library;
  std::function<int(const FitArgs&, const IdData&)> run;
};
const std::map<std::string, FitMethod>& fit_methods();

// Options that belong to some methods only: given to another, they are errors, never silently ignored.
void reject_flags_that_do_not_apply(const FitArgs& a) {
  auto has = [&](const char* f) { return a.given.count(f) > 0; };
  auto refuse = [&](const char* f, const std::string& why) { throw UsageError("--" + std::string(f) + " " + why); };
  const std::string m = a.method;
  const bool tf_data = m == "srivc" || m == "oe" || m == "tfest";
  if (has("reference") && a.controller.empty()) refuse("reference", "needs --closed-loop-controller FILE (without it the fit would be open loop)");
  if (has("closed-loop-controller") && m != "srivc") refuse("closed-loop-controller", "needs --method srivc (got " + m + ")");
  if (has("responses") && m != "fsf") refuse("responses", "writes FSF responses: it needs --method fsf (got " + m + ")");
  if (has("narx") && m != "kia") refuse("narx", "gives KIA its NARX model: it needs --method kia (got " + m + ")");
  if (has("via") && m != "physical") refuse("via", "chooses the route of --method physical (got " + m + ")");
  if (a.via != "fsf" && a.via != "frequency" && a.via != "raw") refuse("via", "must be fsf, frequency or raw (got '" + a.via + "')");
  if (has("model") && m != "physical" && m != "greybox")
    refuse("model", "describes the model of --method physical or greybox (got " + m + ")");
  if (has("param") && m != "physical") refuse("param", "describes the model of --method physical (got " + m + ")");
  if (has("delay") && !tf_data) refuse("delay", "(delay estimation) needs --method srivc, oe or tfest (got " + m + ")");
  if (has("nx") && m != "subspace" && m != "ssest") refuse("nx", "sets a state dimension: it needs --method subspace or ssest (got " + m + ")");
  if (has("initial") && m != "ssest") refuse("initial", "gives ssest its starting model: it needs --method ssest (got " + m + ")");
  if (has("period") && m != "subspace" && m != "ssest")
    refuse("period", "fits the FRF of periodic records: it needs --method subspace or ssest (got " + m + ")");
  for (const char* f : {"skip", "excited"})
    if (has(f) && !has("period")) refuse(f, "belongs to --period (periodic records)");
  if (has("period") && a.frequency) refuse("period", "computes frequency data from periodic records (not with --frequency)");
  for (const char* f : {"validate", "validate-samples"}) {
    if (!has(f)) continue;
    if (m == "narx" || m == "kia" || m == "greybox")
      refuse(f, "is not available with --method " + m + " yet: validate its result with ctid validate RESULT.json DATA");
    if (a.frequency || has("period") || has("closed-loop-controller") || a.paths.size() > 1)
      refuse(f, "holds out a record of a single open-loop time-domain fit (not with --frequency, --period, "
                "--closed-loop-controller or several DATA files): use ctid validate RESULT.json DATA");
  }
  for (const char* f : {"nb", "nf", "nk"})
    if (has(f) && m == "srivc-auto")
      refuse(f, "sets transfer-function orders, which srivc-auto chooses (--set nf_max=N bounds them); give --method "
                "srivc for fixed orders");
  for (const char* f : {"nb", "nf", "nk"})
    if (has(f) && (m == "narx" || m == "kia" || m == "fsf" || m == "physical" || m == "greybox" || m == "subspace" ||
                   m == "ssest"))
      refuse(f, "sets transfer-function orders; " + m + " has its own structure settings (--set)");
  if (!a.frequency)
    for (const char* f : {"w", "re", "im", "u-re", "u-im", "y-re", "y-im"})
      if (has(f)) refuse(f, "names a column of frequency data: it needs --frequency");
}



// After a fit by a linear method of data that keep their offsets (--detrend none): warn_offsets.
void warn_offsets(const FitArgs& a, const IdData& d) {
  static const std::set<std::string> linear = {"srivc", "tfest", "oe", "lssvf", "ivsvf", "rls-svf", "subspace", "ssest"};
  if (a.data.detrend != "none" || !linear.count(a.method)) return;
  cli::warn_offsets(d);
}

// The model simulated on the held-out record (validation_initial_condition: for a linear model the initial state that
// fits it best, as MATLAB's compare), its fit per output printed.
void print_validation(const AnyModel& m, const std::pair<std::string, IdData>& v) {
  const auto& [name, d] = v;
  SimulateOptions so;
  so.initial = validation_initial_condition(m);
  Simulation s;
  try {
    s = simulate(m, d, so);
  } catch (const InvalidArgument& e) {
    throw UsageError(std::string("--validate: ") + e.what());
  }
  std::printf("\nvalidation on %s (%d samples, initial state: %s):", name.c_str(), d.size(),
              so.initial == InitialCondition::Estimated ? "the one that fits them best" : to_string(so.initial));
  if (!s.ok()) {
    std::printf(" %s\n", s.problem.c_str());
    return;
  }
  for (int j = 0; j < d.ny(); ++j)
    std::printf("%s fit %s %%", d.ny() > 1 ? ("  " + channel_name(d.output_names(), j)).c_str() : "",
                fit_percent_text(fit_percent(d.y().col(j), s.y.col(j))).c_str());
  std::printf("\n");
}

// Print, write the JSON file and the HTML report if asked, and map usability to the exit code.
template <class M>
int finish(const Result<M>& r, const std::string& method, const IdData& d, const FitArgs& a, const Settings& settings,
           std::vector<std::pair<std::string, IdData>> more_records = {}) {
  if (BatchOutcome* b = batch_outcome()) {  // ctid batch: the row is written by the batch
    b->result = to_any(r);
    b->method = method;
    return r.usable() ? kOk : kNotUsable;
  }
  print_result(r, method, d);
  warn_offsets(a, d);
  if (a.validation) {
    print_validation(to_any(r).model, *a.validation);
    more_records.insert(more_records.begin(), {"validation, " + a.validation->first, a.validation->second});
  }
  if (!a.json.empty()) {
    write_result_json(a.json, r, method);
    std::printf("wrote %s\n", a.json.c_str());
  }
  write_report(a.report, d, r, method, settings, a.paths.empty() ? a.data.path : a.paths.front(), more_records,
               a.validation ? std::optional(validation_initial_condition(to_any(r).model)) : std::nullopt);
  if (!r.usable()) {
    std::fprintf(stderr, "ctid: the estimate is not usable: %s\n", r.why_not_usable().c_str());
    return kNotUsable;
  }
  return kOk;
}

// Bad orders, options or data for the method are usage errors of the command line (exit 2).
template <class F>
auto call_library(F&& f) {
  try {
    return f();
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
}

// One input, one output: [nb nf nk] from the flags (nb defaults to nf).
TfOrders siso_orders(const FitArgs& a) {
  const int nf = a.nf[0];
  return {a.nb.empty() ? nf : a.nb[0], nf, a.nk[0]};
}

// A single-input transfer-function estimator: its options from the table (--delay is estimate_delay), the fit,
// the output.
template <class O>
int run_tf(const FitArgs& a, const IdData& d, Result<TransferFunction> (*estimator)(const IdData&, const TfOrders&, const O&)) {
  O o;
  if constexpr (requires { o.estimate_delay; }) o.estimate_delay = a.delay;
  apply_sets(a.method, a.sets, o);
  const TfOrders orders = siso_orders(a);
  // The estimator checks the orders itself (SRIVC and tfest take biproper models, nb = nf + 1; LSSVF does not).
  const Result<TransferFunction> r = call_library([&] { return estimator(d, orders, o); });
  return finish(r, a.method, d, a, settings_of(o));
}

// srivc-auto (the default without --method and orders): the first line says which structure it chose and why.
int run_srivc_auto(const FitArgs& a, const IdData& d) {
  SrivcAutoOptions o;
  apply_sets("srivc_auto", a.sets, o);
  const Result<TransferFunction> r = call_library([&] { return srivc_auto(d, o); });
  const Eigen::VectorXd& nb = r.diagnostics.get(diagnostic::structure_nb);
  const TransferFunction& m = r.model;
  char delay[64] = "";
  if (m.io_delay() > 0) std::snprintf(delay, sizeof delay, " and an input delay of %.3g s", m.io_delay());
  if (!batch_outcome())
    std::printf("srivc-auto chose SRIVC with nb = %d, nf = %d%s: the least BIC of %d structures (nf = 1..%d, nb = 1..nf%s)\n",
              m.num().degree() + 1, m.den().degree(), delay, static_cast<int>(nb.size()), o.nf_max,
              o.try_delay ? ", each with and without a delay" : "");
  return finish(r, "srivc_auto", d, a, settings_of(o));
}

std::vector<std::pair<std::string, IdData>> more_records_of(const FitArgs& a, const std::vector<IdData>& ds);
void print_experiments(const FitArgs& a, const std::vector<IdData>& ds);

// Closed-loop SRIVC on one record or several (jointly, one controller): each record's reference column is loaded
// with its data and split off.
int run_closed_loop(const FitArgs& a) {
  if (a.method != "srivc") throw UsageError("--closed-loop-controller needs --method srivc");
  if (a.reference.empty()) throw UsageError("--closed-loop-controller needs --reference COLUMN");
  if (a.data.inputs.size() != 1) throw UsageError("closed-loop identification needs exactly one --input (the plant input)");
  LinearModel c;
  try {
    c = read_model_json(a.controller);
  } catch (const FileError& e) {
    throw InputError(e.what());
  }
  if (!std::holds_alternative<TransferFunction>(c)) throw UsageError(a.controller + ": the controller must be a transfer_function");
  DataArgs da = a.data;
  da.inputs.push_back(a.reference);
  std::vector<IdData> ds;
  std::vector<Eigen::VectorXd> refs;
  ClosedLoopOptions o;
  for (const IdData& both : da.load_each(a.paths, true)) {
    ds.push_back(both.select({0}, {0}));
    refs.push_back(both.u().col(1));
    o.reference_intersample = both.intersample(1);
  }
  o.controller = std::get<TransferFunction>(c);
  apply_sets("srivc_closed_loop", a.sets, o);
  const Result<TransferFunction> r = call_library([&] { return srivc_closed_loop(ds, refs, siso_orders(a), o); });
  print_experiments(a, ds);
  return finish(r, "clsrivc", ds[0], a, settings_of(o), more_records_of(a, ds));
}

// Frequency-response data: columns w, re, im (G) or the spectra U and Y.
int run_frequency(const FitArgs& a) {
  if (a.method != "tfest" && a.method != "oe" && a.method != "srivc" && a.method != "lssvf")
    throw UsageError("frequency data are fitted with --method tfest (Sanathanan-Koerner + output error) or --method "
                     "lssvf (Johansson's criterion in the frequency domain, RJ 45)");
  FrequencyData fd;
  try {
    const CsvTable t = read_csv(a.data.path);
    auto col = [&](const std::string& name) { return Eigen::VectorXd(t.values.col(t.column(name))); };
    const Eigen::VectorXd w = col(a.w);
    try {
      if (!a.u_re.empty() || !a.y_re.empty()) {
        if (a.u_re.empty() || a.u_im.empty() || a.y_re.empty() || a.y_im.empty())
          throw UsageError("spectra need all of --u-re --u-im --y-re --y-im");
        const Eigen::VectorXcd U = col(a.u_re).cast<std::complex<double>>() + std::complex<double>(0, 1) * col(a.u_im);
        const Eigen::VectorXcd Y = col(a.y_re).cast<std::complex<double>>() + std::complex<double>(0, 1) * col(a.y_im);
        fd = FrequencyData::from_spectra(w, U, Y);
      } else {
        fd = FrequencyData(w, col(a.re).cast<std::complex<double>>() + std::complex<double>(0, 1) * col(a.im));
      }
    } catch (const InvalidArgument& e) {
      throw InputError(a.data.path + ": " + e.what());
    }
  } catch (const FileError& e) {
    throw InputError(e.what());
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  const bool svf = a.method == "lssvf";
  if (svf && a.delay) throw UsageError("--delay: the frequency-domain lssvf fits no delay (use --method tfest)");
  FrequencyFitOptions o;
  LssvfOptions so;
  o.estimate_delay = a.delay;
  if (svf) apply_sets("lssvf", a.sets, so);
  else apply_sets("tf_from_frequency", a.sets, o);
  const Result<TransferFunction> r = call_library(
      [&] { return svf ? lssvf(fd, siso_orders(a), so) : tf_from_frequency(fd, siso_orders(a), o); });
  std::printf("method: %s (frequency data)   frequencies: %d   from %.4g to %.4g rad/s\n", svf ? "lssvf" : "tfest",
              fd.size(), fd.w()(0), fd.w()(fd.size() - 1));
  std::printf("model:  G(s) = %s\n", r.model.to_string(6).c_str());
  for (int i = 0; i < r.parameters.size(); ++i)
    std::printf("  %-5s = %14.6g +- %-12.4g\n", r.parameters.names[i].c_str(), r.parameters.values(i), r.parameters.std(i));
  std::printf("fit (complex response): %s %%   termination: %s\n", fit_percent_text(r.fit.fit_percent).c_str(), to_string(r.summary.termination));
  if (!a.json.empty()) {
    write_result_json(a.json, r, svf ? "lssvf-frequency" : "tfest-frequency");
    std::printf("wrote %s\n", a.json.c_str());
  }
  if (!r.usable()) std::fprintf(stderr, "ctid: the estimate is not usable: %s\n", r.why_not_usable().c_str());
  return r.usable() ? kOk : kNotUsable;
}

void write_fsf_responses(const std::string& prefix, const FsfModel& f) {
  const int K = 501;
  Eigen::MatrixXd tm(K, 5);
  for (int i = 0; i < K; ++i) {
    const Eigen::VectorXd t{{f.T() * i / (K - 1)}};
    tm.row(i) << t(0), f.step_response(t)(0), f.step_response_std(t)(0), f.impulse_response(t)(0),
        f.impulse_response_std(t)(0);
  }
  write_csv(prefix + "_time.csv", {"t", "step", "step_std", "impulse", "impulse_std"}, tm);
  Eigen::VectorXd w(200);
  const double wmax = std::min(3.14159 / f.delta(), 10.0 * f.m() * f.omega() + f.omega());
  for (int i = 0; i < 200; ++i) w(i) = f.omega() * 0.01 * std::pow(wmax / (0.01 * f.omega()), i / 199.0);
  const Eigen::VectorXcd g = f.frequency_response(w), gs = f.frequency_response_std(w);
  Eigen::MatrixXd fm(200, 7);
  for (int i = 0; i < 200; ++i)
    fm.row(i) << w(i), g(i).real(), g(i).imag(), gs(i).real(), gs(i).imag(), std::abs(g(i)),
        std::arg(g(i)) * 180.0 / 3.14159265358979;
  write_csv(prefix + "_freq.csv", {"w", "re", "im", "re_std", "im_std", "mag", "phase_deg"}, fm);
  std::printf("wrote %s_time.csv and %s_freq.csv\n", prefix.c_str(), prefix.c_str());
}

int run_fsf(const FitArgs& a, const IdData& d) {
  FsfOptions o;
  apply_sets("fsf", a.sets, o);
  const Result<FsfModel> r = call_library([&] { return fsf(d, o); });
  const int code = finish(r, "fsf", d, a, settings_of(o));
  if (!a.responses.empty()) write_fsf_responses(a.responses, r.model);
  return code;
}

int run_physical_records(const FitArgs& a, const std::vector<IdData>& ds);
int run_physical(const FitArgs& a, const IdData& d) { return run_physical_records(a, {d}); }

// Physical parameters on one record, or on several by the raw route (their output errors stacked).
int run_physical_records(const FitArgs& a, const std::vector<IdData>& ds) {
  const IdData& d = ds.front();
  if (ds.size() > 1 && a.via != "raw")
    throw UsageError(detail::format("{} DATA files: the physical fit of several experiments is by --via raw (the FSF "
                                    "routes compress one record)",
                                    ds.size()));
  if (a.model_expr.empty()) throw UsageError("--method physical needs --model EXPRESSION (e.g. \"k1/(s^2-k2)\")");
  std::vector<PhysicalParameter> ps;
  std::vector<std::string> names;
  for (const auto& p : a.params) {
    const auto eq = p.find('=');
    if (eq == std::string::npos || eq == 0) throw UsageError("--param needs NAME=INITIAL (got '" + p + "')");
    PhysicalParameter q;
    q.name = p.substr(0, eq);
    q.initial = to_double("--param " + q.name, p.substr(eq + 1));
    ps.push_back(q);
    names.push_back(q.name);
  }
  // The parser reports a syntax error or an undeclared symbol with its column; a --param the
  // expression does not use is reported as well.
  std::vector<std::string> symbols;
  try {
    PhysicalModel check(a.model_expr, names);
    symbols = PhysicalModel::symbols(a.model_expr);
  } catch (const InvalidArgument& e) {
    throw UsageError(std::string(e.what()) + "; declare every parameter with --param NAME=INITIAL");
  }
  for (const auto& n : names) {
    bool used = false;
    for (const auto& s : symbols) used = used || n == s;
    if (!used) throw UsageError(detail::format("--param {}: '{}' does not appear in the model \"{}\"", n, n, a.model_expr));
  }
  // fixed.NAME=VALUE and bounds.NAME=LOWER,UPPER are PhysicalFitOptions settings (the vocabulary of oe).
  FsfOptions fo;
  PhysicalFitOptions po;
  apply_sets("physical", a.sets, fo, po);
  if (a.via == "raw")
    for (const auto& s : a.sets)
      for (const char* k : {"T=", "n=", "b=", "weights=", "step_points="})
        if (s.rfind(k, 0) == 0)
          throw UsageError("--set " + s + ": --via raw fits the record itself (its settings: a, unstable, max_iterations, "
                           "tolerance, fixed.NAME, bounds.NAME)");
  Result<TransferFunction> r = call_library([&] {
    const PhysicalModel model(a.model_expr, names);
    if (a.via == "raw") {
      CTID_REQUIRE_OPTION(!fo.unstable || fo.a > 0, "physical: the plant is declared unstable: give a window a > 0 (got a = {})",
                          fo.a);
      return fit_physical_raw(model, ps, ds, fo.a, po);
    }
    const Result<FsfModel> c = fsf(d, fo);
    Result<TransferFunction> q =
        a.via == "frequency" ? fit_physical_frequency(model, ps, c.model, po, &d) : fit_physical_step(model, ps, c.model, po, &d);
    for (const auto& w : c.diagnostics.warnings) q.diagnostics.warnings.push_back("fsf: " + w);
    for (const auto& w : c.diagnostics.choices) q.diagnostics.choices.push_back("fsf: " + w);
    return q;
  });
  Settings settings = a.via == "raw" ? Settings{{"a", options_detail::format_real(fo.a)}} : settings_of(fo);
  for (auto& s : settings_of(po)) settings.push_back(s);
  return finish(r, "physical-" + a.via, d, a, settings, more_records_of(a, ds));
}

// A grey-box model file fitted to one record or several (one parameter set, an initial state per record). The
// model's input and output names are the data columns unless --input/--output map them (in the model's order).
int run_greybox(const FitArgs& a) {
  if (a.model_expr.empty()) throw UsageError("--method greybox needs --model FILE.json (the grey-box model file)");
  if (a.frequency) throw UsageError("--method greybox fits time-domain records (not --frequency)");
  GreyboxModel model;
  try {
    model = read_greybox_json(a.model_expr);
  } catch (const FileError& e) {
    throw InputError(e.what());
  }
  const DataArgs da = columns_of(a.data, model);
  if (static_cast<int>(da.inputs.size()) != model.nu() || static_cast<int>(da.outputs.size()) != model.ny())
    throw UsageError(detail::format("--input/--output name {} and {} columns; the model has {} inputs ({}) and {} outputs ({})",
                                    da.inputs.size(), da.outputs.size(), model.nu(),
                                    options_detail::format_names(model.spec().inputs), model.ny(),
                                    options_detail::format_names(model.output_names())));
  const std::vector<IdData> ds = a.paths.size() > 1 ? da.load_each(a.paths, true) : std::vector<IdData>{da.load(true)};
  GreyboxOptions o;
  apply_sets("greybox", a.sets, o);
  const Result<GreyboxModel> r = call_library([&] { return greybox(ds, model, o); });
  print_experiments(a, ds);
  return finish(r, "greybox", ds.front(), a, settings_of(o), more_records_of(a, ds));
}

// El-Shafey: modal functions (modal_fit) on one record, or on several with piecewise-constant inputs (jointly).
// Besides the table's settings: shift_samples (the shifts in samples) and frequencies=w1,.. (a generated input:
// the generator fitted to the measured input); --nk is the input delay.
int run_modal_records(const FitArgs& a, const std::vector<IdData>& ds);
int run_modal(const FitArgs& a, const IdData& d) { return run_modal_records(a, {d}); }

int run_modal_records(const FitArgs& a, const std::vector<IdData>& ds) {
  const IdData& d = ds.front();
  if (d.nu() != 1) throw UsageError(detail::format("modal needs one input (selected {})", d.nu()));
  if (a.nf.size() != 1 || a.nb.size() > 1 || a.nk.size() != 1) throw UsageError("modal: one --nb, --nf and --nk value");
  const int n = a.nf[0], nb = a.nb.empty() ? n : a.nb[0], nk = a.nk[0];
  if (nk < 0) throw UsageError("--nk must be >= 0");
  std::map<std::string, std::string> own;
  ModalOptions o = modal_options("modal", a.sets, d.ts(), {"frequencies"}, own);
  if (o.shifts.size() == 0) o.order = n;  // the shifts are chosen (and stated)
  else if (o.shifts.size() != n)
    throw UsageError(detail::format("modal needs one shift per pole: --set shifts=T1,..,T{} (s) or shift_samples=S1,..,S{} "
                                    "(samples; got {} for --nf {}), or none (chosen automatically)",
                                    n, n, o.shifts.size(), n));
  if (nk > 0) {
    if (o.delay > 0) throw UsageError("give the input delay once: --nk (samples) or --set delay (s)");
    o.delay = nk * d.ts();
  }
  std::vector<double> frequencies;
  if (own.count("frequencies")) frequencies = call_library([&] { return options_detail::parse_reals("modal", "frequencies", own.at("frequencies")); });
  const Result<TransferFunction> r = call_library([&] {
    if (frequencies.empty()) return modal_fit(ds, nb, o);
    const InputGenerator g = generator_fitted_to_input(frequencies, d);
    return modal_fit(ds, nb, o, &g);
  });
  print_experiments(a, ds);
  Settings settings = settings_of(o);
  if (!frequencies.empty()) settings.emplace_back("frequencies", own.at("frequencies"));
  return finish(r, "modal", d, a, settings, more_records_of(a, ds));
}

// Records 2.. of several DATA files, named by their files (for the report's section per record).
std::vector<std::pair<std::string, IdData>> more_records_of(const FitArgs& a, const std::vector<IdData>& ds) {
  std::vector<std::pair<std::string, IdData>> more;
  for (std::size_t e = 1; e < ds.size(); ++e) more.emplace_back(a.paths[e], ds[e]);
  return more;
}

// Several DATA files: several experiments of one system, the same columns in each, fitted jointly.
// "experiments: 2 (a.csv: 1000 samples, b.csv: 800 samples)" before a joint fit's result (nothing for one record).
void print_experiments(const FitArgs& a, const std::vector<IdData>& ds) {
  if (ds.size() < 2) return;
  std::printf("experiments: %zu (", ds.size());
  for (std::size_t e = 0; e < ds.size(); ++e)
    std::printf("%s%s: %d samples", e ? ", " : "", a.paths[e].c_str(), ds[e].size());
  std::printf(")\n");
}

template <class O>
int fit_experiments(const FitArgs& a, const std::vector<IdData>& ds,
                    Result<TransferFunction> (*estimator)(const std::vector<IdData>&, const TfOrders&, const O&)) {
  O o;
  if constexpr (requires { o.estimate_delay; }) o.estimate_delay = a.delay;
  apply_sets(a.method, a.sets, o);
  const Result<TransferFunction> r = call_library([&] {
    const TfOrders orders = siso_orders(a);
    return estimator(ds, orders, o);
  });
  print_experiments(a, ds);
  // The printed samples are those of the first record; the fit is over all of them; the report shows each record.
  return finish(r, a.method, ds[0], a, settings_of(o), more_records_of(a, ds));
}

// Several inputs: MISO SRIVC on one record or several (jointly). Orders per input: one value for every input, or
// one per input.
int run_miso(const FitArgs& a, const std::vector<IdData>& ds) {
  const int nu = ds.front().nu();
  if (a.method == "srivc-auto") {
    if (ds.size() > 1) throw UsageError("srivc-auto fits one record; several records: --method srivc with --nb/--nf");
    if (a.delay) throw UsageError("--delay: srivc-auto searches the delays itself");
    SrivcAutoOptions o;
    apply_sets("srivc_auto", a.sets, o);
    const Result<MisoModel> r = call_library([&] { return srivc_auto_miso(ds.front(), o); });
    if (!batch_outcome()) std::printf("srivc-auto chose, per input:");
    for (int i = 0; i < nu && !batch_outcome(); ++i) {
      const TransferFunction& g = r.model.channels[static_cast<size_t>(i)];
      char delay[48] = "";
      if (g.io_delay() > 0) std::snprintf(delay, sizeof delay, ", delay %.3g s", g.io_delay());
      std::printf("%s %s nb = %d, nf = %d%s", i ? ";" : "", channel_name(ds.front().input_names(), i).c_str(),
                  g.num().degree() + 1, g.den().degree(), delay);
    }
    if (!batch_outcome())
      std::printf(" (each input alone, then each channel on the output less the others; the least BIC)\n");
    return finish(r, "srivc_auto", ds.front(), a, settings_of(o));
  }
  auto per_input = [&](const std::vector<int>& v, const char* flag, int i) {
    if (v.size() != 1 && static_cast<int>(v.size()) != nu)
      throw UsageError(detail::format("{} has {} values for {} inputs (give one value, or one per input)", flag, v.size(), nu));
    return v.size() == 1 ? v[0] : v[i];
  };
  std::vector<TfOrders> all;
  for (int i = 0; i < nu; ++i) {
    const int nf_i = per_input(a.nf, "--nf", i);
    all.push_back({a.nb.empty() ? nf_i : per_input(a.nb, "--nb", i), nf_i, per_input(a.nk, "--nk", i)});
  }
  if (a.method != "srivc")
    throw UsageError(detail::format("{} estimates single-input models; use --method srivc for {} inputs", a.method, nu));
  if (a.delay) throw UsageError("--delay is available for single-input models");
  SrivcMisoOptions o;
  apply_sets("srivc_miso", a.sets, o);
  const Result<MisoModel> r = call_library([&] { return srivc_miso(ds, all, o); });
  return finish(r, "srivc", ds.front(), a, settings_of(o), more_records_of(a, ds));
}

int run_ssest(const FitArgs& a, const std::vector<IdData>& ds);

int run_experiments(const FitArgs& a) {
  if (a.method == "ssest") {
    if (a.frequency) throw UsageError("several DATA files: time-domain data only (not --frequency)");
    return run_ssest(a, a.data.load_each(a.paths, true));
  }
  if (a.method != "srivc" && a.method != "oe" && a.method != "tfest" && a.method != "lssvf" && a.method != "ivsvf" &&
      a.method != "rls-svf" && a.method != "narx" && a.method != "kia" && a.method != "physical" && a.method != "modal")
    throw UsageError(detail::format("{} DATA files are several experiments: fitted jointly by --method srivc, oe, tfest, "
                                    "lssvf, ivsvf, rls-svf, narx, kia, modal, ssest, physical --via raw or srivc with "
                                    "--closed-loop-controller (got {}; the other estimators take one record so far)",
                                    a.paths.size(), a.method));
  if (a.frequency) throw UsageError("several DATA files: time-domain data only (not --frequency)");
  const std::vector<IdData> ds = a.data.load_each(a.paths, true);
  if (ds[0].ny() != 1)
    throw UsageError(detail::format("several experiments: one --output (selected {})", ds[0].ny()));
  if (ds[0].nu() > 1) return run_miso(a, ds);
  if (a.method == "physical") return run_physical_records(a, ds);
  if (a.method == "modal") return run_modal_records(a, ds);
  if (a.method == "narx" || a.method == "kia")
    return run_narx_or_kia(a.method, ds, a.sets, a.narx, a.json, a.report, more_records_of(a, ds));
  if (a.method == "srivc") return fit_experiments<SrivcOptions>(a, ds, &srivc);
  if (a.method == "lssvf") return fit_experiments<LssvfOptions>(a, ds, &lssvf);
  if (a.method == "ivsvf") return fit_experiments<IvsvfOptions>(a, ds, &ivsvf);
  if (a.method == "rls-svf") return fit_experiments<RlsSvfOptions>(a, ds, &rls_svf);
  using Joint = Result<TransferFunction> (*)(const std::vector<IdData>&, const TfOrders&, const OeOptions&);
  return fit_experiments<OeOptions>(a, ds, a.method == "oe" ? static_cast<Joint>(&oe) : static_cast<Joint>(&tfest));
}

// --nx N or A:B: the state dimension (and the upper end of an order range), 0 when not given.
std::pair<int, int> nx_of(const FitArgs& a) {
  if (a.nx.empty()) return {0, 0};
  const auto colon = a.nx.find(':');
  auto number = [&](const std::string& t) {
    if (t.empty() || t.find_first_not_of("0123456789") != std::string::npos || t.size() > 4 || std::stoi(t) < 1)
      throw UsageError("--nx must be a state dimension N >= 1 or a range A:B (got '" + a.nx + "')");
    return std::stoi(t);
  };
  if (colon == std::string::npos) return {number(a.nx), 0};
  const int lo = number(a.nx.substr(0, colon)), hi = number(a.nx.substr(colon + 1));
  if (hi < lo) throw UsageError("--nx A:B needs A <= B (got '" + a.nx + "')");
  return {lo, hi};
}

// Subspace: any number of inputs and outputs, one record.
int run_subspace(const FitArgs& a, const IdData& d) {
  SubspaceOptions o;
  apply_sets("subspace", a.sets, o);
  const auto [nx, nx_max] = nx_of(a);
  if (nx_max > 0) throw UsageError("--nx A:B (an order range) is for --method ssest; subspace takes one N (or none: "
                                   "its singular values choose)");
  if (nx > 0) o.nx = nx;
  const Result<StateSpace> r = call_library([&] { return subspace(d, o); });
  return finish(r, a.method, d, a, settings_of(o));
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

// ssest: any number of inputs and outputs, one or several records; the subspace start or --initial MODEL.json.
int run_ssest(const FitArgs& a, const std::vector<IdData>& ds) {
  SsestOptions o;
  apply_sets("ssest", a.sets, o);
  const auto [nx, nx_max] = nx_of(a);
  if (nx > 0) o.nx = nx;
  if (nx_max > 0) o.nx_max = nx_max;
  const Result<StateSpace> r =
      call_library([&] { return a.initial.empty() ? ssest(ds, o) : ssest(ds, initial_state_space(a), o); });
  return finish(r, a.method, ds.front(), a, settings_of(o));
}

// --period N: periodic records (one per input) -> their FRF matrix with variances -> subspace or ssest on it.
int run_periodic(const FitArgs& a) {
  if (!a.report.empty()) throw UsageError("--report needs time-domain records (not --period: a fit to frequency data)");
  const std::vector<IdData> ds = a.paths.size() > 1 ? a.data.load_each(a.paths, true) : std::vector<IdData>{a.data.load(true)};
  const FrequencyData fd = call_library([&] { return frf_from_periodic(ds, a.period, a.skip, a.excited); });
  const int periods = ds.front().size() / a.period - a.skip;
  std::printf("FRF matrix of the periodic records: %d excited frequencies from %.6g to %.6g Hz, %d period(s) of %d "
              "samples averaged (%d skipped)\n", fd.size(), fd.w()(0) / (2 * std::numbers::pi),
              fd.w()(fd.size() - 1) / (2 * std::numbers::pi), periods, a.period, a.skip);
  const auto [nx, nx_max] = nx_of(a);
  if (a.method == "subspace") {
    if (nx_max > 0) throw UsageError("--nx A:B (an order range) is for --method ssest; subspace takes one N");
    SubspaceOptions o;
    apply_sets("subspace", a.sets, o);
    if (nx > 0) o.nx = nx;
    const Result<StateSpace> r = call_library([&] { return subspace(fd, o); });
    return finish(r, a.method, ds.front(), a, settings_of(o));
  }
  SsestOptions o;
  apply_sets("ssest", a.sets, o);
  if (nx > 0) o.nx = nx;
  if (nx_max > 0) o.nx_max = nx_max;
  const Result<StateSpace> r = call_library([&] {
    return a.initial.empty() ? ssest(fd, o) : ssest(fd, initial_state_space(a), o);
  });
  return finish(r, a.method, ds.front(), a, settings_of(o));
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
  if (a.data.detrend != "none") d = d.remove_trend(trend);
  std::string name = v.path;
  if (!v.samples.empty()) name += detail::format(" rows {}..{}", rows.first, rows.second);
  return {name, d};
}

int run(FitArgs a) {
  reject_flags_that_do_not_apply(a);
  std::vector<std::string> inputs = a.paths;
  inputs.insert(inputs.end(), {a.narx, a.controller, a.initial, a.validate, a.method == "greybox" ? a.model_expr : ""});
  check_outputs({a.json, a.report, a.responses.empty() ? "" : a.responses + "_time.csv",
                 a.responses.empty() ? "" : a.responses + "_freq.csv"},
                inputs, a.force);
  if (!a.controller.empty()) return run_closed_loop(a);
  if (a.method == "greybox") return run_greybox(a);
  if (a.period > 0) return run_periodic(a);
  if (a.paths.size() > 1) return run_experiments(a);
  if (a.frequency && !a.report.empty()) throw UsageError("--report needs time-domain data (not --frequency)");
  if (a.frequency) return run_frequency(a);
  TrendInfo trend;
  const IdData d = a.data.load(true, &trend);
  if (!a.validate.empty() || !a.validate_samples.empty()) a.validation = validation_record(a, trend);
  // A constant channel carries no information on the dynamics (the library's check, made before any other).
  call_library([&] {
    require_io_data(d, a.method.c_str(), -1, -1);
    return 0;
  });
  if (a.method == "subspace") return run_subspace(a, d);
  if (a.method == "ssest") return run_ssest(a, {d});
  if (d.ny() != 1)
    throw UsageError(detail::format("{} estimates single-output models (selected {} outputs; --method ssest and "
                                    "subspace take several)", a.method, d.ny()));
  if (d.nu() > 1) return run_miso(a, {d});
  return fit_methods().at(a.method).run(a, d);
}

const std::map<std::string, FitMethod>& fit_methods() {
  static const std::map<std::string, FitMethod> m = {
      {"srivc-auto", {{"srivc_auto"}, run_srivc_auto}},
      {"lssvf", {{"lssvf"}, [](const FitArgs& a, const IdData& d) { return run_tf(a, d, &lssvf); }}},
      {"ivsvf", {{"ivsvf"}, [](const FitArgs& a, const IdData& d) { return run_tf(a, d, &ivsvf); }}},
      {"rls-svf", {{"rls_svf"}, [](const FitArgs& a, const IdData& d) { return run_tf(a, d, &rls_svf); }}},
      {"srivc",
       {{"srivc", "srivc_miso", "srivc_closed_loop"}, [](const FitArgs& a, const IdData& d) { return run_tf(a, d, &srivc); }}},
      {"oe", {{"oe", "tf_from_frequency"}, [](const FitArgs& a, const IdData& d) { return run_tf(a, d, &oe); }}},
      {"tfest", {{"tfest", "tf_from_frequency"}, [](const FitArgs& a, const IdData& d) { return run_tf(a, d, &tfest); }}},
      {"fsf", {{"fsf"}, run_fsf}},
      {"physical", {{"physical"}, run_physical}},
      {"greybox", {{"greybox"}, [](const FitArgs& a, const IdData&) { return run_greybox(a); }}},
      {"modal", {{"modal"}, run_modal}},
      {"subspace", {{"subspace"}, run_subspace}},
      {"ssest", {{"ssest"}, [](const FitArgs& a, const IdData& d) { return run_ssest(a, {d}); }}},
      {"narx",
       {{"narx"},
        [](const FitArgs& a, const IdData& d) { return run_narx_or_kia(a.method, {d}, a.sets, a.narx, a.json, a.report, {}); }}},
      {"kia",
       {{"kia", "narx"},
        [](const FitArgs& a, const IdData& d) { return run_narx_or_kia(a.method, {d}, a.sets, a.narx, a.json, a.report, {}); }}},
  };
  return m;
}

}  // namespace


namespace {
std::shared_ptr<FitArgs> g_fit_args;  // read by fit_method_help after a --help
}  // namespace

std::string fit_method_help(const CLI::App& fit) {
  if (!g_fit_args || fit.count("--method") == 0) return "";
  const auto it = fit_methods().find(g_fit_args->method);
  if (it == fit_methods().end()) return "";
  if (it->second.library.empty())
    return "\n" + g_fit_args->method + ": its settings are listed under --set above (not yet in a settings table).\n";
  std::string out;
  static const std::map<std::string, std::string> when = {
      {"srivc_miso", " (several --input columns)"},
      {"srivc_closed_loop", " (with --closed-loop-controller)"},
      {"tf_from_frequency", " (with --frequency)"}};
  for (const auto& name : it->second.library) {
    const MethodInfo& m = method_info(name);
    const std::string note = when.count(name)                             ? when.at(name)
                             : name == "narx" && g_fit_args->method == "kia" ? " (the NARX model fitted first, unless --narx FILE)"
                                                                            : "";
    out += "\n" + m.name + ": " + m.summary + note + "\n" + settings_help(m);
  }
  return out;
}

namespace {
// The options of ctid fit on `app`; after parsing, resolve_fit_args fills the defaults that depend on what was given.
std::shared_ptr<FitArgs> add_fit_options(CLI::App& app) {
  auto a = std::make_shared<FitArgs>();
  app.add_option("DATA", a->paths,
                 "CSV/.dat table (header row optional) or .mat file; several files are several experiments of one system, "
                 "fitted jointly (srivc, oe, tfest, lssvf, ivsvf, rls-svf, narx, kia, modal, physical --via raw, greybox; the same columns in each)")
      ->required();
  std::vector<std::string> names;
  for (const auto& [name, m] : fit_methods()) names.push_back(name);
  app.add_option("--method", a->method,
                 "Estimator: srivc-auto, srivc, tfest, oe, lssvf, ivsvf, rls-svf, fsf, physical, greybox, modal, narx, "
                 "kia, subspace or ssest (with --help: its settings). Default: srivc-auto (the orders and a delay "
                 "chosen by BIC, means removed) without --nb/--nf/--nk, srivc with them")
      ->check(CLI::IsMember(names));
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
  app.add_option("--w", a->w, "Frequency column (rad/s) of frequency data")->capture_default_str();
  app.add_option("--re", a->re, "Real part of G(jw)")->capture_default_str();
  app.add_option("--im", a->im, "Imaginary part of G(jw)")->capture_default_str();
  app.add_option("--u-re", a->u_re, "Input spectrum, real part");
  app.add_option("--u-im", a->u_im, "Input spectrum, imaginary part");
  app.add_option("--y-re", a->y_re, "Output spectrum, real part");
  app.add_option("--y-im", a->y_im, "Output spectrum, imaginary part");
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
  app.add_option("--nx", a->nx, "subspace, ssest: state dimension N, or ssest: a range A:B (the least BIC is kept)");
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
  if (a.method.empty())
    a.method = a.given.count("nb") || a.given.count("nf") || a.given.count("nk") ? "srivc" : "srivc-auto";
  // srivc-auto removes the means unless told otherwise (said on stderr by the loader).
  if (a.method == "srivc-auto" && !a.given.count("detrend")) {
    a.data.detrend = "mean";
    a.data.announce_means = true;
  }
}
}  // namespace

void setup_fit(CLI::App& app) {
  auto a = add_fit_options(app);
  g_fit_args = a;
  app.callback([a, &app] {
    resolve_fit_args(*a, app);
    g_run = [a] { return run(*a); };
  });
}

void setup_batch(CLI::App& app) {
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
  app.callback([a, job, &app] {
    resolve_fit_args(*a, app);
    job->patterns = a->paths;
    job->method = a->method;
    job->force = a->force;
    g_run = [a, job] {
      for (const char* f : {"json", "report", "validate", "validate-samples", "responses", "frequency", "period"})
        if (a->given.count(f))
          throw UsageError("--" + std::string(f) + " is an option of ctid fit on one record, not of ctid batch (one "
                           "row per record in --out)");
      reject_flags_that_do_not_apply(*a);  // once, before any record
      job->fit_one = [a](const std::string& path) {
        FitArgs b = *a;
        b.paths = {path};
        b.data.path = path;
        return run(std::move(b));
      };
      return run_batch(*job);
    };
  });
}

int run_fit(std::vector<std::string> args) {
  CLI::App app{"ctid fit"};
  const auto a = add_fit_options(app);
  std::reverse(args.begin(), args.end());  // CLI11 parses a vector from its back
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    throw UsageError(e.what());
  }
  resolve_fit_args(*a, app);
  return run(*a);
}

}  // namespace ctid::cli
