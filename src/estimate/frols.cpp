// FROLS / ERR structure detection for polynomial NARX models (Billings & Li 1999, BL 28-32;
// SEEDS-SPEC BL-D1, BL-D6). See include/ctid/estimate/frols.hpp.
//
// With p_m the candidate columns, w_s the orthogonalised selected columns and g_s = w_s^T y / w_s^T w_s,
// the orthogonal part of an unselected candidate m after s selections has
//     w_m^T y = p_m^T y - sum_s (p_m^T w_s) g_s,   w_m^T w_m = p_m^T p_m - sum_s (p_m^T w_s)^2 / (w_s^T w_s),
// so ERR_m = (w_m^T y)^2 / (w_m^T w_m y^T y) needs only the inner products c_sm = p_m^T w_s: one pass over
// freshly generated candidate blocks per selected term.
#include "ctid/estimate/frols.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "ctid/core/check.hpp"
#include "ctid/core/progress.hpp"
#include "ctid/validate/metrics.hpp"
#include "data/record_refs.hpp"

namespace ctid {

template <>
const OptionTable<FrolsOptions>& option_table<FrolsOptions>() {
  using O = FrolsOptions;
  static const OptionTable<O> t =
      OptionTable<O>("frols")
          .integer("max_terms", &O::max_terms, "", at_least(1), "upper bound on the number of selected terms")
          .real("err_tolerance", &O::err_tolerance, "", OptionRange{0, 1, false, true, {}, {}},
                "stop when 1 - sum(ERR) <= err_tolerance (0: only max_terms and the criterion)")
          .choice("criterion", &O::criterion,
                  {{"none", InformationCriterion::None}, {"aic", InformationCriterion::Aic},
                   {"aicc", InformationCriterion::Aicc}, {"bic", InformationCriterion::Bic},
                   {"fpe", InformationCriterion::Fpe}},
                  "model size: the number of terms minimising it along the greedy pass (none: all selected)")
          .integer("block_rows", &O::block_rows, "", at_least(16), "rows of candidate columns generated at a time (memory)");
  return t;
}

void FrolsOptions::validate() const { option_table<FrolsOptions>().check(*this); }

namespace {
// Candidate columns for rows [k0, k0 + rows) into the columns of B.
// The three signals a candidate can refer to (e: residuals of the previous NARMAX iteration).
// (Read in place: a record's own columns, or the concatenation of several; e empty when no candidate has a noise factor.)
struct Signals {
  Eigen::Ref<const Eigen::VectorXd> y, u, e;
  const Eigen::Ref<const Eigen::VectorXd>& of(NarxSignal s) const {
    return s == NarxSignal::Output ? y : s == NarxSignal::Input ? u : e;
  }
};

void candidate_block(const std::vector<NarxTerm>& cand, const Signals& sig, Eigen::Index k0, Eigen::Index rows,
                     Eigen::MatrixXd& B) {
  for (size_t m = 0; m < cand.size(); ++m) {
    auto col = B.col(static_cast<Eigen::Index>(m)).head(rows);
    col.setOnes();
    for (const auto& f : cand[m].factors) {
      col.array() *= sig.of(f.signal).segment(k0 - f.lag, rows).array();
    }
  }
}

// Inner products of every candidate with a vector w, without forming the candidate columns: a candidate
// is prefix * x_a * x_b (x_0 = 1, x_1.. the distinct lagged signals), so for each distinct prefix the
// (V+1) x (V+1) matrix Z = (X o (w o prefix))^T X holds all of them — a small matrix product per row block.
class CandidateProducts {
 public:
  CandidateProducts(const std::vector<NarxTerm>& cand) {
    auto var = [&](const NarxFactor& f) {
      for (size_t i = 0; i < vars_.size(); ++i)
        if (vars_[i] == f) return static_cast<int>(i) + 1;
      vars_.push_back(f);
      return static_cast<int>(vars_.size());
    };
    for (const auto& t : cand) {
      Item it;
      const int d = t.degree();
      std::vector<int> prefix;
      for (int i = 0; i + 2 < d; ++i) prefix.push_back(var(t.factors[i]));
      it.a = d >= 2 ? var(t.factors[d - 2]) : 0;
      it.b = d >= 1 ? var(t.factors[d - 1]) : 0;
      auto g = std::find(prefixes_.begin(), prefixes_.end(), prefix);
      it.group = static_cast<int>(g - prefixes_.begin());
      if (g == prefixes_.end()) prefixes_.push_back(prefix);
      items_.push_back(it);
    }
  }

  // c_m = sum_k p_m(k) w(k) over rows k = L .. L + Ne - 1 (w indexed from 0); squared: sum_k p_m(k)^2 w(k).
  Eigen::VectorXd dot(const Signals& sig, Eigen::Index L, const Eigen::VectorXd& w, Eigen::Index block,
                      bool squared = false) const {
    const Eigen::Index Ne = w.size(), V = static_cast<Eigen::Index>(vars_.size()) + 1;
    std::vector<Eigen::MatrixXd> Z(prefixes_.size(), Eigen::MatrixXd::Zero(V, V));
    Eigen::MatrixXd X(block, V), Vw(block, V);
    Eigen::VectorXd om(block);
    for (Eigen::Index r0 = 0; r0 < Ne; r0 += block) {
      const Eigen::Index rows = std::min(block, Ne - r0);
      X.col(0).head(rows).setOnes();
      for (size_t i = 0; i < vars_.size(); ++i) {
        X.col(static_cast<Eigen::Index>(i) + 1).head(rows) = sig.of(vars_[i].signal).segment(L + r0 - vars_[i].lag, rows);
      }
      if (squared) X.topRows(rows) = X.topRows(rows).array().square().matrix();
      for (size_t g = 0; g < prefixes_.size(); ++g) {
        om.head(rows) = w.segment(r0, rows);
        for (int v : prefixes_[g]) om.head(rows).array() *= X.col(v).head(rows).array();
        Vw.topRows(rows) = om.head(rows).asDiagonal() * X.topRows(rows);
        // X^T diag(om) X is symmetric: the lower triangle is enough.
        Z[g].triangularView<Eigen::Lower>() += Vw.topRows(rows).transpose() * X.topRows(rows);
      }
    }
    Eigen::VectorXd c(static_cast<Eigen::Index>(items_.size()));
    for (size_t m = 0; m < items_.size(); ++m) {
      const Item& it = items_[m];
      c(static_cast<Eigen::Index>(m)) = Z[it.group](std::max(it.a, it.b), std::min(it.a, it.b));
    }
    return c;
  }

 private:
  struct Item {
    int group = 0, a = 0, b = 0;
  };
  std::vector<NarxFactor> vars_;
  std::vector<std::vector<int>> prefixes_;
  std::vector<Item> items_;
};

// Several records are concatenated; a regression row k (signal index) belongs to the record that starts at
// the largest start <= k and is used only when all its lags stay inside that record (k - start >= L). The
// mask over rows k = L .. N-1 is 1 for used rows and 0 for rows whose lags reach into the previous record.
Eigen::VectorXd row_mask(const std::vector<Eigen::Index>& starts, Eigen::Index N, Eigen::Index L) {
  Eigen::VectorXd mask = Eigen::VectorXd::Ones(std::max<Eigen::Index>(0, N - L));
  for (Eigen::Index s : starts)
    for (Eigen::Index k = std::max(s, L); k < std::min(s + L, N); ++k) mask(k - L) = 0.0;
  return mask;
}

double criterion_value(InformationCriterion c, double mse, int n, int k) {
  switch (c) {
    case InformationCriterion::Aic: return aic(mse, n, k);
    case InformationCriterion::Aicc: return aicc(mse, n, k);
    case InformationCriterion::Bic: return bic(mse, n, k);
    case InformationCriterion::Fpe: return fpe(mse, n, k);
    case InformationCriterion::None: break;
  }
  return 0.0;
}
}  // namespace

namespace {
// FROLS on given signals (e may be all zero when no candidate is a noise term): the records concatenated,
// record r starting at starts[r] (starts[0] = 0); rows whose lags cross into the previous record are masked out
// of every inner product (row_mask), so the regression is the stack of the records' own regressions.
Result<NarxModel> frols_signals(const Signals& sig, const std::vector<Eigen::Index>& starts, double Ts,
                                const std::vector<NarxTerm>& cand, const FrolsOptions& o) {
  const auto t_start = std::chrono::steady_clock::now();
  int L = 0;
  for (const auto& t : cand) L = std::max(L, t.max_lag());
  const auto& y = sig.y;
  const auto& u = sig.u;
  const Eigen::Index N = y.size(), Ne = N - L;
  const int M = static_cast<int>(cand.size());
  for (size_t r = 0; r < starts.size() && starts.size() > 1; ++r) {  // one record: the row count below says it
    const Eigen::Index n = (r + 1 < starts.size() ? starts[r + 1] : N) - starts[r];
    CTID_REQUIRE(n > L, "frols: record {} has {} samples, not more than the largest lag {}", r + 1, n, L);
  }
  const Eigen::VectorXd mask = row_mask(starts, N, L);
  const Eigen::Index rows_used = static_cast<Eigen::Index>(mask.sum());
  CTID_REQUIRE(rows_used > M, "frols: {} candidate terms but only {} usable rows ({} samples minus the largest lag {}{}); "
               "reduce the lags or the degree", M, rows_used, N, L, starts.size() > 1 ? " in each record" : "");
  const Eigen::VectorXd yt = y.tail(Ne).cwiseProduct(mask);
  const double yy = yt.squaredNorm();
  CTID_REQUIRE(yy > 0, "frols: the output is identically zero");
  const int K = std::min(o.max_terms, M);
  const Eigen::Index BR = std::min<Eigen::Index>(o.block_rows, Ne);

  // Pass 0: p_m^T y and p_m^T p_m.
  const CandidateProducts products(cand);
  const Eigen::VectorXd py = products.dot(sig, L, yt, BR);
  const Eigen::VectorXd pp = products.dot(sig, L, mask, BR, true);

  std::vector<int> sel;
  std::vector<double> err, g, ww;
  Eigen::MatrixXd C(K, M);   // C(s, m) = p_m^T w_s
  Eigen::MatrixXd W(Ne, K);  // orthogonal columns of the selected terms
  std::vector<bool> used(M, false);
  Eigen::VectorXd crit(K);
  Eigen::VectorXd p(Ne);     // the column of the term being selected, then its orthogonal part
  double err_sum = 0;
  bool interrupted = false;
  for (int s = 0; s < K; ++s) {
    if (s > 0 && !report_progress("frols", s, 1 - err_sum)) {
      interrupted = true;
      break;
    }
    int best = -1;
    double best_err = -1;
    for (int m = 0; m < M; ++m) {
      if (used[m] || !(pp(m) > 0)) continue;
      double num = py(m), den = pp(m);
      for (int r = 0; r < s; ++r) {
        num -= C(r, m) * g[r];
        den -= C(r, m) * C(r, m) / ww[r];
      }
      if (!(den > 1e-10 * pp(m))) continue;  // (numerically) in the span of the selected terms
      const double e = num * num / (den * yy);
      if (e > best_err) {
        best_err = e;
        best = m;
      }
    }
    if (best < 0) break;
    // w_s = p_best - sum_r (c_r,best / ww_r) w_r, then c_s,m = p_m^T w_s for every candidate.
    for (Eigen::Index r0 = 0; r0 < Ne; r0 += BR) {
      const Eigen::Index rows = std::min(BR, Ne - r0);
      Eigen::MatrixXd one(rows, 1);
      candidate_block({cand[best]}, sig, L + r0, rows, one);
      p.segment(r0, rows) = one.col(0);
    }
    p.array() *= mask.array();
    for (int r = 0; r < s; ++r) p -= (C(r, best) / ww[r]) * W.col(r);
    W.col(s) = p;
    const double w2 = p.squaredNorm();
    C.row(s) = products.dot(sig, L, W.col(s), BR).transpose();
    used[best] = true;
    sel.push_back(best);
    ww.push_back(w2);
    g.push_back(W.col(s).dot(yt) / w2);
    err.push_back(g.back() * g.back() * w2 / yy);
    err_sum += err.back();
    const double mse_k = std::max(0.0, yy * (1 - err_sum)) / static_cast<double>(rows_used);
    crit(s) = criterion_value(o.criterion, mse_k, static_cast<int>(rows_used), s + 1);
    if (o.criterion == InformationCriterion::None && 1 - err_sum <= o.err_tolerance) break;
  }
  CTID_REQUIRE(!sel.empty(), "frols: every candidate column is zero");
  int k = static_cast<int>(sel.size());
  if (o.criterion != InformationCriterion::None) {
    Eigen::Index best;
    crit.head(k).minCoeff(&best);
    k = static_cast<int>(best) + 1;
  }
  // theta from A theta = g, A unit upper triangular with A(r, s) = c_r,sel(s) / ww_r.
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(k, k);
  for (int s = 0; s < k; ++s)
    for (int r = 0; r < s; ++r) A(r, s) = C(r, sel[s]) / ww[r];
  Eigen::VectorXd gv(k), winv(k);
  for (int s = 0; s < k; ++s) {
    gv(s) = g[s];
    winv(s) = 1.0 / ww[s];
  }
  const auto Atri = A.triangularView<Eigen::UnitUpper>();
  const Eigen::VectorXd theta = Atri.solve(gv);
  double esr = 1;
  for (int s = 0; s < k; ++s) esr -= err[s];
  const double sigma2 = std::max(0.0, yy * esr) / static_cast<double>(std::max<Eigen::Index>(1, rows_used - k));
  const Eigen::MatrixXd Ainv = Atri.solve(Eigen::MatrixXd::Identity(k, k));
  const Eigen::MatrixXd cov = sigma2 * Ainv * winv.asDiagonal() * Ainv.transpose();

  std::vector<NarxTerm> terms;
  Result<NarxModel> res;
  for (int s = 0; s < k; ++s) {
    terms.push_back(cand[sel[s]]);
    res.parameters.names.push_back(cand[sel[s]].name());
  }
  res.model = NarxModel(terms, theta, Ts);
  res.parameters.values = theta;
  res.parameters.fixed.assign(k, false);
  res.parameters.set_covariance(cov);
  res.diagnostics.set(diagnostic::err, 100.0 * Eigen::Map<const Eigen::VectorXd>(err.data(), k));
  if (o.criterion != InformationCriterion::None)
    res.diagnostics.set(diagnostic::criterion, crit.head(static_cast<Eigen::Index>(sel.size())));
  res.diagnostics.set(diagnostic::esr, esr);
  res.diagnostics.set(diagnostic::candidates, M);
  res.diagnostics.condition_number = Ainv.norm() * A.norm();
  // The fit: each record's free run from its own first L measured outputs, pooled after those L samples.
  const NarxModel process = res.model.process();
  Eigen::VectorXd ypool(N - L * static_cast<Eigen::Index>(starts.size())), spool(ypool.size());
  bool escaped = false;
  for (size_t r = 0, at = 0; r < starts.size(); ++r) {
    const Eigen::Index n = (r + 1 < starts.size() ? starts[r + 1] : N) - starts[r];
    bool esc = false;
    const Eigen::VectorXd ys =
        process.simulate(u.segment(starts[r], n), y.segment(starts[r], L), &esc);
    escaped = escaped || esc;
    ypool.segment(static_cast<Eigen::Index>(at), n - L) = y.segment(starts[r] + L, n - L);
    spool.segment(static_cast<Eigen::Index>(at), n - L) = ys.tail(n - L);
    at += static_cast<size_t>(n - L);
  }
  if (escaped) {
    res.fit = fit_report_or_inf(ypool, Eigen::VectorXd::Constant(ypool.size(), NAN), k);
    res.diagnostics.warnings.push_back("the free-run simulation of the selected model escapes (blows up)");
  } else {
    res.fit = fit_report_or_inf(ypool, spool, k);
  }
  res.summary.iterations = static_cast<int>(sel.size());
  if (interrupted) {
    res.summary.termination = Termination::Interrupted;
    res.summary.message = detail::format("interrupted after selecting {} terms", sel.size());
  }
  res.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return res;
}

void check_siso(const IdData& data, const char* who) {
  require_io_data(data, who);
  CTID_REQUIRE(data.is_uniform(), "{}: needs uniformly sampled data", who);
}

// Several records concatenated (each checked: one input, one output, uniform at the first record's Ts); one record
// is read in place (y and u stay empty; `single` points to it).
struct NarxRecords {
  Eigen::VectorXd y, u;
  std::vector<Eigen::Index> starts;
  double ts = 1.0;
  const IdData* single = nullptr;
  // (if, not ?: — the conditional operator would make a temporary VectorXd of the column and refer to it)
  Eigen::Ref<const Eigen::VectorXd> output() const {
    if (single) return single->y().col(0);
    return y;
  }
  Eigen::Ref<const Eigen::VectorXd> input() const {
    if (single) return single->u().col(0);
    return u;
  }
};

NarxRecords concatenate(const internal::RecordRefs& data, const char* who) {
  CTID_REQUIRE(!data.empty(), "{}: no records", who);
  NarxRecords r;
  r.ts = data.front().is_uniform() ? data.front().ts() : 0.0;
  Eigen::Index n = 0;
  for (size_t i = 0; i < data.size(); ++i) {
    check_siso(data[i], who);
    CTID_REQUIRE(std::abs(data[i].ts() - r.ts) <= 1e-9 * r.ts,
                 "{}: record {} is sampled at {} s, record 1 at {} s; a NARX model has one sampling period", who, i + 1,
                 data[i].ts(), r.ts);
    n += data[i].size();
  }
  if (data.size() == 1) {
    r.single = &data.front();
    r.starts = {0};
    return r;
  }
  r.y.resize(n);
  r.u.resize(n);
  n = 0;
  for (const auto& d : data) {
    r.starts.push_back(n);
    r.y.segment(n, d.size()) = d.y().col(0);
    r.u.segment(n, d.size()) = d.u().col(0);
    n += d.size();
  }
  return r;
}

Result<NarxModel> frols_records(const internal::RecordRefs& data, const std::vector<NarxTerm>& cand,
                                const FrolsOptions& o) {
  o.validate();
  const NarxRecords r = concatenate(data, "frols");
  CTID_REQUIRE(!cand.empty(), "frols: no candidate terms");
  for (const auto& t : cand) CTID_REQUIRE(!t.has_noise(), "frols: candidate {} is a noise term (use narmax)", t.name());
  return frols_signals({r.output(), r.input(), Eigen::VectorXd()}, r.starts, r.ts, cand, o);  // (no e: no noise term)
}
}  // namespace

Result<NarxModel> frols(const IdData& data, const std::vector<NarxTerm>& cand, const FrolsOptions& o) {
  return frols_records(data, cand, o);
}

Result<NarxModel> frols(const std::vector<IdData>& data, const std::vector<NarxTerm>& cand, const FrolsOptions& o) {
  return frols_records(data, cand, o);
}


template <>
const OptionTable<NarmaxOptions>& option_table<NarmaxOptions>() {
  using O = NarmaxOptions;
  static const OptionTable<O> t =
      OptionTable<O>("narmax")
          .include(&O::frols, option_table<FrolsOptions>())
          .terms("noise_candidates", &O::noise_candidates, "noise candidate terms (each with an e(k-i) factor)")
          .integer("max_noise_terms", &O::max_noise_terms, "", at_least(0), "noise terms allowed on top of max_terms")
          .integer("iterations", &O::iterations, "", at_least(1), "extended least-squares iterations")
          .real("tolerance", &O::tolerance, "", at_least(0),
                "stop when the process terms repeat and their coefficients change less (relative)");
  return t;
}

template <>
const OptionTable<NarxOptions>& option_table<NarxOptions>() {
  using O = NarxOptions;
  static const OptionTable<O> t =
      OptionTable<O>("narx")
          .integer("degree", &O::degree, "", between(1, 10), "polynomial degree of the candidate terms")
          .integer("ylag", &O::ylag, "samples", at_least(1), "output lags y(k-1) .. y(k-ylag)")
          .integer("ulag", &O::ulag, "samples", at_least(0), "input lags u(k-umin) .. u(k-ulag)")
          .integer("umin", &O::umin, "samples", at_least(0), "smallest input lag (0: direct feed-through)")
          .flag("constant", &O::constant, "include the constant term")
          .integer("noise_terms", &O::noise_terms, "samples", at_least(0),
                   "NARMAX residual lags e(k-1 .. k-noise_terms); 0: NARX by FROLS")
          .include(&O::narmax, option_table<NarmaxOptions>(),
                   {"max_terms", "err_tolerance", "criterion", "block_rows", "max_noise_terms", "iterations", "tolerance"},
                   {{"iterations", "narmax_iterations"}, {"tolerance", "narmax_tolerance"}});
  return t;
}

void NarxOptions::validate() const {
  option_table<NarxOptions>().check(*this);
  narmax.validate();
}

void NarmaxOptions::validate() const {
  frols.validate();
  option_table<NarmaxOptions>().check(*this);
  for (const auto& t : noise_candidates)
    CTID_REQUIRE_OPTION(t.has_noise(), "narmax: noise candidate {} has no e(k-i) factor", t.name());
}

namespace {
Result<NarxModel> narmax_records(const internal::RecordRefs& data, const std::vector<NarxTerm>& process,
                                 const NarmaxOptions& o) {
  const auto t_start = std::chrono::steady_clock::now();
  o.validate();
  const NarxRecords rec = concatenate(data, "narmax");
  for (const auto& t : process) CTID_REQUIRE(!t.has_noise(), "narmax: process candidate {} is a noise term", t.name());
  const Eigen::Ref<const Eigen::VectorXd> y = rec.output(), u = rec.input();
  // Iteration 0: NARX; then residual-driven selection over process and noise candidates (extended LS).
  Result<NarxModel> r = frols_records(data, process, o.frols);
  std::vector<NarxTerm> all = process;
  all.insert(all.end(), o.noise_candidates.begin(), o.noise_candidates.end());
  FrolsOptions fo = o.frols;
  fo.max_terms = o.frols.max_terms + o.max_noise_terms;
  int it = 0;
  double change = std::numeric_limits<double>::infinity();
  // Residuals of the pseudo-linear regression: e_next(k) = y(k) - phi(k; e)^T theta with the noise regressors
  // built from the previous residuals (not the recursive predictor, which diverges when an intermediate noise
  // model is not invertible).
  Eigen::VectorXd e = Eigen::VectorXd::Zero(y.size());
  auto residuals = [&](const NarxModel& m) {
    const Eigen::Index L = m.max_lag(), Ne = y.size() - L;
    Eigen::VectorXd next = Eigen::VectorXd::Zero(y.size());
    Eigen::MatrixXd col(Ne, 1);
    next.tail(Ne) = y.tail(Ne);
    for (size_t i = 0; i < m.terms().size(); ++i) {
      candidate_block({m.terms()[i]}, {y, u, e}, L, Ne, col);
      next.tail(Ne) -= m.coefficients()(static_cast<Eigen::Index>(i)) * col.col(0);
    }
    next.tail(Ne).array() *= row_mask(rec.starts, y.size(), L).array();  // a record's first L residuals are 0
    return next;
  };
  for (; it < o.iterations && !o.noise_candidates.empty(); ++it) {
    if (r.summary.termination == Termination::Interrupted) break;
    if (!report_progress("narmax", it + 1, NAN)) {
      r.summary.termination = Termination::Interrupted;
      r.summary.message = detail::format("interrupted after {} extended least-squares iterations", it);
      break;
    }
    e = residuals(r.model);
    Result<NarxModel> next = frols_signals({y, u, e}, rec.starts, rec.ts, all, fo);
    // Convergence: the same process terms with coefficients within tolerance (relative); noise terms may
    // trade places among themselves.
    change = std::numeric_limits<double>::infinity();
    const NarxModel a = r.model.process(), b = next.model.process();
    if (a.terms().size() == b.terms().size()) {
      double d = 0, scale = 0;
      bool same = true;
      for (size_t i = 0; i < b.terms().size() && same; ++i) {
        const auto hit = std::find(a.terms().begin(), a.terms().end(), b.terms()[i]);
        same = hit != a.terms().end();
        if (!same) break;
        const double ca = a.coefficients()(hit - a.terms().begin()), cb = b.coefficients()(static_cast<Eigen::Index>(i));
        d = std::max(d, std::abs(cb - ca));
        scale = std::max(scale, std::abs(cb));
      }
      if (same) change = d / std::max(scale, 1e-300);
    }
    r = std::move(next);
    if (change <= o.tolerance) {
      ++it;
      break;
    }
  }
  r.diagnostics.set(diagnostic::narmax_iterations, it);
  r.diagnostics.set(diagnostic::relative_change, change);
  if (!o.noise_candidates.empty() && change > o.tolerance)
    r.diagnostics.warnings.push_back(detail::format(
        "narmax: the extended least-squares iterations did not settle in {} iterations (last relative change {})", it,
        change));
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return r;
}

Result<NarxModel> narx_records(const internal::RecordRefs& data, const NarxOptions& o) {
  o.validate();
  const std::vector<NarxTerm> candidates = narx_candidates(o.degree, o.ylag, o.ulag, o.constant, o.umin);
  if (o.noise_terms == 0) return frols_records(data, candidates, o.narmax.frols);
  NarmaxOptions n = o.narmax;
  n.noise_candidates = narx_noise_candidates(o.noise_terms, 2, 2);
  return narmax_records(data, candidates, n);
}
}  // namespace

Result<NarxModel> narmax(const IdData& data, const std::vector<NarxTerm>& process, const NarmaxOptions& o) {
  return narmax_records(data, process, o);
}

Result<NarxModel> narmax(const std::vector<IdData>& data, const std::vector<NarxTerm>& process, const NarmaxOptions& o) {
  return narmax_records(data, process, o);
}

Result<NarxModel> narx(const IdData& data, const NarxOptions& o) { return narx_records(data, o); }

Result<NarxModel> narx(const std::vector<IdData>& data, const NarxOptions& o) { return narx_records(data, o); }

}  // namespace ctid
