// Polynomial NDE models of Billings & Li (1999), eqs 1-6 (BL 4-6, clean convention): terms,
// harmonic probing H_1 and H_2, and simulation by adaptive Dormand-Prince 5(4). See include/ctid/model/nde.hpp.
#include "ctid/model/nde.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "ctid/core/check.hpp"
#include "internal/ode.hpp"

namespace ctid {

namespace {
std::string factor_name(const NdeFactor& f) {
  const char* v = f.input ? "u" : "y";
  if (f.derivative == 0) return v;
  if (f.derivative == 1) return detail::format("D{}", v);
  return detail::format("D^{}{}", f.derivative, v);
}
}  // namespace

std::string NdeTerm::name() const {
  std::string s;
  for (size_t i = 0; i < factors.size();) {
    size_t j = i;
    while (j < factors.size() && factors[j] == factors[i]) ++j;
    if (!s.empty()) s += "*";
    s += factor_name(factors[i]);
    if (j - i > 1) s += detail::format("^{}", j - i);
    i = j;
  }
  return s.empty() ? "1" : s;
}

NdeTerm NdeTerm::parse(const std::string& text) {
  NdeTerm t;
  size_t i = 0;
  auto fail = [&](const char* what) {
    throw InvalidArgument(detail::format("NDE term \"{}\": {} at position {}", text, what, i + 1));
  };
  auto number = [&]() {
    const size_t start = i;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
    if (i == start) fail("expected a number");
    if (i - start > 2) fail("number larger than 99");
    return std::stoi(text.substr(start, i - start));
  };
  while (true) {
    NdeFactor f;
    if (i < text.size() && text[i] == 'D') {
      ++i;
      if (i < text.size() && text[i] == '^') ++i;
      f.derivative = (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ? number() : 1;
    }
    if (i >= text.size() || (text[i] != 'y' && text[i] != 'u')) fail("expected y or u");
    f.input = text[i] == 'u';
    ++i;
    int power = 1;
    if (i < text.size() && text[i] == '^') {
      ++i;
      power = number();
      if (power < 1) fail("a power must be >= 1");
    }
    for (int k = 0; k < power; ++k) t.factors.push_back(f);
    if (i == text.size()) break;
    if (text[i] != '*') fail("expected \"*\"");
    ++i;
  }
  std::sort(t.factors.begin(), t.factors.end());
  return t;
}

NdeModel::NdeModel(std::vector<NdeTerm> terms, Eigen::VectorXd coefficients)
    : terms_(std::move(terms)), c_(std::move(coefficients)) {
  CTID_REQUIRE(static_cast<Eigen::Index>(terms_.size()) == c_.size(), "NdeModel: {} terms but {} coefficients",
               terms_.size(), c_.size());
  CTID_REQUIRE(c_.allFinite(), "NdeModel: non-finite coefficients");
  for (auto& t : terms_) {
    CTID_REQUIRE(!t.factors.empty(), "NdeModel: a constant term is not supported");
    std::sort(t.factors.begin(), t.factors.end());
    for (const auto& f : t.factors)
      CTID_REQUIRE(f.derivative >= 0, "NdeModel: negative derivative order in {}", t.name());
  }
  for (size_t i = 0; i < terms_.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      CTID_REQUIRE(!(terms_[i] == terms_[j]), "NdeModel: term {} appears twice", terms_[i].name());
}

double NdeModel::coefficient(const std::string& name) const {
  const NdeTerm t = NdeTerm::parse(name);
  for (size_t i = 0; i < terms_.size(); ++i)
    if (terms_[i] == t) return c_(static_cast<Eigen::Index>(i));
  return 0.0;
}

NdeModel NdeModel::normalized() const {
  const double cy = coefficient("y");
  CTID_REQUIRE(cy != 0.0, "NdeModel::normalized: the model has no y term");
  return NdeModel(terms_, c_ / cy);
}

namespace {
Polynomial linear_part(const std::vector<NdeTerm>& terms, const Eigen::VectorXd& c, bool input, double sign) {
  int L = 0;
  for (const auto& t : terms)
    if (t.degree() == 1 && t.factors[0].input == input) L = std::max(L, t.factors[0].derivative);
  Eigen::VectorXd p = Eigen::VectorXd::Zero(L + 1);  // descending
  for (size_t i = 0; i < terms.size(); ++i)
    if (terms[i].degree() == 1 && terms[i].factors[0].input == input)
      p(L - terms[i].factors[0].derivative) += sign * c(static_cast<Eigen::Index>(i));
  return Polynomial(p);
}
}  // namespace

Polynomial NdeModel::a() const { return linear_part(terms_, c_, false, 1.0); }
Polynomial NdeModel::b() const { return linear_part(terms_, c_, true, -1.0); }

std::complex<double> NdeModel::h1(std::complex<double> s) const { return b()(s) / a()(s); }

std::complex<double> NdeModel::h2(std::complex<double> s1, std::complex<double> s2) const {
  const std::complex<double> H1[2] = {h1(s1), h1(s2)}, S[2] = {s1, s2};
  // Each factor x contributes, on the probing exponential e^{s t}, X(s) = s^l H_1(s) (y) or s^l (u).
  auto X = [&](const NdeFactor& f, int k) { return std::pow(S[k], f.derivative) * (f.input ? 1.0 : H1[k]); };
  std::complex<double> rhs = 0.0;
  for (size_t i = 0; i < terms_.size(); ++i) {
    if (terms_[i].degree() != 2) continue;
    const auto& f = terms_[i].factors;
    rhs -= c_(static_cast<Eigen::Index>(i)) * (X(f[0], 0) * X(f[1], 1) + X(f[0], 1) * X(f[1], 0));
  }
  return rhs / (2.0 * a()(s1 + s2));
}

std::complex<double> NdeModel::h3(std::complex<double> s1, std::complex<double> s2, std::complex<double> s3) const {
  using cd = std::complex<double>;
  const cd S[3] = {s1, s2, s3}, H1[3] = {h1(s1), h1(s2), h1(s3)};
  // First-order component of a factor on e^{s_k t}; second-order component on e^{(s_j+s_k) t}.
  auto X1 = [&](const NdeFactor& f, int k) { return std::pow(S[k], f.derivative) * (f.input ? 1.0 : H1[k]); };
  auto X2 = [&](const NdeFactor& f, int j, int k) {
    return f.input ? cd(0.0) : std::pow(S[j] + S[k], f.derivative) * 2.0 * h2(S[j], S[k]);
  };
  cd rhs = 0.0;
  for (size_t t = 0; t < terms_.size(); ++t) {
    const auto& f = terms_[t].factors;
    const double c = c_(static_cast<Eigen::Index>(t));
    if (f.size() == 2) {
      for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3, k = (i + 2) % 3;
        rhs -= c * (X1(f[0], i) * X2(f[1], j, k) + X2(f[0], j, k) * X1(f[1], i));
      }
    } else if (f.size() == 3) {
      int p[3] = {0, 1, 2};
      do rhs -= c * X1(f[0], p[0]) * X1(f[1], p[1]) * X1(f[2], p[2]);
      while (std::next_permutation(p, p + 3));
    }
  }
  return rhs / (6.0 * a()(s1 + s2 + s3));
}

std::string NdeModel::to_string(int precision) const {
  std::ostringstream s;
  s.precision(precision);
  for (size_t i = 0; i < terms_.size(); ++i) {
    const double c = c_(static_cast<Eigen::Index>(i));
    if (i == 0) s << (c < 0 ? "-" : "");
    else s << (c < 0 ? " - " : " + ");
    if (std::abs(c) != 1.0) s << std::abs(c) << " ";
    s << terms_[i].name();
  }
  s << " = 0";
  return s.str();
}

NdeSimulation NdeModel::simulate(const Eigen::VectorXd& u, const Eigen::VectorXd& t, Intersample intersample,
                                 const Eigen::VectorXd& x0, double rtol) const {
  CTID_REQUIRE(u.size() == t.size() && t.size() >= 1, "NdeModel::simulate: {} inputs for {} times", u.size(), t.size());
  CTID_REQUIRE(u.allFinite() && t.allFinite(), "NdeModel::simulate: non-finite input or time");
  CTID_REQUIRE(std::isfinite(rtol) && rtol > 0 && rtol < 1, "NdeModel::simulate: rtol must be in (0, 1) (got {})", rtol);
  // Explicit form: the highest derivative L of y appears once, in a linear term.
  int L = 0;
  for (const auto& term : terms_)
    for (const auto& f : term.factors) {
      CTID_REQUIRE(!(f.input && f.derivative > 0), "NdeModel::simulate: term {} differentiates the input; a held or "
                   "linearly interpolated input has no such derivative", term.name());
      if (!f.input) L = std::max(L, f.derivative);
    }
  CTID_REQUIRE(L >= 1, "NdeModel::simulate: no derivative of y: the model is algebraic");
  int top = -1;
  for (size_t i = 0; i < terms_.size(); ++i)
    for (const auto& f : terms_[i].factors)
      if (!f.input && f.derivative == L) {
        CTID_REQUIRE(terms_[i].degree() == 1 && top < 0, "NdeModel::simulate: D^{}y must appear only once and "
                     "linearly (term {}); the model is implicit in its highest derivative", L, terms_[i].name());
        top = static_cast<int>(i);
      }
  CTID_REQUIRE(x0.size() == 0 || x0.size() == L, "NdeModel::simulate: x0 has {} entries, the model has {} states",
               x0.size(), L);
  for (Eigen::Index k = 1; k < t.size(); ++k)
    CTID_REQUIRE(t(k) > t(k - 1), "NdeModel::simulate: times must increase (t[{}] = {}, t[{}] = {})", k - 1, t(k - 1), k,
                 t(k));
  const double ctop = c_(top);
  auto f = [&](double, const Eigen::VectorXd& x, const double* ui, Eigen::VectorXd& dx) {
    const double uu = ui[0];
    double s = 0;
    for (size_t i = 0; i < terms_.size(); ++i) {
      if (static_cast<int>(i) == top) continue;
      double v = c_(static_cast<Eigen::Index>(i));
      for (const auto& fa : terms_[i].factors) v *= fa.input ? uu : x(fa.derivative);
      s += v;
    }
    dx.head(L - 1) = x.tail(L - 1);
    dx(L - 1) = -s / ctop;
  };
  NdeSimulation out;
  out.y = Eigen::VectorXd::Constant(t.size(), std::numeric_limits<double>::quiet_NaN());
  const internal::OdeOutcome o =
      internal::dopri45(f, x0.size() ? x0 : Eigen::VectorXd::Zero(L), u, t,
                        intersample == Intersample::Zoh ? internal::Between::Hold : internal::Between::Linear, rtol,
                        1e-12, L, [&](Eigen::Index k, const Eigen::VectorXd& x) { out.y(k) = x(0); });
  if (!o.ok) {
    out.termination = Termination::NumericalFailure;
    out.message = detail::format("the solution escapes at t = {} s (|x| = {}): the model is unstable for this input",
                                 o.t, o.xmax);
  }
  return out;
}

}  // namespace ctid
