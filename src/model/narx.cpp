// Polynomial NARX / NARMAX models (Billings & Li 1999, eqs 7-10): see include/ctid/model/narx.hpp.
#include "ctid/model/narx.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "ctid/core/check.hpp"

namespace ctid {

int NarxTerm::max_lag() const {
  int m = 0;
  for (const auto& f : factors) m = std::max(m, f.lag);
  return m;
}

bool NarxTerm::has_noise() const {
  return std::any_of(factors.begin(), factors.end(), [](const NarxFactor& f) { return f.signal == NarxSignal::Noise; });
}

std::string NarxTerm::name() const {
  if (factors.empty()) return "1";
  std::string s;
  for (size_t i = 0; i < factors.size(); ++i) {
    if (i) s += "*";
    const char c = factors[i].signal == NarxSignal::Output ? 'y' : factors[i].signal == NarxSignal::Input ? 'u' : 'e';
    s += c;
    s += factors[i].lag == 0 ? std::string("(k)") : "(k-" + std::to_string(factors[i].lag) + ")";
  }
  return s;
}

NarxTerm NarxTerm::parse(const std::string& text) {
  NarxTerm t;
  if (text == "1") return t;
  size_t i = 0;
  auto fail = [&](const char* what) {
    throw InvalidArgument(detail::format("NARX term \"{}\": {} at position {}", text, what, i + 1));
  };
  while (true) {
    if (i >= text.size()) fail("expected y, u or e");
    NarxFactor f;
    if (text[i] == 'y') f.signal = NarxSignal::Output;
    else if (text[i] == 'u') f.signal = NarxSignal::Input;
    else if (text[i] == 'e') f.signal = NarxSignal::Noise;
    else fail("expected y, u or e");
    ++i;
    if (text.compare(i, 2, "(k") != 0) fail("expected \"(k\"");
    i += 2;
    if (i < text.size() && text[i] == ')') {
      f.lag = 0;
    } else {
      if (i >= text.size() || text[i] != '-') fail("expected \"-\" or \")\"");
      ++i;
      const size_t start = i;
      while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
      if (i == start) fail("expected a lag");
      if (i - start > 7) fail("lag larger than 1000000");
      f.lag = std::stoi(text.substr(start, i - start));
      if (f.lag > 1000000) fail("lag larger than 1000000");
      if (i >= text.size() || text[i] != ')') fail("expected \")\"");
    }
    ++i;
    if (f.lag == 0 && f.signal != NarxSignal::Input) fail("output and noise lags must be >= 1");
    t.factors.push_back(f);
    if (i == text.size()) break;
    if (text[i] != '*') fail("expected \"*\"");
    ++i;
  }
  return t;
}

std::vector<NarxTerm> narx_candidates(int degree, int ylag, int ulag, bool constant, int umin) {
  CTID_REQUIRE(degree >= 1, "narx_candidates: degree must be >= 1 (got {})", degree);
  CTID_REQUIRE(ylag >= 0 && umin >= 0, "narx_candidates: lags must be >= 0 (ylag {}, umin {})", ylag, umin);
  CTID_REQUIRE(ulag >= umin - 1, "narx_candidates: ulag = {} < umin = {}", ulag, umin);
  std::vector<NarxFactor> vars;
  for (int l = 1; l <= ylag; ++l) vars.push_back({NarxSignal::Output, l});
  for (int l = umin; l <= ulag; ++l) vars.push_back({NarxSignal::Input, l});
  CTID_REQUIRE(!vars.empty(), "narx_candidates: no lagged variable (ylag = {}, ulag = {})", ylag, ulag);
  // Monomials of degree <= D in V variables: C(V + D, D); refuse before generating an impossible set.
  double count = 1;
  for (int d = 1; d <= degree; ++d) count = count * (static_cast<double>(vars.size()) + d) / d;
  CTID_REQUIRE(count <= 1e7, "narx_candidates: degree {} in {} lagged signals gives {} candidate terms (at most 1e7); "
               "reduce the lags or the degree", degree, vars.size(), count);
  std::vector<NarxTerm> out;
  if (constant) out.push_back({});
  // Monomials of each degree as non-decreasing index tuples.
  const int V = static_cast<int>(vars.size());
  for (int d = 1; d <= degree; ++d) {
    std::vector<int> idx(d, 0);
    while (true) {
      NarxTerm t;
      for (int i : idx) t.factors.push_back(vars[i]);
      out.push_back(t);
      int p = d - 1;
      while (p >= 0 && idx[p] == V - 1) --p;
      if (p < 0) break;
      ++idx[p];
      for (int q = p + 1; q < d; ++q) idx[q] = idx[p];
    }
  }
  return out;
}

std::vector<NarxTerm> narx_noise_candidates(int elag, int degree, int cross_lag) {
  CTID_REQUIRE(elag >= 1, "narx_noise_candidates: elag must be >= 1 (got {})", elag);
  CTID_REQUIRE(degree == 1 || degree == 2, "narx_noise_candidates: degree 1 or 2 (got {})", degree);
  std::vector<NarxTerm> out;
  for (int i = 1; i <= elag; ++i) out.push_back({{{NarxSignal::Noise, i}}});
  if (degree == 2) {
    for (int i = 1; i <= elag; ++i)
      for (int j = i; j <= elag; ++j) out.push_back({{{NarxSignal::Noise, i}, {NarxSignal::Noise, j}}});
    for (int i = 1; i <= elag; ++i)
      for (int j = 1; j <= cross_lag; ++j) {
        out.push_back({{{NarxSignal::Noise, i}, {NarxSignal::Output, j}}});
        out.push_back({{{NarxSignal::Noise, i}, {NarxSignal::Input, j}}});
      }
  }
  return out;
}

NarxModel::NarxModel(std::vector<NarxTerm> terms, Eigen::VectorXd coefficients, double Ts)
    : terms_(std::move(terms)), theta_(std::move(coefficients)), Ts_(Ts) {
  CTID_REQUIRE(static_cast<Eigen::Index>(terms_.size()) == theta_.size(), "NarxModel: {} terms but {} coefficients",
               terms_.size(), theta_.size());
  CTID_REQUIRE(theta_.allFinite(), "NarxModel: non-finite coefficients");
  CTID_REQUIRE(std::isfinite(Ts_) && Ts_ > 0, "NarxModel: the sampling period must be > 0 (got {})", Ts_);
  for (const auto& t : terms_)
    for (const auto& f : t.factors)
      CTID_REQUIRE(f.lag >= (f.signal == NarxSignal::Input ? 0 : 1), "NarxModel: term {} has an invalid lag", t.name());
}

int NarxModel::max_lag() const {
  int m = 0;
  for (const auto& t : terms_) m = std::max(m, t.max_lag());
  return m;
}

int NarxModel::degree() const {
  int d = 0;
  for (const auto& t : terms_) d = std::max(d, t.degree());
  return d;
}

bool NarxModel::has_noise_terms() const {
  return std::any_of(terms_.begin(), terms_.end(), [](const NarxTerm& t) { return t.has_noise(); });
}

NarxModel NarxModel::process() const {
  std::vector<NarxTerm> t;
  std::vector<double> c;
  for (size_t i = 0; i < terms_.size(); ++i)
    if (!terms_[i].has_noise()) {
      t.push_back(terms_[i]);
      c.push_back(theta_(static_cast<Eigen::Index>(i)));
    }
  return NarxModel(t, Eigen::Map<const Eigen::VectorXd>(c.data(), static_cast<Eigen::Index>(c.size())), Ts_);
}

namespace {
// sum_m theta_m prod x_f(k - lag_f) with y and e given up to (and u including) sample k.
double evaluate(const std::vector<NarxTerm>& terms, const Eigen::VectorXd& theta, const Eigen::Ref<const Eigen::VectorXd>& u,
                const Eigen::VectorXd& y, const Eigen::VectorXd* e, Eigen::Index k) {
  double s = 0;
  for (size_t m = 0; m < terms.size(); ++m) {
    double v = theta(static_cast<Eigen::Index>(m));
    for (const auto& f : terms[m].factors) {
      const Eigen::Index i = k - f.lag;
      v *= f.signal == NarxSignal::Output ? y(i) : f.signal == NarxSignal::Input ? u(i) : (e ? (*e)(i) : 0.0);
    }
    s += v;
  }
  return s;
}
}  // namespace

Eigen::VectorXd NarxModel::simulate(const Eigen::Ref<const Eigen::VectorXd>& u, const Eigen::VectorXd& y0,
                                    bool* escaped) const {
  const Eigen::Index N = u.size(), L = max_lag();
  CTID_REQUIRE(u.allFinite(), "NarxModel::simulate: the input has non-finite samples");
  CTID_REQUIRE(y0.size() == 0 || y0.size() >= std::min<Eigen::Index>(L, N),
               "NarxModel::simulate: {} initial outputs for a maximum lag of {}", y0.size(), L);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(N);
  for (Eigen::Index k = 0; k < std::min(L, N); ++k) y(k) = y0.size() ? y0(k) : 0.0;
  if (escaped) *escaped = false;
  for (Eigen::Index k = L; k < N; ++k) {
    y(k) = evaluate(terms_, theta_, u, y, nullptr, k);
    if (!std::isfinite(y(k)) || std::abs(y(k)) > 1e150) {
      y.tail(N - k).setConstant(std::numeric_limits<double>::quiet_NaN());
      if (escaped) *escaped = true;
      break;
    }
  }
  return y;
}

Eigen::VectorXd NarxModel::predict(const Eigen::VectorXd& u, const Eigen::VectorXd& y, int steps) const {
  CTID_REQUIRE(u.size() == y.size(), "NarxModel::predict: u has {} samples, y has {}", u.size(), y.size());
  CTID_REQUIRE(steps >= 1, "NarxModel::predict: steps must be >= 1 (got {})", steps);
  const Eigen::Index N = y.size(), L = max_lag();
  // One-step residuals for the noise terms.
  Eigen::VectorXd e = Eigen::VectorXd::Zero(N), p1 = y;
  for (Eigen::Index k = L; k < N; ++k) {
    p1(k) = evaluate(terms_, theta_, u, y, &e, k);
    e(k) = y(k) - p1(k);
  }
  if (steps == 1) return p1;
  // For each k: measured data up to k - steps, then `steps` model iterations (future noise = 0). The
  // iterated entries of w and ez are restored afterwards, so each prediction costs O(steps * terms).
  Eigen::VectorXd out = y, w = y, ez = e;
  for (Eigen::Index k = L; k < N; ++k) {
    const Eigen::Index k0 = std::max(L, k - steps + 1);
    for (Eigen::Index j = k0; j <= k; ++j) ez(j) = 0.0;
    for (Eigen::Index j = k0; j <= k; ++j) w(j) = evaluate(terms_, theta_, u, w, &ez, j);
    out(k) = w(k);
    for (Eigen::Index j = k0; j <= k; ++j) {
      w(j) = y(j);
      ez(j) = e(j);
    }
  }
  return out;
}

std::string NarxModel::to_string(int precision) const {
  std::ostringstream s;
  s.precision(precision);
  s << "y(k) =";
  for (size_t m = 0; m < terms_.size(); ++m) {
    const double c = theta_(static_cast<Eigen::Index>(m));
    s << (m == 0 ? (c < 0 ? " -" : " ") : (c < 0 ? " - " : " + ")) << std::abs(c);
    if (!terms_[m].factors.empty()) s << " " << terms_[m].name();
  }
  return s.str();
}

}  // namespace ctid
