// Self-contained HTML reports (see include/ctid/io/report.hpp). The page carries its plot data as JSON
// and draws it with the inlined uPlot; a self-check at the end of loading writes "plots=N drawn=M
// errors=E" into #ctid-selfcheck (drawn = canvases with at least one painted pixel; run from a timer after
// uPlot's drawing microtasks), which the browser test reads.
#include "ctid/io/report.hpp"

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

#include "report_sections.hpp"

namespace ctid {

bool report_has_plot_library() { return report_assets::kHaveUplot; }

using namespace report_detail;

namespace {

std::string report_of(const IdData& d, const Result<TransferFunction>& r, const ReportOptions& o) {
  require_siso(d);
  Page page;
  opening(page, d, r, o);
  poles_and_gain(page, r.model);
  pole_zero_map(page, r);
  parameters(page, r.parameters);
  diagnostics(page, r.diagnostics);
  const Eigen::VectorXd w = frequency_grid(r.model.poles(), nyquist_or_zero(d));
  const Eigen::VectorXcd h = r.model.frequency_response(w);
  // 95 % bands of |G|, its phase and the step response from 200 draws of the parameter covariance (seeded: the
  // report is reproducible).
  const MagnitudeBand mag = magnitude_band(r, w);
  // Each drawn phase is unwrapped from the estimate's branch at the first frequency (a draw starting at -179 deg
  // against the estimate's +179 deg is the same curve, not one 360 deg away).
  const Eigen::VectorXd phase0 = unwrapped_phase_deg(h);
  const MagnitudeBand phase = response_band(r, [&](const TransferFunction& g) {
    Eigen::VectorXd ph = unwrapped_phase_deg(g.frequency_response(w));
    if (ph.size() > 0) ph.array() += 360.0 * std::round((phase0(0) - ph(0)) / 360.0);
    return ph;
  });
  bode(page, w, {{"G(jw)", h}}, {&mag, &phase});
  time_responses(page, r.model, {"G"}, response_horizon({r.model}, d.duration()), &r);
  return page.render(o.title.empty() ? o.method + " fit" : o.title);
}

// A state-space model with any number of inputs and outputs: each output simulated and tested, the singular values of
// its subspace step, the poles with natural frequency, damping (and their standard deviations where the fit has a
// covariance) and mode shapes, the Bode magnitude of every channel, step responses per input.
std::string report_of(const IdData& d, const Result<StateSpace>& r, const ReportOptions& o) {
  const StateSpace& m = r.model;
  CTID_REQUIRE(d.nu() == m.nu() && d.ny() == m.ny(), "html_report: the model has {} inputs and {} outputs (data: {}, {})",
               m.nu(), m.ny(), d.nu(), d.ny());
  Page page;
  opening(page, d, r, o);
  if (r.diagnostics.has(diagnostic::singular_values)) {
    const Eigen::VectorXd& sv = r.diagnostics.get(diagnostic::singular_values);
    page.section("Singular values of the subspace step");
    page.text("The order is where they drop (relative to the largest, log10); the model has " + std::to_string(m.nx()) +
              " states.");
    const Eigen::VectorXd n = Eigen::VectorXd::LinSpaced(sv.size(), 1, static_cast<double>(sv.size()));
    page.plot({"Singular values", "index", "log10 (s_i / s_1)", n,
               {{"log10 s", (sv / std::max(sv(0), 1e-300)).array().max(1e-300).log10().matrix()}}, false, true});
  }
  page.section("Modes");
  const std::vector<Mode> modes = m.modes();
  const bool with_std = r.diagnostics.has(diagnostic::mode_wn_std) &&
                        r.diagnostics.get(diagnostic::mode_wn_std).size() == static_cast<Eigen::Index>(modes.size());
  std::vector<std::string> header = {"pole (1/s)", "wn (rad/s)", "f (Hz)", "zeta"};
  if (with_std) header.insert(header.begin() + 2, "wn std"), header.push_back("zeta std");
  for (int j = 0; j < m.ny(); ++j) header.push_back("|shape| " + output_name(d, j));
  std::vector<std::vector<std::string>> rows;
  for (size_t k = 0; k < modes.size(); ++k) {
    const Mode& md = modes[k];
    std::vector<std::string> row = {fmt(md.pole.real(), 5) + (md.pole.imag() != 0 ? " ± " + fmt(md.pole.imag(), 5) + "j" : ""),
                                    fmt(md.wn, 5), fmt(md.wn / (2 * std::numbers::pi), 5), fmt(md.zeta, 4)};
    if (with_std) {
      row.insert(row.begin() + 2, fmt(r.diagnostics.get(diagnostic::mode_wn_std)(static_cast<Eigen::Index>(k)), 3));
      row.push_back(fmt(r.diagnostics.get(diagnostic::mode_zeta_std)(static_cast<Eigen::Index>(k)), 3));
    }
    for (Eigen::Index j = 0; j < md.shape.size(); ++j) row.push_back(fmt(std::abs(md.shape(j)), 3));
    rows.push_back(row);
  }
  page.text("Mode shape: the output direction C v of the mode's eigenvector (unit norm).");
  page.table(header, rows);
  parameters(page, r.parameters);
  diagnostics(page, r.diagnostics);
  // The Bode magnitude matrix: one plot per input, one curve per output.
  const Eigen::VectorXd w = frequency_grid(m.poles(), nyquist_or_zero(d));
  const std::vector<Eigen::MatrixXcd> G = frequency_response(m, w);
  page.section("Frequency response (magnitude of every channel)");
  for (int i = 0; i < m.nu(); ++i) {
    std::vector<Series> ms;
    for (int j = 0; j < m.ny(); ++j) {
      Eigen::VectorXd mag(w.size());
      for (Eigen::Index k = 0; k < w.size(); ++k) mag(k) = 20 * std::log10(std::abs(G[static_cast<size_t>(k)](j, i)));
      ms.push_back({output_name(d, j), mag});
    }
    page.plot({"Bode magnitude from " + input_name(d, i), "frequency (rad/s)", "dB", w, ms, true});
  }
  page.section("Step responses");
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(400, 0.0, poles_response_horizon(m.poles(), d.duration()));
  const std::vector<Eigen::MatrixXd> steps = step_response(m, t);
  for (int i = 0; i < m.nu(); ++i) {
    std::vector<Series> ss;
    for (int j = 0; j < m.ny(); ++j) ss.push_back({output_name(d, j), steps[static_cast<size_t>(i)].col(j)});
    page.plot({"Unit step on " + input_name(d, i), "time (s)", "y", t, ss});
  }
  return page.render(o.title.empty() ? o.method + " fit" : o.title);
}

std::string report_of(const IdData& d, const Result<MisoModel>& r, const ReportOptions& o) {
  CTID_REQUIRE(d.ny() == 1 && d.nu() == r.model.nu(), "html_report: the model has {} inputs and 1 output (data: {}, {})",
               r.model.nu(), d.nu(), d.ny());
  Page page;
  opening(page, d, r, o);
  parameters(page, r.parameters);
  diagnostics(page, r.diagnostics);
  std::vector<std::string> labels;
  for (int i = 0; i < r.model.nu(); ++i) labels.push_back("G" + std::to_string(i + 1) + " (" + input_name(d, i) + ")");
  const Eigen::VectorXd w = frequency_grid(model_poles(r.model), nyquist_or_zero(d));
  const Eigen::MatrixXcd h = model_frequency_response(r.model, w);
  std::vector<std::pair<std::string, Eigen::VectorXcd>> hs;
  for (int i = 0; i < r.model.nu(); ++i) hs.push_back({labels[static_cast<size_t>(i)], h.col(i)});
  bode(page, w, hs);
  time_responses(page, r.model, labels, response_horizon(r.model.channels, d.duration()));
  return page.render(o.title.empty() ? o.method + " fit" : o.title);
}

std::string report_of(const IdData& d, const Result<FsfModel>& r, const ReportOptions& o) {
  require_siso(d);
  Page page;
  const FsfModel& m = r.model;
  opening(page, d, r, o, m.shift() == 0.0);
  if (m.shift() != 0.0)
    page.text("The model was fitted to exponentially windowed data (a = " + fmt(m.shift()) +
              " 1/s): it describes G(s + a), not the system, and is not simulated against the record.");
  parameters(page, r.parameters);
  diagnostics(page, r.diagnostics);
  page.section("Compressed responses (Gawthrop & Wang): +-2 std bands from the parameter covariance");
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(400, 0.0, m.T());
  const Eigen::VectorXd s = m.step_response(t), ss = m.step_response_std(t);
  const Eigen::VectorXd g = m.impulse_response(t), gs = m.impulse_response_std(t);
  const bool bands = ss.allFinite();
  std::vector<Series> sv = {{"step", s}}, gv = {{"impulse", g}};
  if (bands) {
    sv.push_back({"-2 std", s - 2 * ss, false, true});
    sv.push_back({"+2 std", s + 2 * ss, false, true});
    gv.push_back({"-2 std", g - 2 * gs, false, true});
    gv.push_back({"+2 std", g + 2 * gs, false, true});
  }
  page.plot({"Step response", "time (s)", "y", t, sv});
  page.plot({"Impulse response", "time (s)", "y", t, gv});
  const Eigen::VectorXd w = model_frequency_grid(m);
  bode(page, w, {{"Gbar(e^{jw Delta})", m.frequency_response(w)}});
  return page.render(o.title.empty() ? o.method + " fit" : o.title);
}

// |H_2(j w1, j w2)| on a grid (w1, w2 in (0, wmax]) of a kernel function.
template <class F>
Heatmap h2_map(F h2, double wmax, const std::string& what) {
  const int n = 40;
  Heatmap m{"|H_2(jw1, jw2)| of the " + what + " (dB)", "w1 (rad/s)", "w2 (rad/s)", Eigen::VectorXd(n),
            Eigen::VectorXd(n), Eigen::MatrixXd(n, n)};
  for (int i = 0; i < n; ++i) m.x(i) = m.y(i) = wmax * (i + 1) / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double a = std::abs(h2(std::complex<double>(0, m.x(j)), std::complex<double>(0, m.y(i))));
      m.z(i, j) = a > 0 ? 20 * std::log10(a) : NAN;
    }
  return m;
}

std::string report_of(const IdData& d, const Result<NarxModel>& r, const ReportOptions& o) {
  require_siso(d);
  Page page;
  const NarxModel p = r.model.process();
  opening(page, d, r, o);
  page.section("Selected terms");
  page.text("Terms in the order of selection by forward orthogonal least squares; ERR: the error reduction ratio "
            "(share of the output energy explained by the term).");
  parameters(page, r.parameters, r.diagnostics.has(diagnostic::err) ? &r.diagnostics.get(diagnostic::err) : nullptr);
  diagnostics(page, r.diagnostics);
  const bool zoh = d.intersample(0) == Intersample::Zoh;
  const double nyq = std::numbers::pi / p.ts();
  Eigen::VectorXd w = frequency_grid(Eigen::VectorXcd::Constant(1, std::complex<double>(0.1 * nyq, 0.0)), 0.9 * nyq);
  bool linear = false;
  for (const auto& t : p.terms()) linear = linear || (t.degree() == 1 && !t.has_noise());
  if (linear) {
    Eigen::VectorXcd h(w.size());
    for (Eigen::Index i = 0; i < w.size(); ++i) h(i) = narx_gfrf_ct(p, {std::complex<double>(0, w(i))}, zoh);
    bode(page, w, {{"H_1(jw)", h}});
    if (p.degree() >= 2) {
      page.section("Second-order GFRF");
      page.heatmap(h2_map([&](auto a, auto b) { return narx_gfrf_ct(p, {a, b}, zoh); }, 0.5 * nyq, "NARX model"));
    }
  }
  step_at_input_level(page, p, d, time_grid(p.ts(), std::max(4 * std::min(p.max_lag(), d.size()), 200)));
  return page.render(o.title.empty() ? o.method + " fit" : o.title);
}

std::string report_of(const IdData& d, const Result<NdeModel>& r, const ReportOptions& o) {
  require_siso(d);
  Page page;
  const NdeModel& m = r.model;
  opening(page, d, r, o);
  const Eigen::VectorXd* err = r.diagnostics.has(diagnostic::err) ? &r.diagnostics.get(diagnostic::err) : nullptr;
  parameters(page, r.parameters, err && err->size() == r.parameters.size() ? err : nullptr);
  diagnostics(page, r.diagnostics);
  const Eigen::VectorXd w = frequency_grid(m.a().roots(), nyquist_or_zero(d));
  Eigen::VectorXcd h(w.size());
  for (Eigen::Index i = 0; i < w.size(); ++i) h(i) = m.h1(std::complex<double>(0, w(i)));
  bode(page, w, {{"H_1(jw)", h}});
  bool nonlinear = false;
  for (const auto& term : m.terms()) nonlinear = nonlinear || term.degree() == 2;
  if (nonlinear) {
    page.section("Second-order GFRF (harmonic probing)");
    page.heatmap(h2_map([&](auto a, auto b) { return m.h2(a, b); }, w(w.size() - 1) / 4, "equation"));
  }
  step_at_input_level(page, m, d,
                      Eigen::VectorXd::LinSpaced(400, 0.0, std::min(d.duration(), 20 * 2 * std::numbers::pi / w(w.size() / 2))));
  return page.render(o.title.empty() ? o.method + " fit" : o.title);
}

std::string report_of(const IdData& d, const Result<GreyboxModel>& r, const ReportOptions& o) {
  CTID_REQUIRE(d.ny() == 1, "html_report: a grey-box report shows one output (the record has {})", d.ny());
  Page page;
  opening(page, d, r, o);
  page.section("Equations");
  page.text("<pre>" + escape(r.model.to_string()) + "</pre>");
  parameters(page, r.parameters);
  diagnostics(page, r.diagnostics);
  return page.render(o.title.empty() ? o.method + " fit" : o.title);
}

}  // namespace

std::string html_report(const IdData& data, const Result<AnyModel>& result, const ReportOptions& options) {
  return std::visit(
      [&](const auto& m) {
        using M = std::decay_t<decltype(m)>;
        return report_of(data, Result<M>{m, result.parameters, result.fit, result.summary, result.diagnostics},
                         options);
      },
      result.model);
}

}  // namespace ctid
