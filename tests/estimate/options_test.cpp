// The options tables (estimate/options.hpp) and the method registry (estimate/methods.hpp).
#include <array>
#include <numbers>
#include <functional>
#include <set>

#include <gtest/gtest.h>

#include "ctid/ctid.hpp"
#include "test_util.hpp"

using namespace ctid;

using test::error_of;

// Text forms: numbers, whole numbers written as 1e3, flags, choices, lists, named values, bounds, transfer
// functions "NUM/DEN" (descending powers); each set lands in the struct's member.
TEST(Options, TextFormsSetTheMembers) {
  OeOptions o;
  const auto& t = option_table<OeOptions>();
  t.set(o, "max_iterations", "1e3");
  t.set(o, "tolerance", "2.5e-9");
  t.set(o, "estimate_delay", "yes");
  t.set(o, "fixed.a2", "4");
  t.set(o, "bounds.a1", "0,inf");
  t.set(o, "initial", "3/1,1.2,4");
  t.set(o, "delay_max", "0.5");              // from the nested SRIVC options, same name
  t.set(o, "start_max_iterations", "7");     // the nested SRIVC's max_iterations, renamed
  EXPECT_EQ(o.max_iterations, 1000);
  EXPECT_EQ(o.tolerance, 2.5e-9);
  EXPECT_TRUE(o.estimate_delay);
  EXPECT_EQ(o.fixed.at("a2"), 4.0);
  EXPECT_EQ(o.bounds.at("a1").first, 0.0);
  EXPECT_EQ(o.bounds.at("a1").second, std::numeric_limits<double>::infinity());
  ASSERT_TRUE(o.initial.has_value());
  EXPECT_EQ(o.initial->den().coefficients(), (Eigen::VectorXd{{1.0, 1.2, 4.0}}));
  EXPECT_EQ(o.initial->num().coefficients(), (Eigen::VectorXd{{3.0}}));
  EXPECT_EQ(o.srivc.delay_max, 0.5);
  EXPECT_EQ(o.srivc.max_iterations, 7);
  EXPECT_EQ(o.max_iterations, 1000);  // untouched by the renamed nested field

  LssvfOptions l;
  option_table<LssvfOptions>().set(l, "weights", "trapezoidal");
  EXPECT_EQ(l.weights, SvfWeights::Trapezoidal);
  // Formatting reads back what was set (report settings).
  const auto s = t.settings(o);
  auto value = [&](const std::string& k) {
    for (const auto& [n, v] : s)
      if (n == k) return v;
    return std::string("?");
  };
  EXPECT_EQ(value("initial"), "3/1,1.2,4");
  EXPECT_EQ(value("bounds"), "a1=0,inf");
  EXPECT_EQ(value("start_max_iterations"), "7");
}

// Errors name the method, the setting, the admissible range and the value; an unknown key names the closest.
TEST(Options, ErrorsNameTheSettingTheRangeAndTheClosestName) {
  LssvfOptions l;
  const auto& t = option_table<LssvfOptions>();
  EXPECT_EQ(error_of([&] { t.set(l, "tau_grid", "5"); }).find("lssvf: 'tau_grid' is not a setting; did you mean 'tau_grid_size'?"), 0u);
  EXPECT_NE(error_of([&] { t.set(l, "transient", "1"); }).find("did you mean 'transient_time'?"), std::string::npos);
  EXPECT_NE(error_of([&] { t.set(l, "alhpa", "1"); }).find("did you mean 'alpha'?"), std::string::npos);
  EXPECT_EQ(error_of([&] { t.set(l, "tau", "fast"); }), "lssvf: tau must be a number (got 'fast')");
  EXPECT_EQ(error_of([&] { t.set(l, "tau_grid_size", "2.5"); }), "lssvf: tau_grid_size must be a whole number (got '2.5')");
  EXPECT_EQ(error_of([&] { t.set(l, "weights", "simpson"); }),
            "lssvf: weights must be one of riemann, trapezoidal (got 'simpson')");
  EXPECT_EQ(error_of([&] { t.set(l, "fixed", "3"); }).find("lssvf: fixed must be given per name"), 0u);
  l.tau = -0.5;
  EXPECT_EQ(error_of([&] { l.validate(); }), "lssvf: tau must be > 0, or 0 (automatic) (got -0.5 s)");
  l.tau = 0;
  l.tau_grid_size = 1;
  EXPECT_EQ(error_of([&] { l.validate(); }), "lssvf: tau_grid_size must be in [2, 1000] (got 1)");
  RlsSvfOptions r;
  r.forgetting = 1.5;
  EXPECT_EQ(error_of([&] { r.validate(); }), "rls_svf: forgetting must be in (0, 1] (got 1.5)");
  OeOptions o;
  o.bounds["a1"] = {2, 1};
  EXPECT_EQ(error_of([&] { o.validate(); }), "oe: bounds.a1 must be lower <= upper (got 2,1)");
  o.bounds.clear();
  o.tolerance = std::numeric_limits<double>::infinity();
  EXPECT_EQ(error_of([&] { o.validate(); }), "oe: tolerance must be > 0 (got inf)");
  SrivcOptions so;
  EXPECT_NE(error_of([&] { option_table<SrivcOptions>().set(so, "initial", "1,2"); }).find("NUM/DEN"), std::string::npos);
  // A nested struct's setting is checked under the outer method's name.
  IvsvfOptions iv;
  iv.svf.alpha = -1;
  EXPECT_EQ(error_of([&] { option_table<IvsvfOptions>().check(iv); }), "ivsvf: alpha must be >= 0 (got -1 1/s)");
  EXPECT_EQ(closest_name("xyz_unrelated", {"tau", "alpha"}), "");
}

// One constraint vocabulary: fixed.NAME / bounds.NAME resolve the same way for every estimator —
// an unknown name names the closest parameter, a bound on a held parameter is refused, the rest lands per name.
TEST(Options, ConstraintsResolveByNameForEveryEstimator) {
  const std::vector<std::string> names = {"a1", "a2", "b0"};
  const ParameterConstraints c = resolve_constraints({{"a2", 4.0}}, {{"a1", {0.0, 10.0}}}, names, "oe", "a parameter");
  EXPECT_EQ(c.held, (std::vector<bool>{false, true, false}));
  EXPECT_EQ(c.value(1), 4.0);
  EXPECT_TRUE(std::isnan(c.value(0)));
  EXPECT_EQ(c.lower(0), 0.0);
  EXPECT_EQ(c.upper(0), 10.0);
  EXPECT_EQ(c.lower(2), -std::numeric_limits<double>::infinity());
  EXPECT_EQ(c.free(), (std::vector<int>{0, 2}));
  EXPECT_EQ(error_of([&] { resolve_constraints({{"a3", 1.0}}, {}, names, "oe", "a parameter of this structure"); }),
            "oe: fixed.a3: 'a3' is not a parameter of this structure; did you mean 'a1'?");
  EXPECT_EQ(error_of([&] { resolve_constraints({{"a2", 1.0}}, {{"a2", {0, 1}}}, names, "oe", "a parameter"); }),
            "oe: bounds.a2: 'a2' is held (fixed), so it cannot be bounded");
  EXPECT_EQ(error_of([&] { resolve_constraints({}, {{"a1", {0, 1}}}, names, "nde_oe", "a term", {true, false, false}); }),
            "nde_oe: bounds.a1: 'a1' is held (by the method), so it cannot be bounded");
  // The estimators use it: oe, lssvf, physical (declarations and options together) and nde_oe name the same way.
  const TransferFunction g(Eigen::VectorXd{{3.0}}, Eigen::VectorXd{{1.0, 1.2, 4.0}});
  const Eigen::VectorXd u = prbs(400, {.register_length = 7, .clock_period = 5});
  const IdData d(u, lsim(g, u, time_grid(0.02, 400)), 0.02);
  EXPECT_EQ(error_of([&] { oe(d, {1, 2, 0}, {.fixed = {{"a2", 4.0}}, .bounds = {{"a2", {0.0, 5.0}}}}); }),
            "oe: bounds.a2: 'a2' is held (fixed), so it cannot be bounded");
  EXPECT_NE(error_of([&] { lssvf(d, {1, 2, 0}, {.fixed = {{"b1", 3.0}}}); }).find("lssvf: fixed.b1: 'b1' is not a coefficient"),
            std::string::npos);
  const PhysicalModel pm("3/(s^2 + c*s + k)", {"k", "c"});  // the true system at k = 4, c = 1.2
  PhysicalFitOptions po;
  po.bounds = {{"k", {0.0, 10.0}}};
  EXPECT_EQ(error_of([&] { fit_physical_raw(pm, {{"k", 4.0, -INFINITY, INFINITY, true}, {"c", 1.0}}, d, 0.0, po); }),
            "physical: bounds.k: 'k' is held (fixed), so it cannot be bounded");
  // Held by the option, bounded by the declaration: the option wins (the value is held, the bound is dropped).
  po.bounds.clear();
  po.fixed = {{"k", 4.0}};
  const auto r = fit_physical_raw(pm, {{"k", 3.0, 0.0, 3.5}, {"c", 1.0}}, d, 0.0, po);
  EXPECT_EQ(r.parameters.value("k"), 4.0);
  EXPECT_NEAR(r.parameters.value("c"), 1.2, 1e-6);  // noise-free: c = 1.2 of the true system
}

// The registry: names unique, every setting documented with its default, and the defaults are those of a
// default-constructed options struct (read through the table, checked here against the struct members).
TEST(Options, RegistryListsEachMethodOnceWithDocumentedDefaults) {
  std::set<std::string> names;
  for (const auto& m : methods()) {
    EXPECT_TRUE(names.insert(m.name).second) << m.name;
    EXPECT_FALSE(m.summary.empty());
    EXPECT_FALSE(m.settings.empty()) << m.name;
    std::set<std::string> settings;
    for (const auto& s : m.settings) {
      EXPECT_TRUE(settings.insert(s.name).second) << m.name << "." << s.name;
      EXPECT_FALSE(s.doc.empty()) << m.name << "." << s.name;
    }
  }
  auto default_of = [](const std::string& method, const std::string& name) {
    for (const auto& s : method_info(method).settings)
      if (s.name == name) return s.default_value;
    return std::string("?");
  };
  EXPECT_EQ(default_of("srivc", "max_iterations"), std::to_string(SrivcOptions{}.max_iterations));
  EXPECT_EQ(default_of("oe", "tolerance"), "1e-12");
  EXPECT_EQ(default_of("lssvf", "tau_grid_size"), "12");
  EXPECT_EQ(default_of("fsf", "n"), "0");
  EXPECT_EQ(default_of("physical", "step_points"), "1000");
  EXPECT_EQ(default_of("tfest", "start_max_iterations"), "50");
  EXPECT_EQ(default_of("srivc_closed_loop", "reference_at_plant_input"), "1");
  EXPECT_NE(std::string(settings_help(method_info("srivc"))).find("delay_max"), std::string::npos);
  EXPECT_EQ(error_of([] { method_info("srvic"); }).find("'srvic' is not a method; did you mean 'srivc'?"), 0u);
}

// The same table drives validate(): a struct accepted by every field's range passes, one outside fails.
TEST(Options, ValidateUsesTheTableAndKeepsCrossFieldRules) {
  FsfOptions f;
  f.T = 8;
  f.validate();
  f.n = 20;
  EXPECT_NE(error_of([&] { f.validate(); }).find("must be odd"), std::string::npos);
  f.n = 21;
  f.b = 1;
  EXPECT_NE(error_of([&] { f.validate(); }).find("must not exceed a"), std::string::npos);
  f.a = 2;
  f.validate();
  SrivcOptions s;
  s.delay_min = 2;
  s.delay_max = 1;
  EXPECT_NE(error_of([&] { s.validate(); }).find("the delay range [2, 1] s is empty"), std::string::npos);
}

// Typed diagnostics: every method-specific diagnostic a method's result reports is one the
// registry declares for that method (MethodInfo::diagnostics), every declared name is in the catalogue, and a
// result file's diagnostics are read back only under declared names.
TEST(Options, EveryReportedDiagnosticIsDeclaredForItsMethod) {
  for (const auto& m : methods())
    for (const auto& d : m.diagnostics) EXPECT_NE(find_diagnostic(d), nullptr) << m.name << ": " << d;
  std::set<std::string> names;
  for (const auto& d : diagnostic_catalogue()) EXPECT_TRUE(names.insert(d.name).second) << "twice: " << d.name;
  EXPECT_NE(find_diagnostic("x0_3"), nullptr);  // per record
  EXPECT_EQ(find_diagnostic("tau_2"), nullptr);  // tau is one value per fit
  EXPECT_EQ(find_diagnostic("taus"), nullptr);

  // Two records of 3/(s^2 + 1.2 s + 4) (PRBS and two sines, 0.02 s, 600 samples, noise 0.02).
  const TransferFunction g(Eigen::VectorXd{{3.0}}, Eigen::VectorXd{{1.0, 1.2, 4.0}});
  const int N = 600;
  const Eigen::VectorXd t = time_grid(0.02, N);
  const Eigen::VectorXd u1 = prbs(N, {.register_length = 7, .clock_period = 5});
  Eigen::VectorXd u2(N);
  for (int k = 0; k < N; ++k) u2(k) = std::sin(1.1 * t(k)) + 0.5 * std::sin(3.7 * t(k));
  const IdData a(u1, lsim(g, u1, t) + white_noise(N, 0.02, 1), 0.02), b(u2, lsim(g, u2, t) + white_noise(N, 0.02, 2), 0.02);
  const std::vector<IdData> ab{a, b};
  const TfOrders o{1, 2, 0};
  auto check = [](const std::string& method, const Diagnostics& dg) {
    const auto& declared = method_info(method).diagnostics;
    auto has = [&](const std::string& k) {
      const DiagnosticInfo* d = find_diagnostic(k);
      return d && std::find(declared.begin(), declared.end(), d->name) != declared.end();
    };
    for (const auto& [k, v] : dg.scalars()) EXPECT_TRUE(has(k)) << method << " reports undeclared scalar " << k;
    for (const auto& [k, v] : dg.vectors()) EXPECT_TRUE(has(k)) << method << " reports undeclared vector " << k;
    return dg.scalars().size() + dg.vectors().size();
  };
  EXPECT_GE(check("lssvf", lssvf(ab, o).diagnostics), 4u);
  EXPECT_GE(check("ivsvf", ivsvf(a, o).diagnostics), 3u);
  EXPECT_GE(check("rls_svf", rls_svf(ab, o).diagnostics), 2u);
  EXPECT_GE(check("srivc", srivc(ab, o, {.estimate_delay = true}).diagnostics), 5u);
  EXPECT_GE(check("oe", oe(ab, o).diagnostics), 3u);
  EXPECT_GE(check("tfest", tfest(a, o).diagnostics), 4u);
  const Eigen::MatrixXd u12 = (Eigen::MatrixXd(N, 2) << u1, u2).finished();
  const IdData miso(u12, lsim(g, u1, t) + lsim(g, u2, t) + white_noise(N, 0.02, 3), 0.02);
  EXPECT_GE(check("srivc_miso", srivc_miso(miso, {o, o}).diagnostics), 1u);
  EXPECT_GE(check("fsf", fsf(a, {.T = 6.0, .n = 21}).diagnostics), 4u);
  const PhysicalModel pm("k/(s^2 + c*s + k)", {"k", "c"});
  EXPECT_GE(check("physical", fit_physical_raw(pm, {{"k", 3.0}, {"c", 1.0}}, ab).diagnostics), 3u);
  NarxOptions no;
  no.degree = 1;
  EXPECT_GE(check("narx", narx(ab, no).diagnostics), 2u);
  // modal on a piecewise-constant record of S3 (El-Shafey Ex. 5.2 levels).
  const TransferFunction s3(Eigen::VectorXd{{13.0, 52.0}}, Eigen::VectorXd{{1.0, 4.0, 30.0, 52.0}});
  const double Ts = std::numbers::pi / 320;
  Eigen::VectorXd us(1280);
  for (int i = 0; i < 1280; ++i) us(i) = std::array<double, 4>{1, 2, -1, -2}[(i / 80) % 4];
  const IdData steps(us, lsim(s3, us, time_grid(Ts, 1280)), Ts);
  EXPECT_GE(check("modal", modal_fit(std::vector<IdData>{steps, steps}, 2, {.shifts = Eigen::Vector3d(16, 32, 48) * Ts})
                               .diagnostics),
            3u);

  // Reading back: a result file with an undeclared diagnostic is refused by name.
  Diagnostics dg;
  EXPECT_THROW(dg.set_stored("taus", 1.0), InvalidArgument);
  EXPECT_THROW(dg.set_stored("tau", Eigen::VectorXd::Ones(2)), InvalidArgument);  // declared as a scalar
  dg.set_stored("x0_2", Eigen::VectorXd::Ones(2));
  EXPECT_EQ(dg.get(diagnostic::x0, 1).size(), 2);
  EXPECT_EQ(error_of([&] { dg.get(diagnostic::tau); }), "diagnostic 'tau' was not reported by this fit");
}
