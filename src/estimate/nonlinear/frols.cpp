// FROLS / ERR structure detection for polynomial NARX models (Billings & Li 1999, BL 28-32;
// Billings & Li 1999, §2, BL 28-32). See include/ctid/estimate/nonlinear/frols.hpp.
//
// With p_m the candidate columns, w_s the orthogonalised selected columns and g_s = w_s^T y / w_s^T w_s,
// the orthogonal part of an unselected candidate m after s selections has
//     w_m^T y = p_m^T y - sum_s (p_m^T w_s) g_s,   w_m^T w_m = p_m^T p_m - sum_s (p_m^T w_s)^2 / (w_s^T w_s),
// so ERR_m = (w_m^T y)^2 / (w_m^T w_m y^T y) needs only the inner products c_sm = p_m^T w_s: one pass over
// freshly generated candidate blocks per selected term — or, when the candidates' Gram matrix is cheaper to form
// than those passes, c_sm = G(m, sel_s) - sum_{r<s} A(r, s) c_rm from G = P^T P formed in one pass (Korenberg's fast
// orthogonal search: Korenberg 1988, Ann. Biomed. Eng. 16, 123-142; GramMoments below).
#include "ctid/estimate/nonlinear/frols.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>

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
          .integer("block_rows", &O::block_rows, "", at_least(16), "rows of candidate columns generated at a time (memory)")
          .choice("route", &O::route, {{"auto", FrolsRoute::Auto}, {"passes", FrolsRoute::Passes}, {"gram", FrolsRoute::Gram}},
                  "products with the orthogonalised terms: a pass per term, or the candidates' Gram matrix from one "
                  "pass (auto: the one with fewer products per row)");
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

// The column of candidate t over signal indices k0 .. k0 + out.size() - 1.
void candidate_column(const NarxTerm& t, const Signals& sig, Eigen::Index k0, Eigen::Ref<Eigen::VectorXd> out) {
  out.setOnes();
  for (const auto& f : t.factors) out.array() *= sig.of(f.signal).segment(k0 - f.lag, out.size()).array();
}

// Inner products of every candidate with a vector w, without forming the candidate columns: a candidate
// is prefix * x_a * x_b (x_0 = 1, x_1.. the distinct lagged signals), so for each distinct prefix the
// (V+1) x (V+1) matrix Z = (X o (w o prefix))^T X holds all of them — a small matrix product per row block.
class CandidateProducts {
 public:
  CandidateProducts(const std::vector<NarxTerm>& cand, Eigen::Index block) {
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
    const Eigen::Index V = static_cast<Eigen::Index>(vars_.size()) + 1;
    Z.assign(prefixes_.size(), Eigen::MatrixXd::Zero(V, V));
    pass_cost_ = static_cast<double>(prefixes_.size()) * static_cast<double>(V * V);
    block_ = block;  // the block buffers are sized at the first pass (the Gram route makes none)
  }

  // c_m = sum_k p_m(k) w(k) over regression rows r = 0 .. Ne - 1 (signal index k = L + r), with w generated block by
  // block: weights(r0, rows) returns w over rows r0 .. r0 + rows - 1 (valid until the next call). Squared: the sum of
  // p_m(k)^2 w(k).
  // (The block buffers are members, sized once per fit: a fresh buffer per pass would be mapped and faulted anew.)
  template <class Weights>
  Eigen::VectorXd dot(const Signals& sig, Eigen::Index L, Eigen::Index Ne, Weights&& weights, bool squared = false) {
    const Eigen::Index V = static_cast<Eigen::Index>(vars_.size()) + 1, block = block_;
    if (X.rows() != block) {
      X.resize(block, V);
      Vw.resize(block, V);
      om.resize(block);
    }
    for (auto& z : Z) z.setZero();
    for (Eigen::Index r0 = 0; r0 < Ne; r0 += block) {
      const Eigen::Index rows = std::min(block, Ne - r0);
      const Eigen::Ref<const Eigen::VectorXd> w = weights(r0, rows);
      X.col(0).head(rows).setOnes();
      for (size_t i = 0; i < vars_.size(); ++i) {
        X.col(static_cast<Eigen::Index>(i) + 1).head(rows) = sig.of(vars_[i].signal).segment(L + r0 - vars_[i].lag, rows);
      }
      if (squared) X.topRows(rows) = X.topRows(rows).array().square().matrix();
      for (size_t g = 0; g < prefixes_.size(); ++g) {
        om.head(rows) = w;
        for (int v : prefixes_[g]) om.head(rows).array() *= X.col(v).head(rows).array();
        Vw.topRows(rows) = om.head(rows).asDiagonal() * X.topRows(rows);
        // X^T diag(om) X is symmetric: the lower triangle is enough.
        // (Up to a dozen signals the products as dot products of columns are faster; beyond, a packed matrix product.)
        if (V <= 12)
          Z[g].triangularView<Eigen::Lower>() += Vw.topRows(rows).transpose().lazyProduct(X.topRows(rows));
        else
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
  /// Products per row of one pass (each prefix group's (V+1)^2 matrix), the unit of the route choice.
  double pass_cost() const { return pass_cost_; }

 private:
  struct Item {
    int group = 0, a = 0, b = 0;
  };
  double pass_cost_ = 0;
  Eigen::Index block_ = 0;
  std::vector<NarxFactor> vars_;
  std::vector<std::vector<int>> prefixes_;
  std::vector<Item> items_;
  std::vector<Eigen::MatrixXd> Z;
  Eigen::MatrixXd X, Vw;
  Eigen::VectorXd om;
};

// Several records are concatenated; a regression row r (signal index k = L + r) belongs to the record that starts at
// the largest start <= k and is used only when all its lags stay inside that record (k - start >= L). The rows whose
// lags reach into the previous record are kept as ranges (no N-length mask): zero() clears them in a block of rows.
class RowMask {
 public:
  RowMask(const std::vector<Eigen::Index>& starts, Eigen::Index N, Eigen::Index L) : rows_(std::max<Eigen::Index>(0, N - L)) {
    for (Eigen::Index s : starts) {
      const Eigen::Index a = std::max(s, L) - L, b = std::min(s + L, N) - L;
      if (b > a) holes_.emplace_back(a, b);
    }
  }
  Eigen::Index used() const {
    Eigen::Index n = rows_;
    for (const auto& [a, b] : holes_) n -= b - a;
    return n;
  }
  // v holds rows r0 .. r0 + v.size() - 1.
  void zero(Eigen::Ref<Eigen::VectorXd> v, Eigen::Index r0) const {
    for (const auto& [a, b] : holes_) {
      const Eigen::Index lo = std::max(a, r0), hi = std::min(b, r0 + v.size());
      if (hi > lo) v.segment(lo - r0, hi - lo).setZero();
    }
  }

 private:
  Eigen::Index rows_;
  std::vector<std::pair<Eigen::Index, Eigen::Index>> holes_;
};

// The candidates' Gram matrix P^T P, P^T y and y^T y over the used rows in one pass over the signals. Each entry is the
// sum of a monomial in the distinct lagged signals and y(k) itself (the union of two candidates' factors); a monomial
// is its parent (one factor fewer) times one signal, so a block of rows costs one product per monomial and row.
// The constructor stops at `limit` monomials (then ok() is false: the passes are cheaper).
class GramMoments {
 public:
  GramMoments(const std::vector<NarxTerm>& cand, double limit) : limit_(limit) {
    key({});
    std::vector<std::vector<int>> ck;
    for (const auto& t : cand) {
      std::vector<int> k;
      for (const auto& f : t.factors) k.push_back(var_of(f));
      ck.push_back(std::move(k));
    }
    const int y = var_of({NarxSignal::Output, 0});
    const int M = static_cast<int>(cand.size());
    pair_.resize(M, M);
    cy_.resize(M);
    for (int a = 0; a < M && ok_; ++a) {
      for (int b = a; b < M && ok_; ++b) {
        std::vector<int> k = ck[a];
        k.insert(k.end(), ck[b].begin(), ck[b].end());
        pair_(a, b) = pair_(b, a) = key(std::move(k));
      }
      std::vector<int> k = ck[a];
      k.push_back(y);
      cy_[a] = key(std::move(k));
    }
    yy_ = key({y, y});
  }
  bool ok() const { return ok_; }
  int monomials() const { return static_cast<int>(parent_.size()); }

  void accumulate(const Signals& sig, Eigen::Index L, Eigen::Index Ne, const RowMask& mask, Eigen::Index block) {
    const int V = static_cast<int>(vars_.size()), nm = monomials();
    Eigen::MatrixXd X(block, V + 1), C(block, nm);
    sums_ = Eigen::VectorXd::Zero(nm);
    for (Eigen::Index r0 = 0; r0 < Ne; r0 += block) {
      const Eigen::Index rows = std::min(block, Ne - r0);
      // A block's signals are a few kilobytes read once: ask for those of the block four ahead, so that a record
      // larger than the cache does not wait on main memory (the hardware prefetcher does not catch short runs).
      for (NarxSignal g : {NarxSignal::Output, NarxSignal::Input, NarxSignal::Noise}) {
        const auto& x = sig.of(g);
        const Eigen::Index a = L + r0 + 4 * block, b = std::min<Eigen::Index>(a + block, x.size());
        for (Eigen::Index k = a; k < b; k += 8) __builtin_prefetch(x.data() + k);
      }
      for (int v = 0; v < V; ++v) {
        const NarxFactor& f = vars_[static_cast<size_t>(v)];
        X.col(v + 1).head(rows) = sig.of(f.signal).segment(L + r0 - f.lag, rows);
      }
      C.col(0).head(rows).setOnes();
      mask.zero(C.col(0).head(rows), r0);
      for (int i = 1; i < nm; ++i)
        C.col(i).head(rows) = C.col(parent_[i]).head(rows).cwiseProduct(X.col(var_[i]).head(rows));
      sums_ += C.topRows(rows).colwise().sum().transpose();
    }
  }
  double gram(int a, int b) const { return sums_(pair_(a, b)); }
  double with_y(int a) const { return sums_(cy_[a]); }
  double yy() const { return sums_(yy_); }

 private:
  int var_of(const NarxFactor& f) {
    for (size_t i = 0; i < vars_.size(); ++i)
      if (vars_[i] == f) return static_cast<int>(i) + 1;
    vars_.push_back(f);
    return static_cast<int>(vars_.size());
  }
  // The index of a monomial (sorted variable indices; 0: the constant), its parents created first.
  int key(std::vector<int> k) {
    std::sort(k.begin(), k.end());
    if (auto it = index_.find(k); it != index_.end()) return it->second;
    if (static_cast<double>(parent_.size()) >= limit_) {
      ok_ = false;
      return 0;
    }
    const int p = k.empty() ? 0 : key(std::vector<int>(k.begin(), k.end() - 1));
    const int i = static_cast<int>(parent_.size());
    parent_.push_back(p);
    var_.push_back(k.empty() ? 0 : k.back());
    index_.emplace(std::move(k), i);
    return i;
  }
  double limit_;
  bool ok_ = true;
  std::vector<NarxFactor> vars_;
  std::map<std::vector<int>, int> index_;
  std::vector<int> parent_, var_, cy_;
  Eigen::MatrixXi pair_;
  int yy_ = 0;
  Eigen::VectorXd sums_;
};

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
// The fit: each record's free run from its own first L measured outputs, compared with the measured output after
// those L samples. The run is simulated a block at a time (the model's state is its last L outputs) and the sums
// of squares are accumulated, the deviations from the mean merged block by block (Chan, Golub & LeVeque 1983), so
// the fit needs no N-length buffer.
// `escaped`: the run of some record blew up (the fit is then infinite).
FitReport free_run_fit(const NarxModel& process, const Signals& sig, const std::vector<Eigen::Index>& starts, Eigen::Index L,
                       Eigen::Index BR, int k, bool& escaped) {
  const auto& y = sig.y;
  const auto& u = sig.u;
  const Eigen::Index N = y.size();
  escaped = false;
  double sse = 0, sst = 0, mean = 0;
  Eigen::Index n_fit = 0;
  for (size_t r = 0; r < starts.size() && !escaped; ++r) {
    const Eigen::Index end = r + 1 < starts.size() ? starts[r + 1] : N;
    Eigen::VectorXd last = y.segment(starts[r], L);  // the run's last L outputs
    for (Eigen::Index k0 = starts[r] + L; k0 < end && !escaped; k0 += BR) {
      const Eigen::Index rows = std::min(BR, end - k0);
      const Eigen::VectorXd run = process.simulate(u.segment(k0 - L, rows + L), last, &escaped);
      last = run.tail(L);
      const auto yb = y.segment(k0, rows);
      sse += (yb - run.tail(rows)).squaredNorm();
      const double mb = yb.mean(), delta = mb - mean, n = static_cast<double>(n_fit + rows);
      sst += (yb.array() - mb).square().sum() + delta * delta * static_cast<double>(n_fit) * static_cast<double>(rows) / n;
      mean += delta * static_cast<double>(rows) / n;
      n_fit += rows;
    }
  }
  return fit_report_from_sums(escaped ? std::numeric_limits<double>::infinity() : sse, sst, static_cast<int>(n_fit), k);
}

// p_m^T y, p_m^T p_m of every candidate column m and y^T y over the used rows: from the Gram moments when given,
// else by one pass of the candidate products.
void first_moments(const Signals& sig, Eigen::Index L, Eigen::Index Ne, const RowMask& mask, Eigen::Index BR,
                   GramMoments* moments, CandidateProducts& products, Eigen::VectorXd& py, Eigen::VectorXd& pp, double& yy) {
  const auto& y = sig.y;
  yy = 0;
  if (moments) {
    // 128-row blocks: the monomial block stays in the cache (and below the allocator's mmap threshold for the
    // candidate sets auto chooses it for, so a fit of a short record does not fault fresh pages in).
    moments->accumulate(sig, L, Ne, mask, std::min<Eigen::Index>(BR, 128));
    yy = moments->yy();
    for (Eigen::Index m = 0; m < py.size(); ++m) {
      py(m) = moments->with_y(m);
      pp(m) = moments->gram(m, m);
    }
  } else {
    // Pass 0: p_m^T y, p_m^T p_m and y^T y over the used rows.
    Eigen::VectorXd wb(BR);
    py = products.dot(sig, L, Ne, [&](Eigen::Index r0, Eigen::Index rows) {
      auto w = wb.head(rows);
      w = y.segment(L + r0, rows);
      mask.zero(w, r0);
      yy += w.squaredNorm();
      return w;
    });
    pp = products.dot(sig, L, Ne, [&](Eigen::Index r0, Eigen::Index rows) {
      auto w = wb.head(rows);
      w.setOnes();
      mask.zero(w, r0);
      return w;
    }, true);
  }
}

// FROLS on given signals (e may be all zero when no candidate is a noise term): the records concatenated,
// record r starting at starts[r] (starts[0] = 0); rows whose lags cross into the previous record are masked out
// of every inner product (RowMask), so the regression is the stack of the records' own regressions.
Result<NarxModel> frols_signals(const Signals& sig, const std::vector<Eigen::Index>& starts, double Ts,
                                const std::vector<NarxTerm>& cand, const FrolsOptions& o) {
  const auto t_start = std::chrono::steady_clock::now();
  int L = 0;
  for (const auto& t : cand) L = std::max(L, t.max_lag());
  const auto& y = sig.y;
  const Eigen::Index N = y.size(), Ne = N - L;
  const int M = static_cast<int>(cand.size());
  for (size_t r = 0; r < starts.size() && starts.size() > 1; ++r) {  // one record: the row count below says it
    const Eigen::Index n = (r + 1 < starts.size() ? starts[r + 1] : N) - starts[r];
    CTID_REQUIRE(n > L, "frols: record {} has {} samples, not more than the largest lag {}", r + 1, n, L);
  }
  const RowMask mask(starts, N, L);
  const Eigen::Index rows_used = mask.used();
  CTID_REQUIRE(rows_used > M, "frols: {} candidate terms but only {} usable rows ({} samples minus the largest lag {}{}); "
               "reduce the lags or the degree", M, rows_used, N, L, starts.size() > 1 ? " in each record" : "");
  const int K = std::min(o.max_terms, M);
  const Eigen::Index BR = std::min<Eigen::Index>(o.block_rows, Ne);

  // The route: K + 2 passes of CandidateProducts, or one pass of GramMoments when it needs fewer products per row.
  CandidateProducts products(cand, BR);
  constexpr double kMaxMoments = 50000;
  GramMoments moments(cand, o.route == FrolsRoute::Passes ? 0.0
                            : o.route == FrolsRoute::Gram  ? kMaxMoments
                                                           : std::min(kMaxMoments, (K + 2) * products.pass_cost()));
  CTID_REQUIRE_OPTION(o.route != FrolsRoute::Gram || moments.ok(),
                      "frols: route=gram needs more than {} moments for these {} candidates; use route=passes or auto",
                      kMaxMoments, M);
  const bool gram = o.route != FrolsRoute::Passes && moments.ok();
  Eigen::VectorXd py(M), pp(M);
  double yy = 0;
  first_moments(sig, L, Ne, mask, BR, gram ? &moments : nullptr, products, py, pp, yy);
  CTID_REQUIRE(yy > 0, "frols: the output is identically zero");

  std::vector<int> sel;
  std::vector<double> err, g, ww;
  Eigen::MatrixXd C(K, M);   // C(s, m) = p_m^T w_s
  // A(r, s) = c_r,sel(s) / ww_r: w_s = p_sel(s) - sum_{r<s} A(r, s) w_r (A unit upper triangular).
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(K, K);
  std::vector<bool> used(M, false);
  Eigen::VectorXd crit(K);
  // The orthogonal columns w_r of the selected terms are not stored (N x K): each pass regenerates them block by
  // block from the candidate columns with the Gram-Schmidt coefficients already found, w_r = p_sel(r) - sum_{q<r}
  // A(q, r) w_q (an (s + 1)-column block in the cache costs less than reading s stored N-columns from memory).
  Eigen::MatrixXd Wb(gram ? 0 : BR, K);
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
    used[best] = true;
    sel.push_back(best);
    for (int q = 0; q < s; ++q) A(q, s) = C(q, best) / ww[q];
    double w2 = 0, wy = 0;
    if (gram) {
      // From the Gram matrix: c_s,m = G(m, best) - sum_{q<s} A(q, s) c_q,m; w_s^T w_s = c_s,best and
      // w_s^T y = p_best^T y - sum_{q<s} c_q,best g_q (w_s is orthogonal to the earlier w_q).
      for (int m = 0; m < M; ++m) {
        double c = moments.gram(m, best);
        for (int q = 0; q < s; ++q) c -= A(q, s) * C(q, m);
        C(s, m) = c;
      }
      w2 = C(s, best);
      wy = py(best);
      for (int q = 0; q < s; ++q) wy -= C(q, best) * g[q];
    } else {
      // One pass: w_s block by block, its norm and w_s^T y, and c_s,m = p_m^T w_s for every candidate.
      C.row(s) = products.dot(sig, L, Ne, [&](Eigen::Index r0, Eigen::Index rows) {
        for (int r = 0; r <= s; ++r) {
          auto w = Wb.col(r).head(rows);
          candidate_column(cand[sel[r]], sig, L + r0, w);
          mask.zero(w, r0);
          w.noalias() -= Wb.topLeftCorner(rows, r) * A.col(r).head(r);
        }
        const auto w = Wb.col(s).head(rows);
        w2 += w.squaredNorm();
        wy += w.dot(y.segment(L + r0, rows));  // (w is zero on the masked rows)
        return w;
      }).transpose();
    }
    ww.push_back(w2);
    g.push_back(wy / w2);
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
  // theta from A theta = g over the k terms kept.
  Eigen::VectorXd gv(k), winv(k);
  for (int s = 0; s < k; ++s) {
    gv(s) = g[s];
    winv(s) = 1.0 / ww[s];
  }
  const Eigen::MatrixXd Ak = A.topLeftCorner(k, k);
  const auto Atri = Ak.triangularView<Eigen::UnitUpper>();
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
  res.diagnostics.condition_number = Ainv.norm() * Ak.norm();
  bool escaped = false;
  res.fit = free_run_fit(res.model.process(), sig, starts, L, BR, k, escaped);
  if (escaped) res.diagnostics.warnings.push_back("the free-run simulation of the selected model escapes (blows up)");
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
                   {"max_terms", "err_tolerance", "criterion", "block_rows", "route", "max_noise_terms", "iterations", "tolerance"},
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
    Eigen::VectorXd next = Eigen::VectorXd::Zero(y.size()), col(Ne);
    next.tail(Ne) = y.tail(Ne);
    for (size_t i = 0; i < m.terms().size(); ++i) {
      candidate_column(m.terms()[i], {y, u, e}, L, col);
      next.tail(Ne) -= m.coefficients()(static_cast<Eigen::Index>(i)) * col;
    }
    RowMask(rec.starts, y.size(), L).zero(next.tail(Ne), 0);  // a record's first L residuals are 0
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
