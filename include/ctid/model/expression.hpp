// ctid — the grey-box model language: a scalar expression of named variables (states, inputs,
// parameters, t), parsed once and compiled to a stack program that evaluates without allocation, with exact first
// derivatives by forward-mode differentiation of the same program.
//
// Grammar (precedence low to high; ^ is right-associative and binds tighter than unary minus: -x^2 = -(x^2)):
//   expr    := term (('+' | '-') term)*
//   term    := unary (('*' | '/') unary)*
//   unary   := '-' unary | power
//   power   := primary ('^' unary)?
//   primary := number | name | name '(' expr (',' expr)* ')' | '(' expr ')'
// Numbers: 2, 0.5, 1e-3. Functions: exp log sqrt abs sign tanh sin cos atan (one argument), min max pow (two),
// sat(x, lo, hi) (three) = min(max(x, lo), hi).
// Derivatives at the kinks (a set of measure zero along a trajectory): d sign = 0; d abs(x) = sign(x) dx;
// min/max follow the argument that is taken, the second on a tie (max(x, 0) at x = 0: 0, the ReLU convention);
// sat passes dx strictly inside (lo, hi) and the derivative of the bound otherwise. sqrt, log, pow and / have their
// usual derivatives where defined; at sqrt(0) and pow(0, b < 1) a partial that is zero stays zero and any other is
// infinite — so sqrt(max(x, 0)) and pow(max(x, 0), b) (the usual guards) have derivative 0 at x = 0; d pow(0, b)/db = 0.
#pragma once

#include <string>
#include <vector>

namespace ctid {

class Expression {
 public:
  Expression() = default;
  /// Parses `text` over `variables` (the names it may use, in the order of the value arrays). Throws
  /// InvalidArgument naming the expression, the column and the problem: an unknown name (with the closest
  /// variable or function), a wrong number of arguments, a misplaced token, an unbalanced parenthesis.
  Expression(const std::string& text, const std::vector<std::string>& variables);

  /// Whether `name` is one of the language's functions (a name no variable may take).
  static bool is_function(const std::string& name);

  const std::string& text() const { return text_; }
  int n_variables() const { return n_vars_; }
  /// Whether the expression reads variable i (its derivative with respect to the others is 0).
  const std::vector<bool>& uses() const { return uses_; }

  /// The value at x (x[i] = the value of variable i).
  double operator()(const double* x) const;
  /// The value at x; grad[i] = its derivative with respect to variable i (n_variables() entries).
  double gradient(const double* x, double* grad) const;

  /// The text of the argument of each sign() call, in the order the calls appear in the text.
  const std::vector<std::string>& sign_arguments() const { return sign_arguments_; }
  /// As above with the value of each sign() call given: signs[j] for the j-th call (NaN: the sign of its argument,
  /// as without `signs`). A grey-box simulation holds sign(s) at +-1 on each side of a switching surface s = 0 and
  /// gives the Filippov value on it (model/greybox.hpp).
  double operator()(const double* x, const double* signs) const;
  double gradient(const double* x, double* grad, const double* signs) const;

 private:
  enum class Code : unsigned char {
    Number, Variable, Add, Sub, Mul, Div, Pow, Neg, Exp, Log, Sqrt, Abs, Sign, Tanh, Sin, Cos, Atan, Min, Max, Sat
  };
  struct Op {
    Code code;
    int index = 0;       // Variable: which one
    double value = 0.0;  // Number
  };
  friend struct ExpressionParser;
  std::string text_;
  int n_vars_ = 0;
  std::vector<bool> uses_;
  std::vector<Op> program_;  // postfix; a Sign op's index is the ordinal of its call
  std::vector<std::string> sign_arguments_;
  int depth_ = 0;            // the largest stack the program needs
};

}  // namespace ctid
