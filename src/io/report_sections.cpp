// ctid — the sections every HTML report shares (report_sections.hpp).
#include "report_sections.hpp"

#include <algorithm>
#include <ctime>
#include <cmath>
#include <complex>
#include <numbers>
#include <sstream>

#include "ctid/core/check.hpp"
#include "ctid/estimate/nonlinear/gfrf.hpp"
#include "ctid/io/json.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/simulate/simulate.hpp"
#include "ctid/validate/compare.hpp"
#include "ctid/validate/metrics.hpp"
#include "ctid/validate/residuals.hpp"
#include "ctid/validate/uncertainty.hpp"

namespace ctid::report_detail {

void provenance(std::vector<std::vector<std::string>>& rows, const ReportOptions& o) {
  for (const auto& [name, value] : o.provenance.rows()) rows.push_back({name, value});
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  char when[32] = "";
  if (gmtime_r(&now, &utc)) std::strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S UTC", &utc);
  Provenance p = o.provenance;
  if (p.version.empty()) p = make_provenance();
  rows.push_back({"made by", p.made_by() + ", " + when});
}

void data_section(Page& page, const IdData& d, const ReportOptions& o) {
  page.section("Data");
  const double dur = d.duration();
  std::string inputs;
  for (int i = 0; i < d.nu(); ++i)
    inputs += (i ? ", " : "") + input_name(d, i) + " (" + to_string(d.intersample(i)) + ")";
  std::string outputs;
  for (int j = 0; j < d.ny(); ++j) outputs += (j ? ", " : "") + output_name(d, j);
  page.table({"", ""}, {{"source", o.data_source.empty() ? "-" : o.data_source},
                        {"samples", std::to_string(d.size())},
                        {"sampling", d.is_uniform() ? "Ts = " + fmt(d.ts()) + " s" : "irregular"},
                        {"duration", fmt(dur) + " s"},
                        {d.nu() > 1 ? "inputs" : "input", inputs},
                        {d.ny() > 1 ? "outputs" : "output", outputs}});
  const auto k = keep(d.size(), o.max_points);
  const Eigen::VectorXd t = pick(d.times(), k);
  std::vector<Series> us;
  for (int i = 0; i < d.nu(); ++i) us.push_back({input_name(d, i), pick(d.u().col(i), k)});
  page.plot({d.nu() > 1 ? "Inputs" : "Input", "time (s)", "u", t, us});
  std::vector<Series> ys;
  for (int j = 0; j < d.ny(); ++j) ys.push_back({output_name(d, j), pick(d.y().col(j), k)});
  page.plot({d.ny() > 1 ? "Outputs" : "Output", "time (s)", "y", t, ys});
}

void diagnostics(Page& page, const Diagnostics& g) {
  std::vector<std::vector<std::string>> rows;
  auto row = [&](const std::string& name, const std::string& value) {
    const DiagnosticInfo* d = find_diagnostic(name);
    rows.push_back({name, value, d ? d->unit : "", d ? d->doc : ""});
  };
  for (const auto& [k, v] : g.scalars()) row(k, fmt(v));
  for (const auto& [k, v] : g.vectors()) {
    if (v.size() == 0 || v.size() > 24) continue;
    std::string s;
    for (Eigen::Index i = 0; i < v.size(); ++i) s += (i ? ", " : "") + fmt(v(i), 4);
    row(k, s);
  }
  if (rows.empty()) return;
  page.section("Diagnostics");
  if (g.has(diagnostic::condition_by_order)) {
    const Eigen::VectorXd& cond = g.get(diagnostic::condition_by_order);
    page.text("Modal functions (El-Shafey): condition_by_order is the condition number of the modal regression of each "
              "order j = 0, 1, .. (large values: the shifts or windows do not separate the modes; the estimate of that "
              "order is unreliable).");
    Eigen::VectorXd j = Eigen::VectorXd::LinSpaced(cond.size(), 0, static_cast<double>(cond.size() - 1));
    page.plot({"Modal regressions: log10 of the condition number by order", "order j", "log10 condition", j,
               {{"log10 cond", cond.array().log10().matrix()}}, false, true});
  }
  page.table({"diagnostic", "value", "unit", "meaning"}, rows);
}

void parameters(Page& page, const ParameterSet& p, const Eigen::VectorXd* err) {
  page.section("Parameters");
  std::vector<std::vector<std::string>> rows;
  for (int i = 0; i < p.size(); ++i) {
    const bool fixed = i < static_cast<int>(p.fixed.size()) && p.fixed[static_cast<size_t>(i)];
    std::vector<std::string> r = {p.names[static_cast<size_t>(i)], fmt(p.values(i)),
                                  fixed ? "fixed" : (i < p.std.size() ? fmt(p.std(i), 3) : "-")};
    if (err) r.push_back(i < err->size() ? fmt((*err)(i), 4) : "-");
    rows.push_back(r);
  }
  // A parameter within two standard deviations of 0 is not significant: the data cannot tell it from 0 (at about 95 %),
  // so the structure may have a term too many.
  int insignificant = 0;
  for (int i = 0; i < p.size(); ++i) {
    const bool fixed = i < static_cast<int>(p.fixed.size()) && p.fixed[static_cast<size_t>(i)];
    const bool known = !fixed && i < p.std.size() && std::isfinite(p.std(i));
    const bool weak = known && std::abs(p.values(i)) < 2 * p.std(i);
    insignificant += weak;
    rows[static_cast<size_t>(i)].push_back(!known ? "-" : weak ? "no: |value| < 2 std" : "yes");
  }
  if (err) page.table({"parameter", "value", "std", "ERR %", "significant"}, rows);
  else page.table({"parameter", "value", "std", "significant"}, rows);
  if (insignificant > 0)
    page.text("<span class=\"warn\">" + std::to_string(insignificant) + " parameter(s) lie within two standard deviations "
              "of 0: the data cannot tell them from 0 (about 95 % confidence); a structure with fewer terms may do as "
              "well (compare its BIC).</span>");
}

void validation(Page& page, const IdData& d, const Eigen::VectorXd& yhat, const ReportOptions& o, int out) {
  const std::string of = d.ny() > 1 ? " (" + output_name(d, out) + ")" : "";
  page.section("Measured and simulated output" + of);
  const Eigen::VectorXd y = d.y().col(out);
  const auto k = keep(d.size(), o.max_points);
  Eigen::VectorXd e = y - yhat;
  const double fit = fit_report_or_inf(y, yhat, 0).fit_percent;
  page.plot({"Output" + of + ": measured and simulated (fit " + fmt(fit, 4) + " %)", "time (s)", "y", pick(d.times(), k),
             {{"measured", pick(y, k)}, {"simulated", pick(yhat, k), false, false, false, 17}}});
  if (!std::isfinite(e.squaredNorm())) {  // non-finite, or so large that the squares overflow
    page.text("<span class=\"warn\">The simulation does not stay finite on this record: no residual tests.</span>");
    return;
  }
  page.section("Residual tests" + of);
  const int lags = std::min(o.max_lag, d.size() / 4);
  if (lags < 1 || e.squaredNorm() == 0) {
    page.text("Too few samples or zero residuals: no correlation tests.");
    return;
  }
  std::vector<std::pair<std::string, CorrelationTest>> tests = {{"Residual autocorrelation", residual_autocorrelation(e, lags)}};
  for (int i = 0; i < d.nu(); ++i)
    tests.push_back({"Input-residual cross-correlation" + (d.nu() > 1 ? " (" + input_name(d, i) + ")" : std::string()),
                     input_residual_crosscorrelation(d.u().col(i), e, lags)});
  for (size_t t = 0; t < tests.size(); ++t) {
    const auto& [title, test] = tests[t];
    const CorrelationTest* c = &test;
    const Eigen::VectorXd x = c->lags.cast<double>();
    const Eigen::VectorXd b = Eigen::VectorXd::Constant(x.size(), c->bound);
    page.plot({title + ": " + std::to_string(c->n_outside) + " lag(s) outside the 99 % bounds",
               "lag (samples)", "correlation", x, {{"r(k)", c->values}, {"+bound", b, true, true}, {"-bound", -b, true, true}}, false,
               true});
    // What the result means, in one line (Ljung 1999, sec. 16.6).
    const bool pass = c->passed();
    const std::string meaning =
        t == 0 ? (pass ? "Passed: the residuals look white — nothing predictable is left in them."
                       : "Failed: the residuals are correlated — the model misses dynamics, or the noise is coloured "
                         "(an output-error fit does not model the noise; its parameters can still be right).")
               : (pass ? "Passed: the residuals do not depend on past inputs — no input-output dynamics is left "
                         "unexplained."
                       : "Failed: the residuals depend on the input — the model misses input-output dynamics (a higher "
                         "order, another delay, a nonlinearity), or the data were taken in closed loop.");
    page.text(pass ? meaning : "<span class=\"warn\">" + meaning + "</span>");
  }
}

void validations(Page& page, const IdData& d, const Eigen::MatrixXd& yhat, const ReportOptions& o) {
  for (int j = 0; j < d.ny(); ++j) validation(page, d, yhat.col(j), o, j);
}

Eigen::VectorXd unwrapped_phase_deg(const Eigen::VectorXcd& h) {
  Eigen::VectorXd ph(h.size());
  double prev = 0, offset = 0;
  for (Eigen::Index i = 0; i < h.size(); ++i) {
    const double a = std::arg(h(i)) * 180 / std::numbers::pi;
    if (i > 0) {
      while (a + offset - prev > 180) offset -= 360;
      while (a + offset - prev < -180) offset += 360;
    }
    ph(i) = prev = a + offset;
  }
  return ph;
}

void bode(Page& page, const Eigen::VectorXd& w, const std::vector<std::pair<std::string, Eigen::VectorXcd>>& hs,
          const Bands& bands) {
  page.section("Frequency response");
  std::vector<Series> ms, ps;
  for (const auto& [label, h] : hs) {
    ms.push_back({"|" + label + "|", (20 * h.cwiseAbs().array().log10()).matrix()});
    ps.push_back({hs.size() > 1 ? label : "phase", unwrapped_phase_deg(h)});
  }
  const MagnitudeBand* m = bands.magnitude && !bands.magnitude->empty() ? bands.magnitude : nullptr;
  const MagnitudeBand* p = bands.phase && !bands.phase->empty() ? bands.phase : nullptr;
  if (m) {
    ms.push_back({"2.5 %", (20 * m->lower.array().log10()).matrix(), false, true});
    ms.push_back({"97.5 %", (20 * m->upper.array().log10()).matrix(), false, true});
  }
  if (p) {
    ps.push_back({"2.5 %", p->lower, false, true});
    ps.push_back({"97.5 %", p->upper, false, true});
  }
  page.plot({"Bode magnitude" + std::string(m ? " with the 95 % band from the parameter covariance" : ""),
             "frequency (rad/s)", "dB", w, ms, true});
  page.plot({"Bode phase" + std::string(p ? " with the 95 % band from the parameter covariance" : ""),
             "frequency (rad/s)", "deg", w, ps, true});
}

void time_responses(Page& page, const AnyModel& model, const std::vector<std::string>& labels, double horizon,
                    const Result<TransferFunction>* tf) {
  page.section("Step and impulse responses");
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(400, 0.0, horizon);
  const Eigen::MatrixXd s = model_step_response(model, t), g = model_impulse_response(model, t);
  std::vector<Series> step, impulse;
  for (Eigen::Index i = 0; i < s.cols(); ++i) {
    step.push_back({s.cols() > 1 ? labels[static_cast<size_t>(i)] : "step", s.col(i)});
    impulse.push_back({s.cols() > 1 ? labels[static_cast<size_t>(i)] : "impulse", g.col(i)});
  }
  const MagnitudeBand band =
      tf ? response_band(*tf, [&](const TransferFunction& m) { return step_response(m, t); }) : MagnitudeBand{};
  if (!band.empty()) {
    step.push_back({"2.5 %", band.lower, false, true});
    step.push_back({"97.5 %", band.upper, false, true});
  }
  page.plot({band.empty() ? "Step response" : "Step response with the 95 % band from the parameter covariance",
             "time (s)", "y", t, step});
  page.plot({"Impulse response", "time (s)", "y", t, impulse});
}

double nyquist_or_zero(const IdData& d) { return d.is_uniform() ? std::numbers::pi / d.ts() : 0.0; }

Eigen::MatrixXd simulated(Page& page, const IdData& d, const Result<AnyModel>& r, SimulationPurpose purpose,
                          std::optional<InitialCondition> initial) {
  const SimulateOptions so = simulate_options(r, purpose, initial);
  const Simulation s = simulate(r.model, d, so);
  page.text("Simulated from the initial condition: " + std::string(to_string(so.initial)) + ".");
  if (!s.ok()) page.text("<span class=\"warn\">" + escape(s.problem) + "</span>");
  return s.y;
}

void more_records(Page& page, const Result<AnyModel>& r, const ReportOptions& o) {
  const AnyModel& m = r.model;
  for (size_t i = 0; i < o.more_records.size(); ++i) {
    const auto& [name, d] = o.more_records[i];
    CTID_REQUIRE(d.nu() == model_inputs(m) && d.ny() == model_outputs(m),
                 "html_report: record {} ({}) has {} input(s) and {} output(s); the model has {} and {}", i + 2, name,
                 d.nu(), d.ny(), model_inputs(m), model_outputs(m));
    page.section("Record " + std::to_string(i + 2) + ": " + name);
    page.text(std::to_string(d.size()) + " samples, " + fmt(d.duration()) + " s.");
    const auto y = o.more_records_initial ? simulated(page, d, r, SimulationPurpose::Validation, o.more_records_initial)
                                          : simulated(page, d, r, SimulationPurpose::OtherRecord, o.initial);
    validations(page, d, y, o);
  }
}

void require_siso(const IdData& d) {
  CTID_REQUIRE(d.nu() == 1 && d.ny() == 1, "html_report: needs one input and one output (got {}, {})", d.nu(), d.ny());
}

void step_at_input_level(Page& page, const AnyModel& m, const IdData& d, const Eigen::VectorXd& t) {
  page.section("Step response");
  const Eigen::VectorXd u = d.u().col(0);
  const double level = std::sqrt(u.squaredNorm() / std::max<Eigen::Index>(1, u.size()));
  try {
    page.plot({"Response to a step of the input's RMS level (" + fmt(level, 3) + ")", "time (s)", "y", t,
               {{"step", model_step_response(m, t, level).col(0)}}});
  } catch (const InvalidArgument& e) {
    page.text("<span class=\"warn\">" + escape(e.what()) + "</span>");
  }
}

void poles_and_gain(Page& page, const TransferFunction& g) {
  page.section("Poles, zeros and gain");
  std::vector<std::vector<std::string>> rows;
  const Eigen::VectorXcd p = g.poles();
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    const std::complex<double> s = p(i);
    if (s.imag() < -1e-12 * std::abs(s)) continue;  // a pair is shown once, by its upper pole
    const double wn = std::abs(s);
    const bool real = std::abs(s.imag()) <= 1e-12 * std::max(wn, 1e-300);
    const std::string where = s.real() > 0 ? "unstable" : s.real() == 0 ? "on the imaginary axis" : "stable";
    if (real)
      rows.push_back({fmt(s.real()), "real", s.real() != 0 ? fmt(1.0 / std::abs(s.real()), 4) + " s" : "-", "-", "-", where});
    else
      rows.push_back({fmt(s.real()) + " ± " + fmt(s.imag()) + "j", "complex pair", "-", fmt(wn, 4) + " rad/s (" +
                      fmt(wn / (2 * std::numbers::pi), 4) + " Hz)", fmt(-s.real() / wn, 4), where});
  }
  page.table({"pole", "kind", "time constant", "natural frequency", "damping ratio", ""}, rows);
  std::string zeros;
  const Eigen::VectorXcd z = g.zeros();
  for (Eigen::Index i = 0; i < z.size(); ++i)
    zeros += (i ? ", " : "") + (std::abs(z(i).imag()) > 0 ? fmt(z(i).real()) + (z(i).imag() > 0 ? "+" : "-") +
                                                                 fmt(std::abs(z(i).imag())) + "j"
                                                           : fmt(z(i).real()));
  page.table({"", ""}, {{"zeros", zeros.empty() ? "none" : zeros},
                        {"DC gain G(0)", fmt(g.dc_gain(), 5)},
                        {"delay", fmt(g.io_delay(), 4) + " s"}});
}

PointSet points(const std::string& label, const Eigen::VectorXcd& v, char marker, bool light) {
  return {label, v.real(), v.imag(), marker, light};
}

void pole_zero_map(Page& page, const Result<TransferFunction>& r) {
  const Eigen::VectorXcd p = r.model.poles(), z = r.model.zeros();
  double reach = 0;
  for (const auto& v : {p, z})
    if (reach == 0)
      for (Eigen::Index i = 0; i < v.size(); ++i) reach = std::max(reach, 5 * std::abs(v(i)));
  auto inside = [&](std::complex<double> x) { return std::isfinite(std::abs(x)) && std::abs(x) <= std::max(reach, 1e-300); };
  auto kept = [&](const Eigen::VectorXcd& v, int* left_out) {
    std::vector<std::complex<double>> o;
    for (Eigen::Index i = 0; i < v.size(); ++i)
      if (inside(v(i))) o.push_back(v(i));
      else if (left_out) ++*left_out;
    return o;
  };
  auto vec = [](const std::vector<std::complex<double>>& v) {
    return Eigen::Map<const Eigen::VectorXcd>(v.data(), static_cast<Eigen::Index>(v.size())).eval();
  };
  const std::vector<TransferFunction> draws = drawn_models(r);
  std::vector<std::complex<double>> dp, dz;
  int left_out = 0;
  for (const TransferFunction& g : draws) {
    for (const auto& x : kept(g.poles(), &left_out)) dp.push_back(x);
    for (const auto& x : kept(g.zeros(), &left_out)) dz.push_back(x);
  }
  std::vector<PointSet> sets;
  if (!draws.empty()) {
    sets.push_back(points("poles of " + std::to_string(draws.size()) + " models drawn from the covariance", vec(dp), '.', true));
    if (!dz.empty()) sets.push_back(points("their zeros", vec(dz), '.', true));
  }
  sets.push_back(points("poles", p, 'x'));
  const std::vector<std::complex<double>> zi = kept(z, nullptr);
  if (!zi.empty()) sets.push_back(points("zeros", vec(zi), 'o'));
  page.scatter({draws.empty() ? "Pole-zero map" : "Pole-zero map with the spread of the parameter covariance",
                "real part (1/s)", "imaginary part (rad/s)", sets});
  std::string note;
  if (!draws.empty())
    note = "The pale clouds show where the poles and zeros of equally likely models lie (drawn from the parameter "
           "covariance): a wide cloud is a pole or zero the data pin down poorly; a zero cloud over a pole cloud "
           "suggests they cancel and the order may be too high.";
  std::string far;
  for (Eigen::Index i = 0; i < z.size(); ++i)
    if (!inside(z(i)) && z(i).imag() >= 0)
      far += (far.empty() ? "" : ", ") + fmt(z(i).real(), 4) + (z(i).imag() > 0 ? " ± " + fmt(z(i).imag(), 4) + "j" : "");
  if (!far.empty()) note += " Zero(s) beyond the map (5 times the largest pole): " + far + ".";
  if (left_out) note += " " + std::to_string(left_out) + " drawn point(s) beyond the map are not shown.";
  if (!note.empty()) page.text(note);
}

}  // namespace ctid::report_detail
