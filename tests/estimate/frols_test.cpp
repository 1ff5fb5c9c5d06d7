// Polynomial NARX models and FROLS/ERR structure detection (Billings & Li 1999 BL-D1, BL-D6).
#include <cmath>
#include <cstdio>
#include <set>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/data/input_design.hpp"
#include "ctid/estimate/nonlinear/frols.hpp"
#include "ctid/validate/metrics.hpp"
#include "ctid/validate/residuals.hpp"
#include "test_util.hpp"

using namespace ctid;

namespace {
// y(k) = 0.5 y(k-1) - 0.2 y(k-2) + 0.3 u(k-1) + 0.2 u(k-2) + 0.1 y(k-1) u(k-1) - 0.05 y(k-2)^2 + noise.
NarxModel truth() {
  std::vector<NarxTerm> t = {NarxTerm::parse("y(k-1)"),        NarxTerm::parse("y(k-2)"),
                             NarxTerm::parse("u(k-1)"),        NarxTerm::parse("u(k-2)"),
                             NarxTerm::parse("y(k-1)*u(k-1)"), NarxTerm::parse("y(k-2)*y(k-2)")};
  return NarxModel(t, (Eigen::VectorXd(6) << 0.5, -0.2, 0.3, 0.2, 0.1, -0.05).finished(), 0.01);
}

// Equation-error noise e(k) inside the recursion (the NARX model class; output noise would need NARMAX terms).
IdData record(int N, double noise, unsigned seed) {
  const Eigen::VectorXd u = white_noise(N, 1.0, seed), e = white_noise(N, noise, seed + 100);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(N);
  for (int k = 2; k < N; ++k)
    y(k) = 0.5 * y(k - 1) - 0.2 * y(k - 2) + 0.3 * u(k - 1) + 0.2 * u(k - 2) + 0.1 * y(k - 1) * u(k - 1) -
           0.05 * y(k - 2) * y(k - 2) + (noise > 0 ? e(k) : 0.0);
  return IdData(u, y, 0.01);
}

std::set<std::string> names(const NarxModel& m) {
  std::set<std::string> s;
  for (const auto& t : m.terms()) s.insert(t.name());
  return s;
}
}  // namespace

TEST(NarxTerm, NamesParseAndCandidateCounts) {
  for (const char* s : {"1", "y(k-1)", "u(k)", "y(k-2)*u(k-13)", "e(k-3)*y(k-1)"})
    EXPECT_EQ(NarxTerm::parse(s).name(), s);
  EXPECT_THROW(NarxTerm::parse("y(k-0)"), InvalidArgument);
  EXPECT_THROW(NarxTerm::parse("y(k)"), InvalidArgument);   // output lag 0
  EXPECT_THROW(NarxTerm::parse("x(k-1)"), InvalidArgument);
  EXPECT_THROW(NarxTerm::parse("y(k-1)*"), InvalidArgument);
  // SysIdentPy's benchmark set: degree 2, lags 1..16 for y and u, with the constant -> 561 candidates.
  EXPECT_EQ(narx_candidates(2, 16, 16).size(), 561u);
  EXPECT_EQ(narx_candidates(3, 2, 2, false).size(), 4u + 10u + 20u);
  EXPECT_EQ(narx_noise_candidates(3, 2, 2).size(), 3u + 6u + 12u);
}

TEST(NarxModel, SimulationPredictionAndEscape) {
  const NarxModel m = truth();
  const Eigen::VectorXd u = white_noise(300, 1.0, 4);
  const Eigen::VectorXd y = m.simulate(u);
  // The one-step predictor on noise-free data reproduces the simulation; so does the 5-step predictor.
  EXPECT_LT((m.predict(u, y, 1) - y).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_LT((m.predict(u, y, 5) - y).cwiseAbs().maxCoeff(), 1e-13);
  // y(k) = 1.5 y(k-1) + u(k-1) escapes: the simulation reports it instead of returning infinities.
  const NarxModel bad({NarxTerm::parse("y(k-1)"), NarxTerm::parse("u(k-1)")}, Eigen::Vector2d(1.5, 1.0), 1.0);
  bool escaped = false;
  const Eigen::VectorXd yb = bad.simulate(Eigen::VectorXd::Ones(2000), {}, &escaped);
  EXPECT_TRUE(escaped);
  EXPECT_TRUE(std::isnan(yb(1999)));
  EXPECT_EQ(m.to_string(2).substr(0, 20), "y(k) = 0.5 y(k-1) - ");
}

TEST(Frols, FindsTheTrueStructureOnNoiseFreeData) {
  // 15 candidates (degree 2, lags 2/2, constant); the ERR pass must pick exactly the 6 true terms (the
  // residual after them is zero: ESR < 1e-20) with the coefficients to 1e-10.
  // Degree 3 (34 candidates) exercises the grouping of the cubic candidates' inner products by prefix.
  const IdData d = record(2000, 0.0, 1);
  for (int degree : {3, 2}) {
    const auto r3 = frols(d, narx_candidates(degree, 2, 2), {.max_terms = 10, .err_tolerance = 1e-14});
    EXPECT_EQ(names(r3.model), names(truth())) << "degree " << degree;
  }
  const auto r = frols(d, narx_candidates(2, 2, 2), {.max_terms = 10, .err_tolerance = 1e-14});
  ASSERT_TRUE(r.usable()) << r.why_not_usable();
  EXPECT_EQ(names(r.model), names(truth()));
  EXPECT_LT(r.diagnostics.get(diagnostic::esr), 1e-14);
  for (size_t i = 0; i < r.model.terms().size(); ++i)
    for (size_t j = 0; j < truth().terms().size(); ++j)
      if (r.model.terms()[i] == truth().terms()[j])
        EXPECT_NEAR(r.model.coefficients()(i), truth().coefficients()(j), 1e-10) << r.model.terms()[i].name();
  EXPECT_GT(r.fit.fit_percent, 99.999);
  EXPECT_NEAR(r.diagnostics.get(diagnostic::err).sum(), 100.0, 1e-9);
}

TEST(Frols, CoefficientsEqualLeastSquaresOnTheSelectedColumnsAndCriteriaPickTheSize) {
  // With equation noise, the FROLS coefficients must equal ordinary least squares on the selected columns
  // (same rows) to round-off. AIC / BIC read off the single pass keep every true term; the greedy order
  // (u(k-2), u(k-1), u(k-3), ... y(k-2) ninth) lets a few correlated spurious terms in first — measured:
  // AIC 10 terms, BIC 9 — whose coefficients are insignificant (within 4 standard deviations of zero).
  const IdData d = record(5000, 0.02, 2);
  const auto cand = narx_candidates(2, 3, 3);
  for (auto c : {InformationCriterion::Aic, InformationCriterion::Bic}) {
    const auto r = frols(d, cand, {.max_terms = 15, .criterion = c, .block_rows = 512});
    const auto got = names(r.model), want = names(truth());
    for (const auto& t : want) EXPECT_TRUE(got.count(t)) << t << " missing, criterion " << static_cast<int>(c);
    EXPECT_LE(got.size(), 10u);
    for (int i = 0; i < r.parameters.size(); ++i)
      if (!want.count(r.parameters.names[i]))
        EXPECT_LT(std::abs(r.parameters.values(i)), 4 * r.parameters.std(i)) << r.parameters.names[i];
    EXPECT_EQ(r.diagnostics.get(diagnostic::criterion).size(), 15);
    // Least squares on the same columns and rows.
    const Eigen::Index L = 3, Ne = d.size() - L;
    Eigen::MatrixXd P(Ne, r.model.terms().size());
    for (size_t m = 0; m < r.model.terms().size(); ++m)
      for (Eigen::Index k = 0; k < Ne; ++k) {
        double v = 1;
        for (const auto& f : r.model.terms()[m].factors)
          v *= (f.signal == NarxSignal::Output ? d.y()(k + L - f.lag, 0) : d.u()(k + L - f.lag, 0));
        P(k, static_cast<Eigen::Index>(m)) = v;
      }
    const Eigen::VectorXd ls = P.colPivHouseholderQr().solve(d.y().col(0).tail(Ne));
    EXPECT_LT((ls - r.model.coefficients()).cwiseAbs().maxCoeff(), 1e-10);
    EXPECT_LT((r.model.coefficients() - r.parameters.values).norm(), 1e-15);
    EXPECT_GT(r.parameters.std.minCoeff(), 0.0);
  }
}

TEST(Frols, BadInputs) {
  const IdData d = record(100, 0.0, 3);
  EXPECT_THROW(frols(d, narx_candidates(2, 16, 16)), InvalidArgument);  // 561 candidates, 84 rows
  EXPECT_THROW(frols(d, {NarxTerm::parse("e(k-1)")}), InvalidArgument);  // noise term
  EXPECT_THROW(frols(d, narx_candidates(1, 2, 2), {.max_terms = 0}), InvalidOptions);
  EXPECT_THROW(narx_candidates(0, 2, 2), InvalidArgument);
}

TEST(Narmax, NoiseTermsRemoveTheBiasOfOutputNoiseAndTheResidualsPassTheCorrelationTests) {
  // x(k) = 0.7 x(k-1) + 0.3 u(k-1) + 0.1 x(k-1) u(k-1), measured y = x + v (white, std 0.1 against std(x) 0.43):
  // the equation error is coloured (v(k) - 0.7 v(k-1) - 0.1 v(k-1) u(k-1)). NARX (BIC) compensates with wrong
  // terms; NARMAX selects e(k-1) and e(k-1)u(k-1) and recovers the process (measured: 0.7006, 0.3009, 0.1043).
  const int N = 4000;
  const Eigen::VectorXd u = white_noise(N, 1.0, 7), v = white_noise(N, 0.1, 8);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(N);
  for (int k = 1; k < N; ++k) x(k) = 0.7 * x(k - 1) + 0.3 * u(k - 1) + 0.1 * x(k - 1) * u(k - 1);
  const IdData d(u, x + v, 1.0);
  const auto cand = narx_candidates(2, 2, 2);
  const FrolsOptions fo{.max_terms = 10, .criterion = InformationCriterion::Bic};
  const auto narx = frols(d, cand, fo);
  const auto r = narmax(d, cand, {.frols = fo});
  EXPECT_TRUE(r.diagnostics.warnings.empty()) << r.diagnostics.warnings[0];
  const NarxModel p = r.model.process();
  EXPECT_EQ(names(p), (std::set<std::string>{"y(k-1)", "u(k-1)", "y(k-1)*u(k-1)"}));
  for (int i = 0; i < static_cast<int>(p.terms().size()); ++i) {
    const std::string n = p.terms()[i].name();
    const double truth_i = n == "y(k-1)" ? 0.7 : n == "u(k-1)" ? 0.3 : 0.1;
    EXPECT_NEAR(p.coefficients()(i), truth_i, 0.01) << n;
  }
  EXPECT_TRUE(r.model.has_noise_terms());
  // NARX's coefficient of y(k-1) is far from 0.7 (its structure absorbs the noise).
  for (int i = 0; i < narx.parameters.size(); ++i)
    if (narx.parameters.names[i] == "y(k-1)") EXPECT_GT(std::abs(narx.parameters.values(i) - 0.7), 0.2);
  // Billings-Voon tests (95 % bounds, 20 lags): the NARX residuals are coloured (phi_ee outside); the NARMAX
  // one-step residuals are as good as the true noise v itself, whose counts outside the bounds on this seed are
  // (ee 0, ue 5 of 41, e(eu) 1, u2e 1, u2e2 2) — at 95 % about 1 in 20 lags is expected outside.
  const Eigen::VectorXd y = d.y().col(0);
  const auto bad = nonlinear_correlation_tests(u, y - narx.model.predict(u, y), 20);
  const auto good = nonlinear_correlation_tests(u, y - r.model.predict(u, y), 20);
  const auto ideal = nonlinear_correlation_tests(u, v, 20);
  EXPECT_GE(bad.ee.n_outside, 3);  // measured: 4 lags outside
  EXPECT_FALSE(bad.passed());
  EXPECT_LE(good.ee.n_outside, ideal.ee.n_outside + 1);
  EXPECT_LE(good.ue.n_outside, ideal.ue.n_outside + 1);
  EXPECT_LE(good.e_eu.n_outside, ideal.e_eu.n_outside + 1);
  EXPECT_LE(good.u2_e.n_outside, ideal.u2_e.n_outside + 1);
  EXPECT_LE(good.u2_e2.n_outside, ideal.u2_e2.n_outside + 1);
}

namespace {
// A record of truth() with input amplitude `amp`, started from the outputs y(0), y(1) = y0.
IdData record_from(int N, double noise, unsigned seed, double amp, Eigen::Vector2d y0) {
  const Eigen::VectorXd u = white_noise(N, amp, seed), e = white_noise(N, noise, seed + 100);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(N);
  y.head(2) = y0;
  for (int k = 2; k < N; ++k)
    y(k) = 0.5 * y(k - 1) - 0.2 * y(k - 2) + 0.3 * u(k - 1) + 0.2 * u(k - 2) + 0.1 * y(k - 1) * u(k - 1) -
           0.05 * y(k - 2) * y(k - 2) + e(k);
  return IdData(u, y, 0.01);
}
}  // namespace

// Several records: FROLS on two records is least squares on the two records' rows stacked — no
// row reaches across the records (checked against a direct solve to 1e-10); over 60 noisy runs with two records of
// different input amplitude and initial state the joint estimate is more accurate than either record's for every
// coefficient, and its reported standard deviation matches the spread (within 25 %: 60 runs estimate a spread to
// ~9 %).
TEST(Frols, SeveralRecordsAreOneStackedRegressionMoreAccurateThanEither) {
  const std::vector<NarxTerm> terms = truth().terms();
  FrolsOptions o;
  o.err_tolerance = 0.0;  // select all six candidates: the same structure for every fit
  {
    const IdData a = record_from(300, 0.05, 1, 1.0, {0, 0}), b = record_from(200, 0.05, 2, 0.5, {2.0, -1.0});
    const Result<NarxModel> r = frols(std::vector<IdData>{a, b}, terms, o);
    ASSERT_EQ(r.parameters.size(), 6);
    Eigen::MatrixXd P(300 - 2 + 200 - 2, 6);
    Eigen::VectorXd Y(P.rows());
    int row = 0;
    for (const IdData* d : {&a, &b})
      for (int k = 2; k < d->size(); ++k, ++row) {
        const double y1 = d->y()(k - 1, 0), y2 = d->y()(k - 2, 0), u1 = d->u()(k - 1, 0), u2 = d->u()(k - 2, 0);
        P.row(row) << y1, y2, u1, u2, y1 * u1, y2 * y2;
        Y(row) = d->y()(k, 0);
      }
    const Eigen::VectorXd ls = P.colPivHouseholderQr().solve(Y);
    for (int i = 0; i < 6; ++i) {
      const auto at = std::find(r.model.terms().begin(), r.model.terms().end(), terms[i]) - r.model.terms().begin();
      EXPECT_NEAR(r.model.coefficients()(at), ls(i), 1e-10) << terms[i].name();
    }
  }
  const int R = 60;
  const Eigen::VectorXd truth_c = truth().coefficients();
  Eigen::MatrixXd e1(R, 6), e2(R, 6), ej(R, 6), sj(R, 6);
  auto errors = [&](const Result<NarxModel>& r, Eigen::MatrixXd& e, int run, Eigen::MatrixXd* s) {
    for (int i = 0; i < 6; ++i) {
      const auto at = std::find(r.model.terms().begin(), r.model.terms().end(), terms[i]) - r.model.terms().begin();
      e(run, i) = r.model.coefficients()(at) - truth_c(i);
      if (s) (*s)(run, i) = r.parameters.std(at);
    }
  };
  for (int run = 0; run < R; ++run) {
    const IdData a = record_from(400, 0.1, 1000 + 2 * run, 1.0, {0, 0});
    const IdData b = record_from(400, 0.1, 1001 + 2 * run, 0.6, {1.5, -0.5});
    errors(frols(a, terms, o), e1, run, nullptr);
    errors(frols(b, terms, o), e2, run, nullptr);
    errors(frols(std::vector<IdData>{a, b}, terms, o), ej, run, &sj);
  }
  for (int i = 0; i < 6; ++i) {
    auto rmse = [&](const Eigen::MatrixXd& e) { return std::sqrt(e.col(i).squaredNorm() / R); };
    const double mean = ej.col(i).mean(), sd = std::sqrt((ej.col(i).array() - mean).square().sum() / (R - 1));
    std::printf("%s: rmse joint %.4g, record 1 %.4g, record 2 %.4g; reported std / spread %.3f\n", terms[i].name().c_str(),
                rmse(ej), rmse(e1), rmse(e2), sj.col(i).mean() / sd);
    EXPECT_LT(rmse(ej), std::min(rmse(e1), rmse(e2))) << terms[i].name();
    EXPECT_NEAR(sj.col(i).mean() / sd, 1.0, 0.25) << terms[i].name();
  }
  // Records at different sampling periods, or shorter than the largest lag, are refused naming the record.
  const IdData a = record_from(100, 0.0, 5, 1.0, {0, 0});
  EXPECT_NE(test::error_of([&] { frols(std::vector<IdData>{a, IdData(a.u(), a.y(), 0.02)}, terms, o); })
                .find("record 2 is sampled at 0.02 s, record 1 at 0.01 s"),
            std::string::npos);
  EXPECT_NE(test::error_of([&] { frols(std::vector<IdData>{a, record_from(100, 0.0, 6, 1.0, {1.0, 2.0}).slice(0, 2)}, terms, o); }).find("record 2 has 2 samples"),
            std::string::npos);
}

TEST(Frols, StreamedPassesDoNotDependOnTheBlockAndTheFitIsEachRecordsFreeRun) {
  // FROLS regenerates the orthogonal columns and simulates the fit block by block (no N-length buffers). The block
  // size must change nothing beyond round-off: selection, coefficients, ERR, and the fit, which must equal the
  // pooled free runs of NarxModel::simulate from each record's own first L outputs (the independent reference,
  // computed here with fit_report_or_inf over whole vectors). Block sizes 16 and 4096 against 10 000 rows: the
  // 16-row blocks cross every record boundary and lag mask.
  const auto cand = narx_candidates(2, 2, 2);
  const IdData one = record(10000, 0.02, 4);
  const std::vector<IdData> two = {record_from(3001, 0.02, 7, 1.0, {0, 0}), record_from(2003, 0.02, 8, 0.7, {1.0, -0.5})};
  for (int records : {1, 2}) {
    auto fit = [&](int block) {
      const FrolsOptions o{.max_terms = 8, .block_rows = block};
      return records == 1 ? frols(one, cand, o) : frols(two, cand, o);
    };
    const Result<NarxModel> a = fit(16), b = fit(4096);
    ASSERT_EQ(a.parameters.names, b.parameters.names);
    EXPECT_LT((a.parameters.values - b.parameters.values).cwiseAbs().maxCoeff(), 1e-12 * b.parameters.values.cwiseAbs().maxCoeff());
    EXPECT_LT((a.diagnostics.get(diagnostic::err) - b.diagnostics.get(diagnostic::err)).cwiseAbs().maxCoeff(), 1e-10);
    // The reference fit of b's model.
    const NarxModel process = b.model.process();
    const Eigen::Index L = 2;
    Eigen::VectorXd ym, ys;
    for (const IdData& d : records == 1 ? std::vector<IdData>{one} : two) {
      const Eigen::VectorXd run = process.simulate(d.u().col(0), d.y().col(0).head(L));
      const Eigen::Index n = d.size() - L, at = ym.size();
      ym.conservativeResize(at + n);
      ys.conservativeResize(at + n);
      ym.tail(n) = d.y().col(0).tail(n);
      ys.tail(n) = run.tail(n);
    }
    const FitReport ref = fit_report_or_inf(ym, ys, static_cast<int>(b.parameters.size()));
    for (const Result<NarxModel>* r : {&a, &b}) {
      EXPECT_EQ(r->fit.n_samples, ref.n_samples);
      EXPECT_NEAR(r->fit.fit_percent, ref.fit_percent, 1e-9 * std::abs(ref.fit_percent)) << records << " records";
      EXPECT_NEAR(r->fit.mse, ref.mse, 1e-10 * ref.mse);
      EXPECT_NEAR(r->fit.aic, ref.aic, 1e-9 * std::abs(ref.aic));
    }
  }
}

TEST(Frols, GramRouteAgreesWithThePasses) {
  // The two routes to the same greedy selection (FrolsOptions::route): K + 2 passes of Gram-Schmidt on regenerated
  // columns, or the candidates' Gram matrix from one pass (fast orthogonal search). On one record, on two (the lag
  // mask between them) and on 165 degree-3 candidates: the same terms, coefficients to 1e-8 and ERR to 1e-8 %
  // (measured: 2.4e-15 and 7.8e-14 %; on collinear lag sets — a binary input, 2 ms sampling — a study found 1e-9).
  const IdData one = record(10000, 0.02, 4);
  const std::vector<IdData> two = {record_from(3001, 0.02, 7, 1.0, {0, 0}), record_from(2003, 0.02, 8, 0.7, {1.0, -0.5})};
  struct Case {
    std::vector<NarxTerm> cand;
    int records, terms;
  };
  for (const Case& c : {Case{narx_candidates(2, 2, 2), 1, 8}, Case{narx_candidates(2, 2, 2), 2, 8},
                        Case{narx_candidates(3, 4, 4), 1, 12}}) {
    auto fit = [&](FrolsRoute route) {
      const FrolsOptions o{.max_terms = c.terms, .route = route};
      return c.records == 1 ? frols(one, c.cand, o) : frols(two, c.cand, o);
    };
    const Result<NarxModel> passes = fit(FrolsRoute::Passes), gram = fit(FrolsRoute::Gram);
    ASSERT_EQ(passes.parameters.names, gram.parameters.names) << c.cand.size() << " candidates";
    EXPECT_LT((passes.parameters.values - gram.parameters.values).cwiseAbs().maxCoeff(),
              1e-8 * passes.parameters.values.cwiseAbs().maxCoeff());
    EXPECT_LT((passes.diagnostics.get(diagnostic::err) - gram.diagnostics.get(diagnostic::err)).cwiseAbs().maxCoeff(), 1e-8);
    EXPECT_NEAR(passes.fit.fit_percent, gram.fit.fit_percent, 1e-6);
    EXPECT_NEAR(passes.parameters.std(0), gram.parameters.std(0), 1e-6 * passes.parameters.std(0));
  }
  // Auto takes the Gram matrix for 15 candidates of degree 2 (86 moments per row against 7 passes of 25 products) and
  // the passes for 561 (lags 1..16: the Gram matrix would need more than 50 000 moments, which route=gram refuses).
  const auto small = narx_candidates(2, 2, 2), large = narx_candidates(2, 16, 16);
  EXPECT_EQ(frols(one, small, {.max_terms = 8}).parameters.values, frols(one, small, {.max_terms = 8, .route = FrolsRoute::Gram}).parameters.values);
  EXPECT_EQ(frols(one, large, {.max_terms = 4}).parameters.values,
            frols(one, large, {.max_terms = 4, .route = FrolsRoute::Passes}).parameters.values);
  try {
    frols(one, large, {.max_terms = 4, .route = FrolsRoute::Gram});
    ADD_FAILURE() << "route=gram accepted 561 candidates";
  } catch (const InvalidOptions& e) {
    EXPECT_NE(std::string(e.what()).find("more than 50000 moments for these 561 candidates"), std::string::npos) << e.what();
  }
}
