// ctid fit DATA --method lssvf|ivsvf|rls-svf ...
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <set>
#include <type_traits>

#include "common.hpp"

namespace ctid::cli {
extern std::function<int()> g_run;

namespace {

struct FitArgs {
  DataArgs data;
  std::string method = "lssvf";
  std::vector<int> nb, nf{1}, nk{0};
  std::vector<std::string> sets;
  bool delay = false;
  std::string controller, reference;
  bool frequency = false;
  std::string model_expr, via = "fsf", responses;
  std::vector<std::string> params;
  std::string w = "w", re = "re", im = "im", u_re, u_im, y_re, y_im;
  std::string json, narx, report;
  bool force = false;
  std::set<std::string> given;  ///< long names of the options given on the command line
};

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
  for (const char* f : {"model", "param"})
    if (has(f) && m != "physical") refuse(f, "describes the model of --method physical (got " + m + ")");
  if (has("delay") && !tf_data) refuse("delay", "(delay estimation) needs --method srivc, oe or tfest (got " + m + ")");
  for (const char* f : {"nb", "nf", "nk"})
    if (has(f) && (m == "narx" || m == "kia" || m == "fsf" || m == "physical"))
      refuse(f, "sets transfer-function orders; " + m + " has its own structure settings (--set)");
  if (!a.frequency)
    for (const char* f : {"w", "re", "im", "u-re", "u-im", "y-re", "y-im"})
      if (has(f)) refuse(f, "names a column of frequency data: it needs --frequency");
}

// Apply --set keys to LSSVF options; consumed keys are erased.
void apply_svf_sets(std::map<std::string, std::string>& s, LssvfOptions& o) {
  consume_sets(s, [&](const std::string& k, const std::string& v) {
    if (k == "tau") o.tau = to_double(k, v);
    else if (k == "alpha") o.alpha = to_double(k, v);
    else if (k == "transient") o.transient_time = to_double(k, v);
    else if (k == "tau_grid") o.tau_grid_size = to_int(k, v);
    else if (k == "weights") {
      if (v == "riemann") o.weights = SvfWeights::Riemann;
      else if (v == "trapezoidal") o.weights = SvfWeights::Trapezoidal;
      else throw UsageError("--set weights: use riemann or trapezoidal (got '" + v + "')");
    } else if (k.rfind("fix.", 0) == 0) o.fixed[k.substr(4)] = to_double(k, v);
    else return false;
    return true;
  });
}

// Print, write the JSON file and the HTML report if asked, and map usability to the exit code.
template <class M>
int finish(const Result<M>& r, const std::string& method, const IdData& d, const FitArgs& a) {
  print_result(r, method, d);
  if (!a.json.empty()) {
    write_result_json(a.json, r, method);
    std::printf("wrote %s\n", a.json.c_str());
  }
  write_report(a.report, d, r, method, a.sets, a.data.path);
  if (!r.usable()) {
    std::fprintf(stderr, "ctid: the estimate is not usable: %s\n", r.why_not_usable().c_str());
    return kNotUsable;
  }
  return kOk;
}

void reject_unknown(const std::map<std::string, std::string>& s, const std::string& method, const std::string& known) {
  if (s.empty()) return;
  throw UsageError("--set " + s.begin()->first + ": not a setting of " + method + " (settings: " + known + ")");
}

Result<TransferFunction> run_rls(const IdData& d, const TfOrders& orders, std::map<std::string, std::string> s) {
  RlsSvfOptions o;
  consume_sets(s, [&](const std::string& k, const std::string& v) {
    if (k == "tau") o.tau = to_double(k, v);
    else if (k == "p0") o.p0 = to_double(k, v);
    else if (k == "forgetting") o.forgetting = to_double(k, v);
    else if (k == "alpha") o.alpha = to_double(k, v);
    else if (k == "regression_interval") o.regression_interval = to_double(k, v);
    else if (k.rfind("fix.", 0) == 0) o.fixed[k.substr(4)] = to_double(k, v);
    else return false;
    return true;
  });
  reject_unknown(s, "rls-svf", "tau, p0, forgetting, alpha, regression_interval, fix.NAME");
  if (d.nu() != 1 || d.ny() != 1) throw UsageError("rls-svf needs one --input and one --output");
  if (orders.nk > 0) throw UsageError("rls-svf: --nk must be 0 (delay the input column instead)");
  o.input_intersample = d.intersample(0);
  const auto start = std::chrono::steady_clock::now();
  RlsSvf rls(orders, o);
  for (int k = 0; k < d.size(); ++k) rls.update(d.time(k), d.u()(k, 0), d.y()(k, 0));
  Result<TransferFunction> r;
  r.model = rls.model();
  r.parameters.names = tf_parameter_names(orders);
  r.parameters.values = rls.parameters();
  r.parameters.std = Eigen::VectorXd::Constant(orders.n_parameters(), std::numeric_limits<double>::quiet_NaN());
  r.parameters.fixed.assign(orders.n_parameters(), false);
  for (int i = 0; i < orders.n_parameters(); ++i) r.parameters.fixed[i] = o.fixed.count(r.parameters.names[i]) > 0;
  r.diagnostics.scalars["tau"] = o.tau;
  r.summary.iterations = static_cast<int>(rls.n_updates());
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.fit = fit_report_or_inf(d.y().col(0), lsim(r.model, d, 0), orders.n_parameters() - static_cast<int>(o.fixed.size()));
  if (!r.model.is_stable()) r.diagnostics.warnings.push_back("the estimated model is unstable");
  return r;
}

// Settings shared by srivc / oe / tfest.
bool apply_srivc_set(const std::string& k, const std::string& v, SrivcOptions& o) {
  if (k == "max_iterations") o.max_iterations = to_int(k, v);
  else if (k == "tolerance") o.tolerance = to_double(k, v);
  else if (k == "delay") o.delay = to_double(k, v);
  else if (k == "delay_min") o.delay_min = to_double(k, v);
  else if (k == "delay_max") o.delay_max = to_double(k, v);
  else if (k == "delay_grid") o.delay_grid = to_int(k, v);
  else return false;
  return true;
}

Result<TransferFunction> run_oe(const IdData& d, const TfOrders& orders, std::map<std::string, std::string> sets,
                                bool delay, bool tf_est) {
  OeOptions o;
  o.estimate_delay = delay;
  consume_sets(sets, [&](const std::string& k, const std::string& v) {
    if (k == "max_iterations") o.max_iterations = to_int(k, v);
    else if (k == "tolerance") o.tolerance = to_double(k, v);
    else if (k == "delay") o.delay = to_double(k, v);
    else if (k.rfind("fix.", 0) == 0) o.fixed[k.substr(4)] = to_double(k, v);
    else if (k.rfind("lower.", 0) == 0) {
      auto& b = o.bounds.try_emplace(k.substr(6), -INFINITY, INFINITY).first->second;
      b.first = to_double(k, v);
    } else if (k.rfind("upper.", 0) == 0) {
      auto& b = o.bounds.try_emplace(k.substr(6), -INFINITY, INFINITY).first->second;
      b.second = to_double(k, v);
    } else if (k == "delay_min" || k == "delay_max" || k == "delay_grid") return apply_srivc_set(k, v, o.srivc);
    else return false;
    return true;
  });
  reject_unknown(sets, tf_est ? "tfest" : "oe",
                 "max_iterations, tolerance, delay, delay_min, delay_max, delay_grid, fix.NAME, lower.NAME, upper.NAME");
  return tf_est ? tfest(d, orders, o) : oe(d, orders, o);
}

// Closed-loop SRIVC: the reference column is loaded with the data and split off.
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
  const IdData both = da.load(true);
  const IdData d = both.select({0}, {0});
  const Eigen::VectorXd r = both.u().col(1);
  ClosedLoopOptions o;
  o.controller = std::get<TransferFunction>(c);
  auto sets = parse_sets(a.sets);
  consume_sets(sets, [&](const std::string& k, const std::string& v) {
    if (k == "max_iterations") o.max_iterations = to_int(k, v);
    else if (k == "tolerance") o.tolerance = to_double(k, v);
    else if (k == "setpoint") o.reference_at_plant_input = to_int(k, v) == 0;
    else return false;
    return true;
  });
  reject_unknown(sets, "srivc (closed loop)", "max_iterations, tolerance, setpoint (1: u = C (r - y))");
  Result<TransferFunction> r2;
  try {
    const int nf = a.nf[0];
    r2 = srivc_closed_loop(d, r, {a.nb.empty() ? nf : a.nb[0], nf, a.nk[0]}, o);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  return finish(r2, "clsrivc", d, a);
}

// Frequency-response data: columns w, re, im (G) or the spectra U and Y.
int run_frequency(const FitArgs& a) {
  if (a.method != "tfest" && a.method != "oe" && a.method != "srivc")
    throw UsageError("frequency data are fitted with --method tfest (Sanathanan-Koerner + output error)");
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
  FrequencyFitOptions o;
  o.estimate_delay = a.delay;
  auto sets = parse_sets(a.sets);
  consume_sets(sets, [&](const std::string& k, const std::string& v) {
    if (k == "max_iterations") o.max_iterations = to_int(k, v);
    else if (k == "tolerance") o.tolerance = to_double(k, v);
    else if (k == "sk_iterations") o.sk_iterations = to_int(k, v);
    else if (k == "delay") o.delay = to_double(k, v);
    else if (k == "refine") o.refine = to_int(k, v) != 0;
    else return false;
    return true;
  });
  reject_unknown(sets, "frequency-domain tfest", "max_iterations, tolerance, sk_iterations, delay, refine");
  Result<TransferFunction> r;
  try {
    const int nf = a.nf[0];
    r = tf_from_frequency(fd, {a.nb.empty() ? nf : a.nb[0], nf, a.nk[0]}, o);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  std::printf("method: tfest (frequency data)   frequencies: %d   from %.4g to %.4g rad/s\n", fd.size(), fd.w()(0),
              fd.w()(fd.size() - 1));
  std::printf("model:  G(s) = %s\n", r.model.to_string(6).c_str());
  for (int i = 0; i < r.parameters.size(); ++i)
    std::printf("  %-5s = %14.6g +- %-12.4g\n", r.parameters.names[i].c_str(), r.parameters.values(i), r.parameters.std(i));
  std::printf("fit (complex response): %.2f %%   termination: %s\n", r.fit.fit_percent, to_string(r.summary.termination));
  if (!a.json.empty()) {
    write_result_json(a.json, r, "tfest-frequency");
    std::printf("wrote %s\n", a.json.c_str());
  }
  return r.usable() ? kOk : kNotUsable;
}

// Gawthrop & Wang: FSF compression settings shared by --method fsf and --method physical.
FsfOptions fsf_options(std::map<std::string, std::string>& sets, bool* unstable) {
  FsfOptions o;
  o.T = 0;
  consume_sets(sets, [&](const std::string& k, const std::string& v) {
    if (k == "T") o.T = to_double(k, v);
    else if (k == "n") o.n = to_int(k, v);
    else if (k == "a") o.a = to_double(k, v);
    else if (k == "b") o.b = to_double(k, v);
    else if (k == "unstable" && unstable) *unstable = to_int(k, v) != 0;
    else return false;
    return true;
  });
  if (o.T == 0) throw UsageError("the FSF window needs --set T=SECONDS (settling time of the, possibly shifted, system)");
  if (unstable && *unstable && !(o.a > 0))
    throw UsageError(detail::format("the plant is declared unstable: give a window a > 0 larger than its fastest unstable "
                                    "pole (got a = {})",
                                    o.a));
  return o;
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
  auto sets = parse_sets(a.sets);
  bool unstable = false;
  const FsfOptions o = fsf_options(sets, &unstable);
  reject_unknown(sets, "fsf", "T, n, a, b, unstable");
  Result<FsfModel> r;
  try {
    r = fsf(d, o);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  const int code = finish(r, "fsf", d, a);
  if (!a.responses.empty()) write_fsf_responses(a.responses, r.model);
  return code;
}

int run_physical(const FitArgs& a, const IdData& d) {
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
  auto sets = parse_sets(a.sets);
  PhysicalFitOptions po;
  consume_sets(sets, [&](const std::string& k, const std::string& v) {
    if (k == "max_iterations") po.max_iterations = to_int(k, v);
    else if (k == "tolerance") po.tolerance = to_double(k, v);
    else if (k.rfind("lower.", 0) == 0 || k.rfind("upper.", 0) == 0 || k.rfind("fix.", 0) == 0) {
      const auto dot = k.find('.');
      const std::string name = k.substr(dot + 1);
      bool found = false;
      for (auto& q : ps)
        if (q.name == name) {
          found = true;
          if (k[0] == 'l') q.lower = to_double(k, v);
          else if (k[0] == 'u') q.upper = to_double(k, v);
          else { q.fixed = true; q.initial = to_double(k, v); }
        }
      if (!found) throw UsageError("--set " + k + ": '" + name + "' is not a --param");
    } else return false;
    return true;
  });
  Result<TransferFunction> r;
  try {
    const PhysicalModel model(a.model_expr, names);
    if (a.via == "raw") {
      double wa = 0;
      bool unstable = false;
      consume_sets(sets, [&](const std::string& k, const std::string& v) {
        if (k == "a") wa = to_double(k, v);
        else if (k == "unstable") unstable = to_int(k, v) != 0;
        else return false;
        return true;
      });
      if (unstable && !(wa > 0)) throw UsageError("the plant is declared unstable: give a window a > 0");
      reject_unknown(sets, "physical (raw)", "a, unstable, max_iterations, tolerance, lower.NAME, upper.NAME, fix.NAME");
      r = fit_physical_raw(model, ps, d, wa, po);
    } else {
      bool unstable = false;
      const FsfOptions fo = fsf_options(sets, &unstable);
      reject_unknown(sets, "physical", "T, n, a, b, unstable, max_iterations, tolerance, lower.NAME, upper.NAME, fix.NAME");
      const Result<FsfModel> c = fsf(d, fo);
      r = a.via == "frequency" ? fit_physical_frequency(model, ps, c.model, po) : fit_physical_step(model, ps, c.model, po);
      for (const auto& w : c.diagnostics.warnings) r.diagnostics.warnings.push_back("fsf: " + w);
    }
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  return finish(r, "physical-" + a.via, d, a);
}

// El-Shafey: modal functions (generated input with --set frequencies, or piecewise-constant input).
int run_modal(const FitArgs& a, const IdData& d0) {
  if (d0.nu() != 1) throw UsageError(detail::format("modal needs one input (selected {})", d0.nu()));
  if (a.nf.size() != 1 || a.nb.size() > 1 || a.nk.size() != 1) throw UsageError("modal: one --nb, --nf and --nk value");
  const int n = a.nf[0], nb = a.nb.empty() ? n : a.nb[0], nk = a.nk[0];
  if (nk < 0) throw UsageError("--nk must be >= 0");
  auto sets = parse_sets(a.sets);
  ModalSettings ms = modal_settings(sets, d0.ts());
  reject_unknown(sets, "modal", "shifts (samples) or shift_times (s), basis=fourier|walsh|discrete, functions, iv "
                                "(samples), stride, quadrature, window=START,LENGTH (samples), frequencies=w1,..");
  if (ms.options.shifts.size() != n)
    throw UsageError(detail::format("modal needs one shift per pole: --set shifts=S1,..,S{} (samples; got {} for --nf {})",
                                    n, ms.options.shifts.size(), n));
  // An input delay of nk samples: fit on the delayed input (zero before the record), report it as io_delay.
  IdData d = d0;
  if (nk > 0) {
    Eigen::MatrixXd u = Eigen::MatrixXd::Zero(d0.size(), 1);
    for (int i = nk; i < d0.size(); ++i) u(i, 0) = d0.u()(i - nk, 0);
    d = IdData(u, d0.y(), d0.ts(), d0.t0());
    d.set_intersample(0, d0.intersample(0));
  }
  if (!ms.basis_given) ms.options.basis = ms.frequencies.empty() ? ModalBasis::Walsh : ModalBasis::Fourier;
  if (!ms.functions_given && ms.options.basis == ModalBasis::Walsh) ms.options.functions = 8;
  Result<TransferFunction> r;
  try {
    if (!ms.frequencies.empty()) {
      const InputGenerator g = generator_fitted_to_input(ms.frequencies, d);
      r = modal_fit(d, nb, ms.options, &g);
    } else {
      r = modal_fit(d, nb, ms.options);
    }
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  if (nk > 0) r.model.set_io_delay(nk * d0.ts());
  return finish(r, "modal", d0, a);
}

int run(const FitArgs& a) {
  reject_flags_that_do_not_apply(a);
  check_outputs({a.json, a.report, a.responses.empty() ? "" : a.responses + "_time.csv",
                 a.responses.empty() ? "" : a.responses + "_freq.csv"},
                {a.data.path, a.narx, a.controller}, a.force);
  if (!a.controller.empty()) return run_closed_loop(a);
  if (a.frequency && !a.report.empty()) throw UsageError("--report needs time-domain data (not --frequency)");
  if (a.frequency) return run_frequency(a);
  const IdData d = a.data.load(true);
  // A constant channel carries no information on the dynamics: refuse instead of returning a model of nothing.
  auto constant = [](const Eigen::VectorXd& v) { return v.size() > 0 && v.maxCoeff() == v.minCoeff(); };
  for (int i = 0; i < d.nu(); ++i)
    if (constant(d.u().col(i)))
      throw UsageError(detail::format("input '{}' is constant ({}) over the whole record: it excites nothing (a step "
                                      "response needs samples before the step)", d.input_names()[i], d.u()(0, i)));
  for (int i = 0; i < d.ny(); ++i)
    if (constant(d.y().col(i)))
      throw UsageError(detail::format("output '{}' is constant ({}) over the whole record: there is nothing to fit",
                                      d.output_names()[i], d.y()(0, i)));
  if (d.ny() != 1) throw UsageError(detail::format("{} estimates single-output models (selected {} outputs)", a.method, d.ny()));
  // Orders per input: one value for every input, or one per input.
  auto per_input = [&](const std::vector<int>& v, const char* flag, int i) {
    if (v.size() != 1 && static_cast<int>(v.size()) != d.nu())
      throw UsageError(detail::format("{} has {} values for {} inputs (give one value, or one per input)", flag, v.size(),
                                      d.nu()));
    return v.size() == 1 ? v[0] : v[i];
  };
  std::vector<TfOrders> all;
  for (int i = 0; i < d.nu(); ++i) {
    const int nf_i = per_input(a.nf, "--nf", i);
    all.push_back({a.nb.empty() ? nf_i : per_input(a.nb, "--nb", i), nf_i, per_input(a.nk, "--nk", i)});
  }
  if (d.nu() > 1) {
    if (a.method != "srivc")
      throw UsageError(detail::format("{} estimates single-input models; use --method srivc for {} inputs", a.method, d.nu()));
    if (a.delay) throw UsageError("--delay is available for single-input models");
    SrivcMisoOptions o;
    auto sets = parse_sets(a.sets);
    consume_sets(sets, [&](const std::string& k, const std::string& v) {
      if (k == "max_iterations") o.max_iterations = to_int(k, v);
      else if (k == "tolerance") o.tolerance = to_double(k, v);
      else if (k == "common_denominator") o.common_denominator = to_int(k, v) != 0;
      else return false;
      return true;
    });
    reject_unknown(sets, "srivc (MISO)", "max_iterations, tolerance, common_denominator");
    Result<MisoModel> r;
    try {
      r = srivc_miso(d, all, o);
    } catch (const InvalidArgument& e) {
      throw UsageError(e.what());
    }
    return finish(r, "srivc", d, a);
  }
  if (a.method == "fsf" || a.method == "physical") {
    if (d.nu() != 1) throw UsageError(detail::format("{} needs one input (selected {})", a.method, d.nu()));
    return a.method == "fsf" ? run_fsf(a, d) : run_physical(a, d);
  }
  if (a.method == "modal") return run_modal(a, d);
  if (a.method == "narx" || a.method == "kia") return run_narx_or_kia(a.method, d, a.sets, a.narx, a.json, a.report);
  TfOrders orders = all[0];
  auto sets = parse_sets(a.sets);
  Result<TransferFunction> r;
  try {
    orders.validate();
    if (a.method == "lssvf") {
      LssvfOptions o;
      apply_svf_sets(sets, o);
      reject_unknown(sets, "lssvf", "tau, alpha, transient, weights, tau_grid, fix.NAME");
      r = lssvf(d, orders, o);
    } else if (a.method == "ivsvf") {
      IvsvfOptions o;
      apply_svf_sets(sets, o.svf);
      consume_sets(sets, [&](const std::string& k, const std::string& v) {
        if (k == "max_iterations") o.max_iterations = to_int(k, v);
        else if (k == "tolerance") o.tolerance = to_double(k, v);
        else return false;
        return true;
      });
      reject_unknown(sets, "ivsvf", "tau, alpha, transient, weights, tau_grid, fix.NAME, max_iterations, tolerance");
      r = ivsvf(d, orders, o);
    } else if (a.method == "srivc") {
      SrivcOptions o;
      o.estimate_delay = a.delay;
      consume_sets(sets, [&](const std::string& k, const std::string& v) { return apply_srivc_set(k, v, o); });
      reject_unknown(sets, "srivc", "max_iterations, tolerance, delay, delay_min, delay_max, delay_grid");
      r = srivc(d, orders, o);
    } else if (a.method == "oe" || a.method == "tfest") {
      r = run_oe(d, orders, sets, a.delay, a.method == "tfest");
    } else {
      r = run_rls(d, orders, sets);
    }
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  return finish(r, a.method, d, a);
}

}  // namespace

void setup_fit(CLI::App& app) {
  auto a = std::make_shared<FitArgs>();
  app.add_option("DATA", a->data.path, "CSV/.dat table (header row optional) or .mat file")->required();
  app.add_option("--method", a->method,
                 "Estimator: srivc, tfest, oe, lssvf, ivsvf, rls-svf, fsf, physical, modal, narx or kia")
      ->check(CLI::IsMember({"lssvf", "ivsvf", "rls-svf", "srivc", "oe", "tfest", "fsf", "physical", "modal", "narx", "kia"}))
      ->capture_default_str();
  a->data.add_to(app, true);
  app.add_option("--nb", a->nb, "Number of numerator coefficients (default: nf); one per input with several inputs (1,2)")
      ->delimiter(',');
  app.add_option("--nf", a->nf, "Model order (denominator coefficients after the leading 1); per input allowed")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--nk", a->nk, "Input delay in samples; per input allowed")->delimiter(',')->capture_default_str();
  app.add_option("--set", a->sets,
                 "Method setting KEY=VALUE (repeatable). lssvf/ivsvf: tau (s, 0 = automatic), alpha, transient (s), "
                 "weights=riemann|trapezoidal, fix.NAME=value (e.g. fix.a2=4); ivsvf also max_iterations, tolerance; "
                 "rls-svf: tau, p0, forgetting, alpha, regression_interval, fix.NAME; srivc: max_iterations, tolerance, "
                 "delay (s), delay_min, delay_max, delay_grid; oe/tfest: the same plus fix.NAME, lower.NAME, upper.NAME; "
                 "fsf/physical: T (s), n (odd), a, b, unstable=1; physical also lower.NAME, upper.NAME, fix.NAME; modal: "
                 "shifts=S1,..,Sn (samples) or shift_times (s), basis=fourier|walsh|discrete, functions, iv (samples), "
                 "stride, quadrature=simpson|trapezoid, window=START,LENGTH (samples), frequencies=w1,.. (generated input); "
                 "narx: degree, ylag, ulag, umin, constant, max_terms, err_tolerance, criterion=none|aic|aicc|bic|fpe, "
                 "noise_terms (NARMAX e lags), noise_max; kia: the narx settings or --narx FILE, y_order, u_order, points, "
                 "max (rad/s, <= pi/Ts; default 1.25/Ts), seed, gls_order, err_threshold (%), zoh, refine (0: KIA only), quadratic=y^2,y*Dy, cubic=y^3, qpoints, qmax (default 0.55/Ts), qgls_order, "
                 "qerr_threshold");
  app.add_flag("--delay", a->delay,
               "Estimate a (non-integer) input delay (srivc, oe, tfest): grid search over [delay_min, delay_max], then "
               "refinement");
  app.add_option("--closed-loop-controller", a->controller,
                 "Closed-loop data: JSON file of the known controller C(s) (transfer_function); with --reference");
  app.add_option("--reference", a->reference, "Closed-loop data: the reference column (added at the plant input unless --set setpoint=1)");
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
  app.add_option("--model", a->model_expr, "physical: transfer-function expression in s, e.g. \"k1/(s^2-k2)\"");
  app.add_option("--param", a->params, "physical: NAME=INITIAL for each parameter of --model (repeatable)");
  app.add_option("--via", a->via, "physical: fit to the FSF step response (fsf), the FSF frequency response (frequency), "
                                  "or the raw data (raw)")
      ->capture_default_str();
  app.add_option("--responses", a->responses,
                 "fsf: write PREFIX_time.csv (step and impulse with standard deviations) and PREFIX_freq.csv (G(jw) with "
                 "standard deviations of its real and imaginary parts)");
  app.add_option("--narx", a->narx, "kia: the NARX model JSON to reconstruct from (otherwise a NARX model is fitted first)");
  app.add_option("--json", a->json, "Write the result (model, parameters, fit) to this JSON file");
  app.add_option("--report", a->report, "Write a self-contained HTML report (plots, tests, parameters) to this file");
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a, &app] {
    for (const CLI::Option* o : app.get_options())
      if (o->count() > 0)
        for (const auto& n : o->get_lnames()) a->given.insert(n);
    g_run = [a] { return run(*a); };
  });
}

}  // namespace ctid::cli
