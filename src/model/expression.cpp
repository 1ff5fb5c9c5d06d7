// ctid — the grey-box model language (include/ctid/model/expression.hpp): recursive-descent parser to a postfix
// program; evaluation and forward-mode differentiation of that program.
#include "ctid/model/expression.hpp"

#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>

#include "ctid/core/check.hpp"
#include "ctid/core/error.hpp"
#include "ctid/core/names.hpp"
#include "model/text_cursor.hpp"

namespace ctid {

namespace {
constexpr int kMaxDepth = 64;  // stack slots; deeper nesting is refused at parse time

struct Function {
  const char* name;
  int arity;
};
constexpr std::array<Function, 13> kFunctions = {{{"exp", 1}, {"log", 1}, {"sqrt", 1}, {"abs", 1}, {"sign", 1},
                                                   {"tanh", 1}, {"sin", 1}, {"cos", 1}, {"atan", 1}, {"min", 2},
                                                   {"max", 2}, {"pow", 2}, {"sat", 3}}};
}  // namespace

bool Expression::is_function(const std::string& name) {
  for (const auto& f : kFunctions)
    if (name == f.name) return true;
  return false;
}

struct ExpressionParser : model_detail::TextCursor {
  Expression& e;
  const std::vector<std::string>& vars;
  int depth = 0;

  ExpressionParser(const std::string& t, Expression& expression, const std::vector<std::string>& variables)
      : TextCursor{t}, e(expression), vars(variables) {}
  // Emits an op and tracks the stack height: `pops` operands replaced by one result.
  void emit(Expression::Code c, int pops, int index = 0, double value = 0.0) {
    e.program_.push_back({c, index, value});
    depth += 1 - pops;
    if (depth > kMaxDepth) fail(detail::format("nested more than {} levels deep", kMaxDepth));
    e.depth_ = std::max(e.depth_, depth);
  }

  void expr() {
    term();
    for (;;) {
      if (accept('+')) term(), emit(Expression::Code::Add, 2);
      else if (accept('-')) term(), emit(Expression::Code::Sub, 2);
      else return;
    }
  }
  void term() {
    unary();
    for (;;) {
      if (accept('*')) unary(), emit(Expression::Code::Mul, 2);
      else if (accept('/')) unary(), emit(Expression::Code::Div, 2);
      else return;
    }
  }
  void unary() {
    if (accept('-')) {
      unary();
      emit(Expression::Code::Neg, 1);
    } else {
      power();
    }
  }
  void power() {
    primary();
    if (accept('^')) {
      unary();
      emit(Expression::Code::Pow, 2);
    }
  }
  void primary() {
    skip();
    if (pos >= text.size()) fail("unexpected end of expression");
    const char c = text[pos];
    if (const auto v = number()) {
      emit(Expression::Code::Number, 0, 0, *v);
      return;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      const std::size_t start = pos;
      while (pos < text.size() && (std::isalnum(static_cast<unsigned char>(text[pos])) || text[pos] == '_')) ++pos;
      const std::string name = text.substr(start, pos - start);
      if (accept('(')) return call(name, start);
      for (std::size_t i = 0; i < vars.size(); ++i)
        if (vars[i] == name) {
          e.uses_[i] = true;
          emit(Expression::Code::Variable, 0, static_cast<int>(i));
          return;
        }
      pos = start;
      const std::string near = closest_name(name, vars);
      std::string known;
      for (const auto& v : vars) known += (known.empty() ? "" : ", ") + v;
      fail(detail::format("unknown name '{}'{} (names: {})", name, near.empty() ? "" : "; did you mean '" + near + "'?",
                          known.empty() ? "none" : known));
    }
    if (accept('(')) {
      expr();
      if (!accept(')')) fail("expected ')'");
      return;
    }
    fail(detail::format("unexpected '{}'", c));
  }
  void call(const std::string& name, std::size_t start) {
    const Function* f = nullptr;
    for (const auto& g : kFunctions)
      if (name == g.name) f = &g;
    if (!f) {
      pos = start;
      std::vector<std::string> names;
      for (const auto& g : kFunctions) names.emplace_back(g.name);
      const std::string near = closest_name(name, names);
      fail(detail::format("unknown function '{}'{}", name, near.empty() ? "" : "; did you mean '" + near + "'?"));
    }
    int args = 0;
    skip();
    const std::size_t arg_start = pos;
    if (!accept(')')) {
      do {
        expr();
        ++args;
      } while (accept(','));
      if (!accept(')')) fail(detail::format("expected ',' or ')' in {}(...)", name));
    }
    if (args != f->arity) {
      pos = start;
      fail(detail::format("{}() takes {} argument{} (got {})", name, f->arity, f->arity == 1 ? "" : "s", args));
    }
    using C = Expression::Code;
    static const std::array<C, 13> codes = {C::Exp, C::Log, C::Sqrt, C::Abs, C::Sign, C::Tanh, C::Sin,
                                            C::Cos, C::Atan, C::Min, C::Max, C::Pow, C::Sat};
    const C code = codes[static_cast<std::size_t>(f - kFunctions.data())];
    if (code == C::Sign) {  // the argument's text, up to the closing parenthesis
      std::size_t end = pos - 1;
      while (end > arg_start && std::isspace(static_cast<unsigned char>(text[end - 1]))) --end;
      emit(code, 1, static_cast<int>(e.sign_arguments_.size()));
      e.sign_arguments_.push_back(text.substr(arg_start, end - arg_start));
      return;
    }
    emit(code, f->arity);
  }
};

Expression::Expression(const std::string& text, const std::vector<std::string>& variables)
    : text_(text), n_vars_(static_cast<int>(variables.size())), uses_(variables.size(), false) {
  ExpressionParser p(text_, *this, variables);
  p.expr();
  p.skip();
  if (p.pos != text_.size()) p.fail(detail::format("unexpected '{}'", text_[p.pos]));
  CTID_ASSERT(p.depth == 1);
}

namespace {
double sign_of(double a) { return a > 0 ? 1.0 : a < 0 ? -1.0 : 0.0; }
}  // namespace

double Expression::operator()(const double* x) const { return (*this)(x, nullptr); }
double Expression::gradient(const double* x, double* grad) const { return gradient(x, grad, nullptr); }

double Expression::operator()(const double* x, const double* signs) const {
  CTID_REQUIRE(!program_.empty(), "Expression: evaluating an empty expression");
  std::array<double, kMaxDepth> st;
  int top = -1;
  for (const Op& op : program_) {
    switch (op.code) {
      case Code::Number: st[++top] = op.value; break;
      case Code::Variable: st[++top] = x[op.index]; break;
      case Code::Add: --top, st[top] += st[top + 1]; break;
      case Code::Sub: --top, st[top] -= st[top + 1]; break;
      case Code::Mul: --top, st[top] *= st[top + 1]; break;
      case Code::Div: --top, st[top] /= st[top + 1]; break;
      case Code::Pow: --top, st[top] = std::pow(st[top], st[top + 1]); break;
      case Code::Neg: st[top] = -st[top]; break;
      case Code::Exp: st[top] = std::exp(st[top]); break;
      case Code::Log: st[top] = std::log(st[top]); break;
      case Code::Sqrt: st[top] = std::sqrt(st[top]); break;
      case Code::Abs: st[top] = std::abs(st[top]); break;
      case Code::Sign: st[top] = signs && !std::isnan(signs[op.index]) ? signs[op.index] : sign_of(st[top]); break;
      case Code::Tanh: st[top] = std::tanh(st[top]); break;
      case Code::Sin: st[top] = std::sin(st[top]); break;
      case Code::Cos: st[top] = std::cos(st[top]); break;
      case Code::Atan: st[top] = std::atan(st[top]); break;
      case Code::Min: --top, st[top] = st[top] <= st[top + 1] ? st[top] : st[top + 1]; break;
      case Code::Max: --top, st[top] = st[top] >= st[top + 1] ? st[top] : st[top + 1]; break;
      case Code::Sat: {
        top -= 2;
        const double m = st[top] >= st[top + 1] ? st[top] : st[top + 1];  // max(x, lo)
        st[top] = m <= st[top + 2] ? m : st[top + 2];                       // min(., hi)
        break;
      }
    }
  }
  return st[0];
}

double Expression::gradient(const double* x, double* grad, const double* signs) const {
  CTID_REQUIRE(!program_.empty(), "Expression: evaluating an empty expression");
  const int n = n_vars_;
  std::array<double, kMaxDepth> v;
  thread_local std::vector<double> gs;  // depth_ rows of n partials; grows once per thread, then reused
  if (gs.size() < static_cast<std::size_t>(depth_ * std::max(n, 1))) gs.resize(static_cast<std::size_t>(depth_ * std::max(n, 1)));
  auto g = [&](int slot) { return gs.data() + static_cast<std::ptrdiff_t>(slot) * n; };
  auto scale = [&](int slot, double f) {
    double* a = g(slot);
    for (int i = 0; i < n; ++i) a[i] *= f;
  };
  auto combine = [&](int slot, double fa, double fb) {  // g(slot) = fa g(slot) + fb g(slot + 1)
    double* a = g(slot);
    const double* b = g(slot + 1);
    for (int i = 0; i < n; ++i) a[i] = fa * a[i] + fb * b[i];
  };
  auto take = [&](int slot, int from) {  // slot <- from (value and partials)
    v[slot] = v[from];
    std::copy(g(from), g(from) + n, g(slot));
  };
  int top = -1;
  for (const Op& op : program_) {
    switch (op.code) {
      case Code::Number:
        v[++top] = op.value;
        std::fill(g(top), g(top) + n, 0.0);
        break;
      case Code::Variable:
        v[++top] = x[op.index];
        std::fill(g(top), g(top) + n, 0.0);
        g(top)[op.index] = 1.0;
        break;
      case Code::Add: --top, v[top] += v[top + 1], combine(top, 1.0, 1.0); break;
      case Code::Sub: --top, v[top] -= v[top + 1], combine(top, 1.0, -1.0); break;
      case Code::Mul: {
        --top;
        const double a = v[top], b = v[top + 1];
        v[top] = a * b;
        combine(top, b, a);
        break;
      }
      case Code::Div: {
        --top;
        const double a = v[top], b = v[top + 1];
        v[top] = a / b;
        combine(top, 1.0 / b, -a / (b * b));
        break;
      }
      case Code::Pow: {
        --top;
        const double a = v[top], b = v[top + 1], p = std::pow(a, b);
        const double* gb = g(top + 1);
        bool exponent_varies = false;
        for (int i = 0; i < n; ++i) exponent_varies = exponent_varies || gb[i] != 0.0;
        // d a^b = b a^(b-1) da + a^b ln(a) db (the second term only where the exponent depends on a variable; 0 where
        // a^b = 0). At a = 0 with b < 1 the first factor is infinite: a zero partial stays zero (as for sqrt).
        const double fa = b == 0.0 ? 0.0 : b * std::pow(a, b - 1.0), fb = exponent_varies && p != 0.0 ? p * std::log(a) : 0.0;
        double* ga = g(top);
        for (int i = 0; i < n; ++i) ga[i] = (ga[i] == 0.0 ? 0.0 : fa * ga[i]) + (gb[i] == 0.0 ? 0.0 : fb * gb[i]);
        v[top] = p;
        break;
      }
      case Code::Neg: v[top] = -v[top], scale(top, -1.0); break;
      case Code::Exp: v[top] = std::exp(v[top]), scale(top, v[top]); break;
      case Code::Log: scale(top, 1.0 / v[top]), v[top] = std::log(v[top]); break;
      case Code::Sqrt: {  // a zero partial stays zero at sqrt(0) (no 0 * inf)
        v[top] = std::sqrt(v[top]);
        double* a = g(top);
        for (int i = 0; i < n; ++i) a[i] = a[i] == 0.0 ? 0.0 : a[i] * (0.5 / v[top]);
        break;
      }
      case Code::Abs: scale(top, sign_of(v[top])), v[top] = std::abs(v[top]); break;
      case Code::Sign:
        v[top] = signs && !std::isnan(signs[op.index]) ? signs[op.index] : sign_of(v[top]);
        scale(top, 0.0);
        break;
      case Code::Tanh: v[top] = std::tanh(v[top]), scale(top, 1.0 - v[top] * v[top]); break;
      case Code::Sin: scale(top, std::cos(v[top])), v[top] = std::sin(v[top]); break;
      case Code::Cos: scale(top, -std::sin(v[top])), v[top] = std::cos(v[top]); break;
      case Code::Atan: scale(top, 1.0 / (1.0 + v[top] * v[top])), v[top] = std::atan(v[top]); break;
      // On a tie the second argument is taken (its partials): max(x, 0) at x = 0 has derivative 0.
      case Code::Min: --top; if (!(v[top] < v[top + 1])) take(top, top + 1); break;
      case Code::Max: --top; if (!(v[top] > v[top + 1])) take(top, top + 1); break;
      case Code::Sat:
        top -= 2;
        if (!(v[top] > v[top + 1])) take(top, top + 1);  // max(x, lo)
        if (!(v[top] < v[top + 2])) take(top, top + 2);  // min(., hi)
        break;
    }
  }
  std::copy(g(0), g(0) + n, grad);
  return v[0];
}

}  // namespace ctid
