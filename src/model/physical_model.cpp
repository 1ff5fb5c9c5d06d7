// Physical transfer-function expressions: a recursive-descent parser producing an AST,
// evaluated with polynomials whose coefficients carry exact gradients. See physical_model.hpp.
#include "ctid/model/physical_model.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <utility>

#include "ctid/core/check.hpp"
#include "model/text_cursor.hpp"

namespace ctid {

namespace {

// ---- AST -----------------------------------------------------------------------------
struct Node {
  enum Kind { Number, Symbol, S, Neg, Add, Sub, Mul, Div, Pow } kind;
  double value = 0;      // Number; exponent for Pow
  int symbol = -1;       // Symbol: index into the parameter list
  std::unique_ptr<Node> a, b;
};

class Parser : model_detail::TextCursor {
 public:
  Parser(const std::string& t, const std::vector<std::string>* params, std::vector<std::string>* seen)
      : TextCursor{t}, params_(params), seen_(seen) {}
  std::unique_ptr<Node> parse() {
    auto n = expr();
    skip();
    if (pos < text.size()) fail(detail::format("unexpected '{}'", text[pos]));
    return n;
  }

 private:
  static std::unique_ptr<Node> make(Node::Kind k, std::unique_ptr<Node> a = nullptr, std::unique_ptr<Node> b = nullptr) {
    auto n = std::make_unique<Node>();
    n->kind = k;
    n->a = std::move(a);
    n->b = std::move(b);
    return n;
  }
  std::unique_ptr<Node> expr() {
    auto n = term();
    for (;;) {
      if (accept('+')) n = make(Node::Add, std::move(n), term());
      else if (accept('-')) n = make(Node::Sub, std::move(n), term());
      else return n;
    }
  }
  std::unique_ptr<Node> term() {
    auto n = factor();
    for (;;) {
      if (accept('*')) n = make(Node::Mul, std::move(n), factor());
      else if (accept('/')) n = make(Node::Div, std::move(n), factor());
      else return n;
    }
  }
  std::unique_ptr<Node> factor() {
    auto n = unary();
    if (accept('^')) {
      skip();
      const std::size_t start = pos;
      while (pos < text.size() && std::isdigit(static_cast<unsigned char>(text[pos]))) ++pos;
      if (start == pos) fail("expected a non-negative integer exponent after '^'");
      if (pos - start > 3) fail("exponent larger than 64");
      auto p = make(Node::Pow, std::move(n));
      p->value = std::stod(text.substr(start, pos - start));
      if (p->value > 64) fail("exponent larger than 64");
      return p;
    }
    return n;
  }
  std::unique_ptr<Node> unary() {
    if (accept('-')) return make(Node::Neg, unary());
    if (accept('+')) return unary();
    return primary();
  }
  std::unique_ptr<Node> primary() {
    skip();
    if (pos >= text.size()) fail("unexpected end of expression");
    const char c = text[pos];
    if (c == '(') {
      ++pos;
      auto n = expr();
      if (!accept(')')) fail("expected ')'");
      return n;
    }
    if (const auto v = number()) {
      auto n = make(Node::Number);
      n->value = *v;
      return n;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      const std::size_t start = pos;
      while (pos < text.size() && (std::isalnum(static_cast<unsigned char>(text[pos])) || text[pos] == '_')) ++pos;
      const std::string name = text.substr(start, pos - start);
      if (name == "s") return make(Node::S);
      if (seen_) {
        bool known = false;
        for (const auto& x : *seen_) known = known || x == name;
        if (!known) seen_->push_back(name);
      }
      auto n = make(Node::Symbol);
      if (params_) {
        for (std::size_t i = 0; i < params_->size(); ++i)
          if ((*params_)[i] == name) n->symbol = static_cast<int>(i);
        if (n->symbol < 0) {
          std::string list;
          for (const auto& p : *params_) list += (list.empty() ? "" : ", ") + p;
          pos = start;
          fail(detail::format("unknown symbol '{}' (parameters: {})", name, list.empty() ? "none" : list));
        }
      }
      return n;
    }
    fail(detail::format("unexpected '{}'", c));
  }

  const std::vector<std::string>* params_;
  std::vector<std::string>* seen_;
};

// ---- values: polynomials in s with coefficients carrying gradients ----------------------
struct Dual {
  double v = 0;
  Eigen::VectorXd g;  // d v / d Theta
};
Dual operator+(const Dual& a, const Dual& b) { return {a.v + b.v, a.g + b.g}; }
Dual operator*(const Dual& a, const Dual& b) { return {a.v * b.v, a.v * b.g + b.v * a.g}; }

using DPoly = std::vector<Dual>;  // ascending powers of s

DPoly padd(const DPoly& a, const DPoly& b, double sign, int P) {
  DPoly r(std::max(a.size(), b.size()), Dual{0, Eigen::VectorXd::Zero(P)});
  for (std::size_t i = 0; i < a.size(); ++i) r[i] = r[i] + a[i];
  for (std::size_t i = 0; i < b.size(); ++i) r[i] = r[i] + Dual{sign * b[i].v, sign * b[i].g};
  return r;
}
DPoly pmul(const DPoly& a, const DPoly& b, int P) {
  DPoly r(a.size() + b.size() - 1, Dual{0, Eigen::VectorXd::Zero(P)});
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j) r[i + j] = r[i + j] + a[i] * b[j];
  return r;
}
struct Ratio {
  DPoly num, den;
};

Ratio eval(const Node& n, const Eigen::VectorXd& theta) {
  const int P = static_cast<int>(theta.size());
  auto constant = [&](double v) { return DPoly{Dual{v, Eigen::VectorXd::Zero(P)}}; };
  switch (n.kind) {
    case Node::Number: return {constant(n.value), constant(1.0)};
    case Node::Symbol: {
      Dual d{theta(n.symbol), Eigen::VectorXd::Zero(P)};
      d.g(n.symbol) = 1.0;
      return {DPoly{d}, constant(1.0)};
    }
    case Node::S: return {DPoly{Dual{0, Eigen::VectorXd::Zero(P)}, Dual{1, Eigen::VectorXd::Zero(P)}}, constant(1.0)};
    case Node::Neg: {
      Ratio r = eval(*n.a, theta);
      return {padd(DPoly{}, r.num, -1.0, P), r.den};
    }
    case Node::Add:
    case Node::Sub: {
      const Ratio x = eval(*n.a, theta), y = eval(*n.b, theta);
      return {padd(pmul(x.num, y.den, P), pmul(y.num, x.den, P), n.kind == Node::Add ? 1.0 : -1.0, P), pmul(x.den, y.den, P)};
    }
    case Node::Mul: {
      const Ratio x = eval(*n.a, theta), y = eval(*n.b, theta);
      return {pmul(x.num, y.num, P), pmul(x.den, y.den, P)};
    }
    case Node::Div: {
      const Ratio x = eval(*n.a, theta), y = eval(*n.b, theta);
      return {pmul(x.num, y.den, P), pmul(x.den, y.num, P)};
    }
    case Node::Pow: {
      const Ratio x = eval(*n.a, theta);
      Ratio r{constant(1.0), constant(1.0)};
      for (int k = 0; k < static_cast<int>(n.value); ++k) r = {pmul(r.num, x.num, P), pmul(r.den, x.den, P)};
      return r;
    }
  }
  CTID_ASSERT(false);
}

// Degrees of the numerator and denominator the expansion of `n` works with (an upper bound of the reduced
// degrees: eval's polynomial sizes follow the tree, not the values), in double so that nesting cannot overflow.
std::pair<double, double> expanded_degrees(const Node& n) {
  switch (n.kind) {
    case Node::Number:
    case Node::Symbol: return {0, 0};
    case Node::S: return {1, 0};
    case Node::Neg: return expanded_degrees(*n.a);
    case Node::Pow: {
      const auto [xn, xd] = expanded_degrees(*n.a);
      return {xn * n.value, xd * n.value};
    }
    default: break;
  }
  const auto [xn, xd] = expanded_degrees(*n.a);
  const auto [yn, yd] = expanded_degrees(*n.b);
  switch (n.kind) {
    case Node::Mul: return {xn + yn, xd + yd};
    case Node::Div: return {xn + yd, xd + yn};
    default: return {std::max(xn + yd, yn + xd), xd + yd};  // Add, Sub
  }
}

// The expansion's cost grows with the square of these degrees: (s^55 + k)^55 is refused here rather than
// expanded to degree 3025 (a 10-second fuzz input).
std::unique_ptr<Node> bounded(std::unique_ptr<Node> root, const std::string& text) {
  constexpr double kMaxDegree = 100;
  const auto [dn, dd] = expanded_degrees(*root);
  CTID_REQUIRE(std::max(dn, dd) <= kMaxDegree,
               "expression \"{}\": expanding it gives polynomials in s of degree {} (at most {} supported)", text,
               std::max(dn, dd), kMaxDegree);
  return root;
}

}  // namespace

struct PhysicalModel::Compiled {
  std::unique_ptr<Node> root;  // transfer-function expression form
  // State-space forms: entries (expression form) or a callable; both give values + gradients.
  std::function<StateSpaceWithGradient(const Eigen::VectorXd&)> ss;
};

PhysicalModel::PhysicalModel(const std::string& expression, std::vector<std::string> parameters)
    : expr_(expression), names_(std::move(parameters)) {
  for (std::size_t i = 0; i < names_.size(); ++i) {
    CTID_REQUIRE(names_[i] != "s", "PhysicalModel: 's' is the Laplace variable, not a parameter name");
    for (std::size_t j = 0; j < i; ++j)
      CTID_REQUIRE(names_[i] != names_[j], "PhysicalModel: parameter '{}' is declared twice", names_[i]);
  }
  auto c = std::make_shared<Compiled>();
  c->root = bounded(Parser(expr_, &names_, nullptr).parse(), expr_);
  c_ = c;
}

namespace {
// Scalar value and gradient of an expression without s.
Dual scalar(const Node& root, const std::string& text, const Eigen::VectorXd& theta) {
  const Ratio r = eval(root, theta);
  auto deg = [](const DPoly& p) {
    int d = static_cast<int>(p.size()) - 1;
    while (d > 0 && p[d].v == 0.0) --d;
    return d;
  };
  CTID_REQUIRE(deg(r.num) == 0 && deg(r.den) == 0, "state-space entry \"{}\": entries must not contain s", text);
  const Dual n = r.num[0], d = r.den[0];
  CTID_REQUIRE(d.v != 0.0, "state-space entry \"{}\": division by zero for these parameter values", text);
  return {n.v / d.v, (n.g * d.v - n.v * d.g) / (d.v * d.v)};
}
}  // namespace

PhysicalModel PhysicalModel::from_state_space(const std::vector<std::vector<std::string>>& A,
                                              const std::vector<std::vector<std::string>>& B,
                                              const std::vector<std::vector<std::string>>& C,
                                              const std::vector<std::vector<std::string>>& D, std::vector<std::string> names) {
  struct Entries {
    std::vector<std::vector<std::shared_ptr<Node>>> n;
    std::vector<std::vector<std::string>> text;
    Eigen::Index rows = 0, cols = 0;
  };
  auto parse = [&](const std::vector<std::vector<std::string>>& M, const char* which) {
    Entries e;
    e.rows = static_cast<Eigen::Index>(M.size());
    e.cols = M.empty() ? 0 : static_cast<Eigen::Index>(M[0].size());
    for (std::size_t i = 0; i < M.size(); ++i) {
      CTID_REQUIRE(static_cast<Eigen::Index>(M[i].size()) == e.cols, "PhysicalModel: row {} of {} has {} entries ({} expected)",
                   i + 1, which, M[i].size(), e.cols);
      e.n.emplace_back();
      for (const auto& t : M[i]) e.n.back().push_back(std::shared_ptr<Node>(bounded(Parser(t, &names, nullptr).parse(), t).release()));
    }
    e.text = M;
    return e;
  };
  auto eA = parse(A, "A"), eB = parse(B, "B"), eC = parse(C, "C"), eD = parse(D, "D");
  CTID_REQUIRE(eA.rows == eA.cols && eA.rows >= 1, "PhysicalModel: A must be square and non-empty (got {}x{})", eA.rows,
               eA.cols);
  CTID_REQUIRE(eB.rows == eA.rows && eB.cols == 1, "PhysicalModel: B must be {}x1 (got {}x{})", eA.rows, eB.rows, eB.cols);
  CTID_REQUIRE(eC.rows == 1 && eC.cols == eA.rows, "PhysicalModel: C must be 1x{} (got {}x{})", eA.rows, eC.rows, eC.cols);
  CTID_REQUIRE(eD.rows == 1 && eD.cols == 1, "PhysicalModel: D must be 1x1 (got {}x{})", eD.rows, eD.cols);
  const auto P = static_cast<Eigen::Index>(names.size());
  auto fn = [eA, eB, eC, eD, P](const Eigen::VectorXd& theta) {
    auto value = [&](const Entries& e, std::vector<Eigen::MatrixXd>& d) {
      Eigen::MatrixXd v(e.rows, e.cols);
      d.assign(static_cast<std::size_t>(P), Eigen::MatrixXd(e.rows, e.cols));
      for (Eigen::Index i = 0; i < e.rows; ++i)
        for (Eigen::Index j = 0; j < e.cols; ++j) {
          const Dual x = scalar(*e.n[i][j], e.text[i][j], theta);
          v(i, j) = x.v;
          for (Eigen::Index k = 0; k < P; ++k) d[k](i, j) = x.g(k);
        }
      return v;
    };
    std::vector<Eigen::MatrixXd> dA, dB, dC, dD;
    StateSpaceWithGradient out{StateSpace(value(eA, dA), value(eB, dB), value(eC, dC), value(eD, dD)), {}};
    for (Eigen::Index k = 0; k < P; ++k) out.derivatives.emplace_back(dA[k], dB[k], dC[k], dD[k]);
    return out;
  };
  return from_callable(fn, std::move(names), "state space");
}

PhysicalModel PhysicalModel::from_callable(std::function<StateSpaceWithGradient(const Eigen::VectorXd&)> model,
                                           std::vector<std::string> names, std::string description) {
  CTID_REQUIRE(static_cast<bool>(model), "PhysicalModel: the callable is empty");
  PhysicalModel m;
  m.expr_ = std::move(description);
  m.names_ = std::move(names);
  auto c = std::make_shared<Compiled>();
  c->ss = std::move(model);
  m.c_ = c;
  return m;
}

std::vector<std::string> PhysicalModel::symbols(const std::string& expression) {
  std::vector<std::string> seen;
  Parser(expression, nullptr, &seen).parse();
  return seen;
}

namespace {
// N(s + a) and D(s + a) with gradients, trimmed and normalised so that D is monic.
void expand(const Node& root, const std::string& expr, const Eigen::VectorXd& theta, double a, Eigen::VectorXd& num,
            Eigen::VectorXd& den, Eigen::MatrixXd& dnum, Eigen::MatrixXd& dden) {
  const int P = static_cast<int>(theta.size());
  Ratio r = eval(root, theta);
  auto shift = [&](const DPoly& p) {  // p(s + a) = sum_i c_i (s + a)^i
    if (a == 0.0) return p;
    DPoly out(p.size(), Dual{0, Eigen::VectorXd::Zero(P)});
    DPoly pw{Dual{1, Eigen::VectorXd::Zero(P)}};
    const DPoly lin{Dual{a, Eigen::VectorXd::Zero(P)}, Dual{1, Eigen::VectorXd::Zero(P)}};
    for (std::size_t i = 0; i < p.size(); ++i) {
      for (std::size_t j = 0; j < pw.size(); ++j) out[j] = out[j] + p[i] * pw[j];
      pw = pmul(pw, lin, P);
    }
    return out;
  };
  r.num = shift(r.num);
  r.den = shift(r.den);
  auto degree = [](const DPoly& p) {
    int d = static_cast<int>(p.size()) - 1;
    while (d > 0 && p[d].v == 0.0) --d;
    return d;
  };
  const int dn = degree(r.num), dd = degree(r.den);
  const Dual lead = r.den[dd];
  CTID_REQUIRE(lead.v != 0.0, "expression \"{}\": the denominator vanishes for these parameter values", expr);
  CTID_REQUIRE(dn <= dd || (dn == 0 && r.num[0].v == 0.0),
               "expression \"{}\": not a proper transfer function (numerator degree {} > denominator degree {})", expr, dn, dd);
  // Descending coefficients divided by the leading denominator coefficient (quotient rule).
  num.resize(dn + 1);
  den.resize(dd + 1);
  dnum.resize(dn + 1, P);
  dden.resize(dd + 1, P);
  auto divide = [&](const Dual& c, double& v, Eigen::MatrixXd& g, int row) {
    v = c.v / lead.v;
    if (g.cols() > 0) g.row(row) = ((c.g * lead.v - c.v * lead.g) / (lead.v * lead.v)).transpose();  // no parameters: no gradient
  };
  for (int i = 0; i <= dn; ++i) divide(r.num[dn - i], num(i), dnum, i);
  for (int i = 0; i <= dd; ++i) divide(r.den[dd - i], den(i), dden, i);
}
}  // namespace

namespace {
StateSpaceWithGradient checked_state_space(const std::function<StateSpaceWithGradient(const Eigen::VectorXd&)>& f,
                                           const Eigen::VectorXd& theta) {
  StateSpaceWithGradient g = f(theta);
  CTID_REQUIRE(g.model.nu() == 1 && g.model.ny() == 1, "PhysicalModel: the state-space model must be single-input "
                                                       "single-output (has {} inputs, {} outputs)",
               g.model.nu(), g.model.ny());
  CTID_REQUIRE(static_cast<Eigen::Index>(g.derivatives.size()) == theta.size(),
               "PhysicalModel: {} derivative models for {} parameters", g.derivatives.size(), theta.size());
  for (const auto& d : g.derivatives)
    CTID_REQUIRE(d.nx() == g.model.nx() && d.nu() == 1 && d.ny() == 1, "PhysicalModel: a derivative model has the wrong size");
  return g;
}
StateSpace shift_ss(const StateSpace& m, double a) {
  return StateSpace(m.A() - a * Eigen::MatrixXd::Identity(m.nx(), m.nx()), m.B(), m.C(), m.D());
}
}  // namespace

TransferFunction PhysicalModel::shifted(const Eigen::VectorXd& theta, double a) const {
  CTID_REQUIRE(theta.size() == n_parameters(), "PhysicalModel: {} parameter values for {} parameters", theta.size(),
               n_parameters());
  CTID_REQUIRE(theta.allFinite(), "PhysicalModel: parameter values must be finite");
  if (c_->ss) return shift_ss(checked_state_space(c_->ss, theta).model, a).to_transfer_function();
  Eigen::VectorXd num, den;
  Eigen::MatrixXd dn, dd;
  expand(*c_->root, expr_, theta, a, num, den, dn, dd);
  return TransferFunction(num, den);
}

TransferFunction PhysicalModel::transfer_function(const Eigen::VectorXd& theta) const { return shifted(theta, 0.0); }

StateSpaceWithGradient PhysicalModel::realisation(const Eigen::VectorXd& theta, double a) const {
  CTID_REQUIRE(theta.size() == n_parameters(), "PhysicalModel: {} parameter values for {} parameters", theta.size(),
               n_parameters());
  CTID_REQUIRE(theta.allFinite(), "PhysicalModel: parameter values must be finite");
  if (c_->ss) {
    StateSpaceWithGradient g = checked_state_space(c_->ss, theta);
    g.model = shift_ss(g.model, a);  // d(A - aI)/dTheta = dA/dTheta
    return g;
  }
  Eigen::VectorXd num, den;
  Eigen::MatrixXd dn, dd;
  expand(*c_->root, expr_, theta, a, num, den, dn, dd);
  const int n = static_cast<int>(den.size()) - 1, P = n_parameters();
  // The numerator padded to the denominator's degree: b_0 s^n + .. + b_n over s^n + a_1 s^{n-1} + .. + a_n.
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n + 1);
  Eigen::MatrixXd db = Eigen::MatrixXd::Zero(n + 1, P);
  b.tail(num.size()) = num;
  db.bottomRows(num.size()) = dn;
  auto canonical = [&](const Eigen::VectorXd& av, const Eigen::VectorXd& bv, const Eigen::VectorXd& dav,
                       const Eigen::VectorXd& dbv, bool derivative) {
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n), B = Eigen::MatrixXd::Zero(n, 1), C(1, n), D(1, 1);
    for (int j = 0; j < n; ++j) {
      A(0, j) = -(derivative ? dav(j + 1) : av(j + 1));
      if (j > 0) A(j, j - 1) = derivative ? 0.0 : 1.0;
      C(0, j) = derivative ? dbv(j + 1) - dbv(0) * av(j + 1) - bv(0) * dav(j + 1) : bv(j + 1) - bv(0) * av(j + 1);
    }
    if (n > 0 && !derivative) B(0, 0) = 1.0;
    D(0, 0) = derivative ? dbv(0) : bv(0);
    return StateSpace(A, B, C, D);
  };
  StateSpaceWithGradient g;
  g.model = canonical(den, b, den, b, false);
  for (int k = 0; k < P; ++k)
    g.derivatives.push_back(canonical(den, b, Eigen::VectorXd(dd.col(k)), Eigen::VectorXd(db.col(k)), true));
  return g;
}

std::vector<TransferFunction> PhysicalModel::sensitivities(const Eigen::VectorXd& theta, double a) const {
  CTID_REQUIRE(theta.size() == n_parameters(), "PhysicalModel: {} parameter values for {} parameters", theta.size(),
               n_parameters());
  if (c_->ss) {
    // Sensitivity equations as one linear system per parameter (A already shifted by -aI):
    // [x; dx] with x' = A x + B u, dx' = dA x + A dx + dB u, dy = dC x + C dx + dD u.
    const StateSpaceWithGradient g = checked_state_space(c_->ss, theta);
    const StateSpace m = shift_ss(g.model, a);
    const Eigen::Index n = m.nx();
    std::vector<TransferFunction> out;
    for (const auto& d : g.derivatives) {
      Eigen::MatrixXd A2 = Eigen::MatrixXd::Zero(2 * n, 2 * n), B2(2 * n, 1), C2(1, 2 * n);
      A2.topLeftCorner(n, n) = m.A();
      A2.bottomLeftCorner(n, n) = d.A();
      A2.bottomRightCorner(n, n) = m.A();
      B2 << m.B(), d.B();
      C2 << d.C(), m.C();
      out.push_back(StateSpace(A2, B2, C2, d.D()).to_transfer_function());
    }
    return out;
  }
  Eigen::VectorXd num, den;
  Eigen::MatrixXd dn, dd;
  expand(*c_->root, expr_, theta, a, num, den, dn, dd);
  const Polynomial N(num), D(den);
  std::vector<TransferFunction> out;
  for (int k = 0; k < n_parameters(); ++k) {
    const Polynomial Nk(Eigen::VectorXd(dn.col(k))), Dk(Eigen::VectorXd(dd.col(k)));
    out.emplace_back(Nk * D - N * Dk, D * D);
  }
  return out;
}

}  // namespace ctid
