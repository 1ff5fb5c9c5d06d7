// HTML reports (io/report.hpp): content and structure; the browser check is in tests/cli (Chromium).
#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/data/input_design.hpp"
#include "ctid/estimate/fsf/fsf.hpp"
#include "ctid/estimate/modal/modal.hpp"
#include "ctid/estimate/transfer_function/srivc.hpp"
#include "ctid/estimate/state_space/ssest.hpp"
#include "estimate/state_space_fixtures.hpp"
#include "ctid/io/report.hpp"
#include "ctid/simulate/lsim.hpp"
#include "test_util.hpp"

using namespace ctid;

namespace {
IdData plant() { return test::second_order_record(); }
int count(const std::string& s, const std::string& what) {
  int n = 0;
  for (size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
  return n;
}
}  // namespace

TEST(Report, TransferFunctionReportHasEverySection) {
  const IdData d = plant();
  const auto r = srivc(d, {.nb = 1, .nf = 2});
  const std::string html = html_report(d, r, {.method = "srivc", .settings = {{"max_iterations", "50"}}});
  for (const char* s : {"<h2>Summary</h2>", "<h2>Method settings</h2>", "<h2>Data</h2>", "Measured and simulated",
                        "<h2>Residual tests</h2>", "<h2>Parameters</h2>", "<h2>Frequency response</h2>",
                        "95 % band", "Step response", "Impulse response", "max_iterations",
                        "Bode phase with the 95 % band", "Step response with the 95 % band"})
    EXPECT_NE(html.find(s), std::string::npos) << s;
  // 10 plots: input, output, compare, 2 correlations, pole-zero map, Bode magnitude and phase, step, impulse.
  EXPECT_EQ(count(html, "class=\"plot\""), 10);
  EXPECT_EQ(count(html, "\"kind\":\"line\""), 9);
  char fit[32];
  std::snprintf(fit, sizeof fit, "fit %.4g %%", r.fit.fit_percent);
  EXPECT_NE(html.find(fit), std::string::npos) << fit;
  for (const char* ref : {"src=\"http", "href=\"http", "url(http", "import("})  // offline: nothing fetched
    EXPECT_EQ(html.find(ref), std::string::npos) << ref;
  EXPECT_TRUE(report_has_plot_library());
}

TEST(Report, SaysWhatTheNumbersMean) {
  // "A report worth sending": the poles as an engineer reads them, parameters within 2 std of 0 flagged,
  // one plain-language line under each residual test, the preprocessing, the command and the version.
  // The record (test::second_order_record) is 4/(s^2 + 0.8 s + 4) at 20 dB: wn = 2 rad/s, zeta = 0.2, DC gain 1.
  const IdData d = plant();
  auto r = srivc(d, {.nb = 1, .nf = 2});
  ReportOptions o{.method = "srivc"};
  o.provenance.preprocessing = {"rows 1..500 of 1000; means removed"};
  o.provenance.command_line = "ctid fit x.csv --method srivc";
  std::string html = html_report(d, r, o);
  for (const char* s : {"<h2>Poles, zeros and gain</h2>", "complex pair", "DC gain G(0)", "<td>preprocessing</td><td>rows "
                        "1..500 of 1000; means removed</td>", "<td>command</td><td>ctid fit x.csv --method srivc</td>",
                        "<td>made by</td><td>ctid "})
    EXPECT_NE(html.find(s), std::string::npos) << s;
  const Eigen::VectorXcd p = r.model.poles();
  const double wn = std::abs(p(0)), zeta = -p(0).real() / wn;
  EXPECT_NEAR(wn, 2.0, 0.05);   // the estimate of the truth's 2 rad/s
  EXPECT_NEAR(zeta, 0.2, 0.02);
  char cell[64];
  std::snprintf(cell, sizeof cell, "<td>%.4g</td>", zeta);
  EXPECT_NE(html.find(cell), std::string::npos) << cell;
  EXPECT_EQ(count(html, "Passed: ") + count(html, "Failed: "), 2);  // one line under each of the two tests
  // The pole-zero map, with the cloud of 200 drawn models' poles (2 each: 400 points) next to the estimate's 2.
  EXPECT_NE(html.find("Pole-zero map with the spread of the parameter covariance"), std::string::npos);
  EXPECT_NE(html.find("\"label\":\"poles of 200 models drawn from the covariance\",\"marker\":\".\",\"light\":true"),
            std::string::npos);
  EXPECT_EQ(html.find("no: |value| &lt; 2 std"), std::string::npos);  // every parameter of the true structure is significant
  // A parameter made insignificant (its std raised above half its value) is flagged, with a note.
  r.parameters.std(0) = 0.6 * std::abs(r.parameters.values(0));
  html = html_report(d, r, o);
  EXPECT_EQ(count(html, "no: |value| &lt; 2 std"), 1);
  EXPECT_NE(html.find("1 parameter(s) lie within two standard deviations of 0"), std::string::npos);
}

TEST(Report, ComparisonPutsModelsSideBySide) {
  // ctid compare's report: the SRIVC fit of the record's structure against a first-order model and a diverging one.
  const IdData d = plant();
  const auto r = srivc(d, {.nb = 1, .nf = 2});
  const TransferFunction first(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 1.0}});
  const TransferFunction unstable(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, -20.0}});
  const auto cs = compare_models(d, {{"srivc <2>", r.model}, {"first", first}, {"unstable", unstable}});
  ReportOptions o;
  o.provenance.command_line = "ctid compare a.json b.json c.json x.csv";
  const std::string html = html_comparison_report(d, cs, o);
  for (const char* s : {"<title>ctid compare</title>", "<h2>Models</h2>", "<td>srivc &lt;2&gt;</td>", "<td>diverges</td>",
                        "<h2>Residual tests</h2>", "Unit step response", "Poles of the linear models",
                        "<td>command</td><td>ctid compare a.json b.json c.json x.csv</td>"})
    EXPECT_NE(html.find(s), std::string::npos) << s;
  char best[96];
  std::snprintf(best, sizeof best, "<td>best fit</td><td>srivc &lt;2&gt; (%.4g %%)</td>", cs[0].fits[0].fit_percent);
  EXPECT_NE(html.find(best), std::string::npos) << best;
  // Plots: input, output, overlay, Bode magnitude and phase, step, poles; every model in the overlay.
  EXPECT_EQ(count(html, "<div class=\"plot"), 7);
  EXPECT_EQ(count(html, "\"label\":\"unstable"), 4);  // overlay, Bode magnitude and phase, poles; not the step
  EXPECT_NE(html.find("unstable: not drawn, it is unstable"), std::string::npos);
  EXPECT_THROW(html_comparison_report(d, {}, o), InvalidArgument);
  EXPECT_THROW(html_comparison_report(d.slice(0, 100), cs, o), InvalidArgument);
}

TEST(Report, MultiInputReportHasAChannelPerInput) {
  // Two inputs through (s + 3)/(s^2 + 2 s + 5) and 2/(s + 1), noise-free, MISO SRIVC: the report shows both
  // inputs, a cross-correlation test per input, and one Bode/step/impulse series per channel.
  const double Ts = 0.02;
  const Eigen::VectorXd t = time_grid(Ts, 2000);
  Eigen::MatrixXd u(2000, 2);
  u << prbs(2000, {.register_length = 8, .clock_period = 7}), prbs(2000, {.register_length = 10, .clock_period = 4});
  const MisoModel g{{TransferFunction(Eigen::VectorXd{{1.0, 3.0}}, Eigen::VectorXd{{1.0, 2.0, 5.0}}),
                     TransferFunction(Eigen::VectorXd{{2.0}}, Eigen::VectorXd{{1.0, 1.0}})}};
  IdData d(u, lsim(g, IdData(u, Eigen::VectorXd::Zero(2000), Ts)), Ts);
  d.set_input_names({"fan", "heater"});
  const auto r = srivc_miso(d, {{2, 2, 0}, {1, 1, 0}});
  ASSERT_TRUE(r.usable()) << r.why_not_usable();
  const std::string html = html_report(d, r, {.method = "srivc"});
  for (const char* s : {"fan (zoh), heater (zoh)", "Input-residual cross-correlation (fan)",
                        "Input-residual cross-correlation (heater)", "G1 (fan)", "G2 (heater)", "u2.b0"})
    EXPECT_NE(html.find(s), std::string::npos) << s;
  // 10 plots: inputs, output, compare, autocorrelation, 2 cross-correlations, Bode magnitude and phase, step, impulse.
  EXPECT_EQ(count(html, "class=\"plot\""), 10);
  EXPECT_THROW(html_report(d.select({0}, {0}), r, {}), InvalidArgument);
}

TEST(Report, StateSpaceReportShowsModesEveryOutputAndEveryChannel) {
  // The two-mode 2 x 2 system, 20 dB noise, ssest with 4 states: the report holds the singular values, a
  // modes table (2 rows, with standard deviations and a shape column per output), each output's comparison whose fit
  // is the fit the estimator reported for that output (same initial state), its residual tests, one Bode magnitude
  // plot and one step plot per input with a curve per output.
  const int N = 1500;
  const Eigen::MatrixXd u = test::ss::levels(N, 2, 7, 3);
  IdData d = test::ss::record(test::ss::two_modes(), u, Eigen::VectorXd::LinSpaced(N, 0.0, (N - 1) * 0.05),
                              Eigen::Vector4d::Zero(), 20.0, 3);
  d.set_output_names({"left", "right"});
  SsestOptions o;
  o.nx = 4;
  const Result<StateSpace> r = ssest(d, o);
  ASSERT_TRUE(r.usable()) << r.why_not_usable();
  const std::string html = html_report(d, r, {.method = "ssest"});
  for (const char* s : {"<h2>Singular values of the subspace step</h2>", "<h2>Modes</h2>", "wn std", "zeta std",
                        "|shape| left", "|shape| right", "<h2>Measured and simulated output (left)</h2>",
                        "<h2>Residual tests (right)</h2>", "Bode magnitude from u1", "Bode magnitude from u2",
                        "Unit step on u2", "outputs</td><td>left, right"})
    EXPECT_NE(html.find(s), std::string::npos) << s;
  for (int j = 0; j < 2; ++j) {
    char fit[64];
    std::snprintf(fit, sizeof fit, "(%s): measured and simulated (fit %.4g %%)", j ? "right" : "left",
                  r.diagnostics.get(diagnostic::output_fit_percent)(j));
    EXPECT_NE(html.find(fit), std::string::npos) << fit;
  }
  // Plots: inputs, outputs, singular values, 2 x (compare, autocorrelation, 2 cross-correlations), 2 Bode, 2 steps.
  EXPECT_EQ(count(html, "class=\"plot\""), 3 + 2 * 4 + 2 + 2);
  EXPECT_THROW(html_report(d.select({0, 1}, {0}), r, {}), InvalidArgument);
}

TEST(Report, DiagnosticsSectionShowsMethodNumbers) {
  // SRIVC reports its delay and noise variance; a modal-function fit (El-Shafey, two sinusoids driving
  // (13 s + 52)/(s^3 + 4 s^2 + 30 s + 52), noise-free) its condition number by order, with a plot.
  const IdData d = plant();
  const std::string h = html_report(d, srivc(d, {.nb = 1, .nf = 2}), {.method = "srivc"});
  EXPECT_NE(h.find("<h2>Diagnostics</h2>"), std::string::npos);
  EXPECT_NE(h.find("noise_variance"), std::string::npos);
  const TransferFunction s3(Polynomial{13.0, 52.0}, Polynomial{1.0, 4.0, 30.0, 52.0});
  const double Ts = 3.141592653589793 / 420;
  const InputGenerator g = InputGenerator::sinusoid(4.0, 1.0) + InputGenerator::sinusoid(1.5, 0.0, 0.7);
  const Eigen::VectorXd t = time_grid(Ts, 1500);
  const IdData sines(g(t), lsim(s3.to_state_space(), g, t), Ts);
  const auto m = modal_fit(sines, 3, {.shifts = Eigen::Vector3d(40 * Ts, 80 * Ts, 120 * Ts), .functions = 10}, &g);
  ASSERT_TRUE(m.usable()) << m.why_not_usable();
  const std::string hm = html_report(sines, m, {.method = "modal"});
  EXPECT_NE(hm.find("Modal functions (El-Shafey)"), std::string::npos);
  EXPECT_NE(hm.find("condition_by_order"), std::string::npos);
  EXPECT_EQ(count(hm, "class=\"plot\""), 11);  // the 10 of a transfer-function report + the condition plot
}

TEST(Report, TextIsEscapedAndScriptsCannotBeInjected) {
  IdData d = plant();
  d.set_output_names({"y</script><script>alert(1)</script>"});
  const auto r = srivc(d, {.nb = 1, .nf = 2});
  const std::string html = html_report(d, r, {.method = "<b>srivc</b>", .data_source = "a&b.csv"});
  EXPECT_EQ(html.find("<b>srivc</b>"), std::string::npos);
  EXPECT_NE(html.find("&lt;b&gt;srivc&lt;/b&gt;"), std::string::npos);
  EXPECT_NE(html.find("a&amp;b.csv"), std::string::npos);
  EXPECT_EQ(html.find("<script>alert(1)"), std::string::npos);
}

TEST(Report, FsfReportHasBandsAndMultiChannelDataIsRejected) {
  const IdData d = plant();
  const auto f = fsf(d, {.T = 20.0, .n = 31});
  const std::string html = html_report(d, f, {.method = "fsf"});
  EXPECT_NE(html.find("Compressed responses"), std::string::npos);
  EXPECT_NE(html.find("\"label\":\"+2 std\""), std::string::npos);
  const IdData mimo(Eigen::MatrixXd::Zero(100, 2), Eigen::MatrixXd::Zero(100, 1), 0.1);
  EXPECT_THROW(html_report(mimo, srivc(d, {.nb = 1, .nf = 2}), {}), InvalidArgument);
}
