// ctid — nonlinear grey-box models (include/ctid/model/greybox.hpp): compilation of the equations, simulation and
// forward sensitivities (Ljung 1999 §7; Hairer, Norsett & Wanner I.14: the variational equations).
#include "ctid/model/greybox.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>

#include "ctid/core/check.hpp"
#include "ctid/core/error.hpp"
#include "ctid/core/names.hpp"
#include "ctid/model/expression.hpp"
#include "internal/levenberg_marquardt.hpp"
#include "internal/ode.hpp"

namespace ctid {

// Every expression reads z = [x (nx), u (nu), theta (np), t]; initial-state expressions read theta only.
struct GreyboxModel::Compiled {
  std::vector<Expression> f, h, x0;  // x0[i] empty (no text) for an estimated state without a start
  int nz = 0;
};

namespace {

bool is_identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

// The names an expression may read, in the order of z.
std::vector<std::string> variables_of(const GreyboxSpec& s) {
  std::vector<std::string> v = s.states;
  v.insert(v.end(), s.inputs.begin(), s.inputs.end());
  for (const auto& p : s.parameters) v.push_back(p.name);
  v.push_back("t");
  return v;
}

Expression compile(const std::string& text, const std::vector<std::string>& vars, const std::string& what) {
  try {
    return Expression(text, vars);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(what + ": " + e.what());
  }
}

}  // namespace

GreyboxModel::GreyboxModel(GreyboxSpec spec) : spec_(std::move(spec)) {
  const GreyboxSpec& s = spec_;
  CTID_REQUIRE(!s.states.empty(), "greybox model: no states (declare \"states\": [\"x1\", ..])");
  CTID_REQUIRE(!s.outputs.empty(), "greybox model: no outputs (declare \"outputs\": {{\"y\": \"x1\"}})");
  CTID_REQUIRE(s.equations.size() == s.states.size(), "greybox model: {} equations for {} states", s.equations.size(),
               s.states.size());
  CTID_REQUIRE(s.initial.size() == s.states.size(), "greybox model: {} initial values for {} states", s.initial.size(),
               s.states.size());
  std::set<std::string> seen;
  auto declare = [&](const std::string& name, const char* kind) {
    CTID_REQUIRE(is_identifier(name), "greybox model: {} name '{}' is not a name (letters, digits, _; not starting with a digit)",
                 kind, name);
    CTID_REQUIRE(name != "t" && !Expression::is_function(name),
                 "greybox model: {} name '{}' is reserved (t is the time; {} is a function)", kind, name, name);
    CTID_REQUIRE(seen.insert(name).second, "greybox model: the name '{}' is declared twice", name);
  };
  for (const auto& n : s.states) declare(n, "state");
  for (const auto& n : s.inputs) declare(n, "input");
  for (const auto& p : s.parameters) {
    declare(p.name, "parameter");
    CTID_REQUIRE(std::isfinite(p.value), "greybox model: parameter {} has value {} (not finite)", p.name, p.value);
    CTID_REQUIRE(!std::isnan(p.lower) && !std::isnan(p.upper) && p.lower < p.upper,
                 "greybox model: parameter {}: lower bound {} is not below upper bound {}", p.name, p.lower, p.upper);
    CTID_REQUIRE(p.value >= p.lower && p.value <= p.upper, "greybox model: parameter {} = {} lies outside its bounds [{}, {}]",
                 p.name, p.value, p.lower, p.upper);
  }
  std::set<std::string> outs;
  for (const auto& [name, e] : s.outputs) {
    CTID_REQUIRE(is_identifier(name), "greybox model: output name '{}' is not a name", name);
    CTID_REQUIRE(outs.insert(name).second, "greybox model: the output '{}' is declared twice", name);
  }
  auto c = std::make_shared<Compiled>();
  const std::vector<std::string> vars = variables_of(s);
  c->nz = static_cast<int>(vars.size());
  for (int i = 0; i < nx(); ++i)
    c->f.push_back(compile(s.equations[i], vars, "greybox model: equation of d" + s.states[i] + "/dt"));
  for (const auto& [name, e] : s.outputs) c->h.push_back(compile(e, vars, "greybox model: output " + name));
  std::vector<std::string> pnames = parameter_names();
  for (int i = 0; i < nx(); ++i) {
    const GreyboxInitial& in = s.initial[i];
    if (in.estimate && in.expression.empty()) {
      c->x0.emplace_back();
      continue;
    }
    // An initial value is a number or an expression of the parameters: reading a state, input or t is refused by name.
    const Expression e = compile(in.expression, vars, "greybox model: initial value of " + s.states[i]);
    for (int k = 0; k < c->nz; ++k)
      CTID_REQUIRE(!e.uses()[k] || (k >= nx() + nu() && k < nx() + nu() + np()),
                   "greybox model: the initial value of {} (\"{}\") reads {}: an initial value is a number or an "
                   "expression of the parameters (or \"estimate\")", s.states[i], in.expression, vars[k]);
    c->x0.push_back(compile(in.expression, pnames, "greybox model: initial value of " + s.states[i]));
  }
  c_ = std::move(c);
}

std::vector<std::string> GreyboxModel::parameter_names() const {
  std::vector<std::string> n;
  for (const auto& p : spec_.parameters) n.push_back(p.name);
  return n;
}

Eigen::VectorXd GreyboxModel::parameter_values() const {
  Eigen::VectorXd v(np());
  for (int i = 0; i < np(); ++i) v(i) = spec_.parameters[i].value;
  return v;
}

std::vector<std::string> GreyboxModel::output_names() const {
  std::vector<std::string> n;
  for (const auto& o : spec_.outputs) n.push_back(o.first);
  return n;
}

namespace {
int index_of(const std::vector<std::string>& names, const std::string& name, const char* kind) {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  const std::string near = closest_name(name, names);
  throw InvalidArgument(detail::format("greybox model: '{}' is not a {}{}", name, kind,
                                       near.empty() ? std::string() : "; did you mean '" + near + "'?"));
}
}  // namespace

int GreyboxModel::parameter_index(const std::string& name) const { return index_of(parameter_names(), name, "parameter"); }
int GreyboxModel::state_index(const std::string& name) const { return index_of(spec_.states, name, "state"); }

GreyboxModel GreyboxModel::with_parameters(const Eigen::VectorXd& values) const {
  CTID_REQUIRE(values.size() == np(), "greybox model: {} parameter values for {} parameters", values.size(), np());
  CTID_REQUIRE(values.allFinite(), "greybox model: parameter values must be finite");
  GreyboxModel m = *this;  // the compiled expressions read theta at run time: shared unchanged
  for (int i = 0; i < np(); ++i) m.spec_.parameters[i].value = values(i);
  return m;
}

GreyboxModel GreyboxModel::with_estimated_initial(const Eigen::VectorXd& x0) const {
  CTID_REQUIRE(x0.size() == nx(), "greybox model: {} initial values for {} states", x0.size(), nx());
  GreyboxSpec s = spec_;
  for (int i = 0; i < nx(); ++i)
    if (s.initial[i].estimate) s.initial[i].expression = detail::round_trip(x0(i));
  return GreyboxModel(std::move(s));
}

bool GreyboxModel::estimates_initial_state() const {
  for (const auto& in : spec_.initial)
    if (in.estimate) return true;
  return false;
}

Eigen::VectorXd GreyboxModel::initial_state() const {
  const Eigen::VectorXd theta = parameter_values();
  Eigen::VectorXd x0(nx());
  for (int i = 0; i < nx(); ++i) x0(i) = c_->x0[i].text().empty() ? NAN : c_->x0[i](theta.data());
  return x0;
}

Eigen::VectorXd GreyboxModel::initial_state_guess(const IdData& data) const {
  Eigen::VectorXd x0 = initial_state();
  for (int i = 0; i < nx(); ++i) {
    if (!std::isnan(x0(i))) continue;
    const int j = output_of_state(i);
    x0(i) = j >= 0 && j < data.ny() && data.size() > 0 ? data.y()(0, j) : 0.0;
  }
  return x0;
}

int GreyboxModel::output_of_state(int i) const {
  for (int j = 0; j < ny(); ++j) {
    std::string e = spec_.outputs[j].second;
    e.erase(std::remove_if(e.begin(), e.end(), [](unsigned char ch) { return std::isspace(ch); }), e.end());
    if (e == spec_.states[i]) return j;
  }
  return -1;
}

Eigen::MatrixXd GreyboxModel::initial_state_jacobian() const {
  const Eigen::VectorXd theta = parameter_values();
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(nx(), np());
  std::vector<double> g(static_cast<size_t>(np()));
  for (int i = 0; i < nx(); ++i) {
    if (spec_.initial[i].estimate || c_->x0[i].text().empty()) continue;
    c_->x0[i].gradient(theta.data(), g.data());
    for (int j = 0; j < np(); ++j) J(i, j) = g[static_cast<size_t>(j)];
  }
  return J;
}

std::string GreyboxModel::to_string() const {
  std::string out;
  for (int i = 0; i < nx(); ++i) out += "d" + spec_.states[i] + "/dt = " + spec_.equations[i] + "\n";
  for (const auto& [name, e] : spec_.outputs) out += name + " = " + e + "\n";
  return out;
}

namespace {
// Checks shared by simulate and sensitivities; returns the start state (estimated states without a value at 0).
Eigen::VectorXd checked_start(const GreyboxModel& m, const Eigen::MatrixXd& u, const Eigen::VectorXd& t,
                              const Eigen::VectorXd& x0) {
  CTID_REQUIRE(u.rows() == t.size(), "greybox simulate: {} input rows for {} times", u.rows(), t.size());
  CTID_REQUIRE(u.cols() == m.nu(), "greybox simulate: {} input columns for the model's {} inputs", u.cols(), m.nu());
  CTID_REQUIRE(t.size() >= 1, "greybox simulate: no samples");
  for (Eigen::Index k = 1; k < t.size(); ++k)
    CTID_REQUIRE(t(k) > t(k - 1), "greybox simulate: times must increase (t[{}] = {}, t[{}] = {})", k - 1, t(k - 1), k, t(k));
  CTID_REQUIRE(x0.size() == 0 || x0.size() == m.nx(), "greybox simulate: x0 has {} entries, the model has {} states",
               x0.size(), m.nx());
  Eigen::VectorXd start = x0.size() ? x0 : m.initial_state();
  for (Eigen::Index i = 0; i < start.size(); ++i)
    if (std::isnan(start(i))) start(i) = 0.0;
  CTID_REQUIRE(start.allFinite(), "greybox simulate: the initial state is not finite");
  return start;
}

// The expressions' variables z = [x, u, theta, t] at one instant (theta loaded once).
class Point {
 public:
  Point(const GreyboxModel& g, int nz) : z_(static_cast<size_t>(nz)), n_(g.nx()), m_(g.nu()) {
    for (int j = 0; j < g.np(); ++j) z_[static_cast<size_t>(n_ + m_ + j)] = g.spec().parameters[j].value;
  }
  const double* at(double t, const double* x, const double* u) {
    std::copy(x, x + n_, z_.begin());
    std::copy(u, u + m_, z_.begin() + n_);
    z_.back() = t;
    return z_.data();
  }
  // At sample k of the inputs u (N x nu), read in place (no temporary row per sample).
  const double* at(double t, const double* x, const Eigen::MatrixXd& u, Eigen::Index k) {
    std::copy(x, x + n_, z_.begin());
    for (int i = 0; i < m_; ++i) z_[static_cast<size_t>(n_ + i)] = u(k, i);
    z_.back() = t;
    return z_.data();
  }

 private:
  std::vector<double> z_;
  int n_, m_;
};

// Greybox integrations give up after 200 steps per sample on average (a stiff system or parameters that make it
// so, e.g. a drawn start of a multi-start search): far beyond what a model at the data's time scale needs.
long step_budget(const Eigen::VectorXd& t) { return 10000L + 200L * static_cast<long>(t.size()); }

std::string escape_message(const internal::OdeOutcome& o) {
  if (o.budget || o.collapsed)
    return detail::format("the integration stalled at t = {} s ({}) with the state finite: the model is stiff at these "
                          "parameters, its right-hand side switches back and forth across a discontinuity (e.g. "
                          "sign(v) friction at rest: a sliding mode this integrator cannot follow; smooth it, e.g. "
                          "tanh(v/0.01) for sign(v)), or the state runs into a singularity of it (e.g. a division by "
                          "a state that reaches 0)",
                          o.t, o.budget ? "more than 200 steps per sample" : "the step size collapsed");
  return detail::format("the solution escapes at t = {} s (|x| = {}): the model is unstable for this input, or its "
                        "parameters are far from the data's", o.t, o.xmax);
}
}  // namespace

GreyboxSimulation GreyboxModel::simulate(const Eigen::MatrixXd& u, const Eigen::VectorXd& t, Intersample intersample,
                                         const Eigen::VectorXd& x0, double rtol) const {
  const Eigen::VectorXd start = checked_start(*this, u, t, x0);
  const Compiled& c = *c_;
  const int n = nx();
  Point z(*this, c.nz);
  const internal::OdeRhs f = [&](double tt, const Eigen::VectorXd& x, const double* ui, Eigen::VectorXd& dx) {
    const double* v = z.at(tt, x.data(), ui);
    for (int i = 0; i < n; ++i) dx(i) = c.f[i](v);
  };
  GreyboxSimulation out;
  out.y = Eigen::MatrixXd::Constant(t.size(), ny(), NAN);
  out.x = Eigen::MatrixXd::Constant(t.size(), n, NAN);
  const internal::OdeOutcome o = internal::dopri45(
      f, start, u, t, intersample == Intersample::Zoh, rtol, 1e-3 * rtol, n, [&](Eigen::Index k, const Eigen::VectorXd& x) {
        const double* v = z.at(t(k), x.data(), u, k);
        out.x.row(k) = x.transpose();
        for (int j = 0; j < ny(); ++j) out.y(k, j) = c.h[j](v);
      }, step_budget(t));
  if (!o.ok) {
    out.termination = Termination::NumericalFailure;
    out.message = escape_message(o);
  }
  return out;
}

GreyboxSensitivities GreyboxModel::sensitivities(const Eigen::MatrixXd& u, const Eigen::VectorXd& t, Intersample intersample,
                                                 const Eigen::VectorXd& x0, const std::vector<int>& free,
                                                 const std::vector<int>& free_x0, double rtol,
                                                 bool x0_from_parameters) const {
  const Eigen::VectorXd start = checked_start(*this, u, t, x0);
  const Compiled& c = *c_;
  const int n = nx(), m = nu(), p = np(), ny_ = ny();
  for (int j : free) CTID_REQUIRE(j >= 0 && j < p, "greybox sensitivities: parameter index {} of {}", j, p);
  for (int j : free_x0) CTID_REQUIRE(j >= 0 && j < n, "greybox sensitivities: state index {} of {}", j, n);
  const int nf = static_cast<int>(free.size()), q = nf + static_cast<int>(free_x0.size());
  Point z(*this, c.nz);
  std::vector<double> g(static_cast<size_t>(c.nz));
  // The derivative along column j of S of the expression whose gradient g holds: dh/dx . S_j + dh/dtheta_{free[j]}
  // (no direct term for an initial state).
  auto chain = [&](const double* S, int j) {
    double d = j < nf ? g[static_cast<size_t>(n + m + free[static_cast<size_t>(j)])] : 0.0;
    for (int k = 0; k < n; ++k) d += g[static_cast<size_t>(k)] * S[k];
    return d;
  };
  auto column = [&](const Eigen::VectorXd& a, int j) { return a.data() + n + static_cast<Eigen::Index>(n) * j; };
  // Augmented state [x; S(:,0); ..; S(:,q-1)]: dS_j/dt = (df/dx) S_j + df/dtheta_{free[j]}.
  const internal::OdeRhs f = [&](double tt, const Eigen::VectorXd& a, const double* ui, Eigen::VectorXd& da) {
    const double* v = z.at(tt, a.data(), ui);
    for (int i = 0; i < n; ++i) {
      da(i) = c.f[i].gradient(v, g.data());
      for (int j = 0; j < q; ++j) da(n + static_cast<Eigen::Index>(n) * j + i) = chain(column(a, j), j);
    }
  };
  Eigen::VectorXd a0 = Eigen::VectorXd::Zero(n + static_cast<Eigen::Index>(n) * q);
  a0.head(n) = start;
  if (x0_from_parameters) {
    const Eigen::MatrixXd dx0 = initial_state_jacobian();
    for (int j = 0; j < nf; ++j) a0.segment(n + static_cast<Eigen::Index>(n) * j, n) = dx0.col(free[static_cast<size_t>(j)]);
  }
  for (size_t k = 0; k < free_x0.size(); ++k) a0(n + static_cast<Eigen::Index>(n) * (nf + static_cast<int>(k)) + free_x0[k]) = 1.0;
  GreyboxSensitivities out;
  out.y = Eigen::MatrixXd::Constant(t.size(), ny_, NAN);
  out.dy.assign(static_cast<size_t>(ny_), Eigen::MatrixXd::Constant(t.size(), q, NAN));
  const internal::OdeOutcome o = internal::dopri45(
      f, a0, u, t, intersample == Intersample::Zoh, rtol, 1e-3 * rtol, n, [&](Eigen::Index k, const Eigen::VectorXd& a) {
        const double* v = z.at(t(k), a.data(), u, k);
        for (int o2 = 0; o2 < ny_; ++o2) {
          out.y(k, o2) = c.h[o2].gradient(v, g.data());
          for (int j = 0; j < q; ++j) out.dy[static_cast<size_t>(o2)](k, j) = chain(column(a, j), j);
        }
        if (k + 1 == t.size()) {
          out.x_end = a.head(n);
          out.dx_end = Eigen::Map<const Eigen::MatrixXd>(a.data() + n, n, q);
        }
      }, step_budget(t));
  if (!o.ok) {
    out.ok = false;
    out.message = escape_message(o);
  }
  return out;
}

Eigen::VectorXd greybox_initial_state(const GreyboxModel& model, const IdData& data, int samples, double rtol) {
  CTID_REQUIRE(data.nu() == model.nu() && data.ny() == model.ny(),
               "greybox initial state: the data have {} inputs and {} outputs, the model {} and {}", data.nu(), data.ny(),
               model.nu(), model.ny());
  CTID_REQUIRE(samples >= 0, "greybox initial state: samples must be >= 0 (got {})", samples);
  const int n = samples == 0 ? data.size() : std::min(samples, data.size());
  std::vector<int> which;
  for (int i = 0; i < model.nx(); ++i)
    if (model.spec().initial[i].estimate) which.push_back(i);
  if (which.empty())
    for (int i = 0; i < model.nx(); ++i) which.push_back(i);
  CTID_REQUIRE(n * model.ny() >= static_cast<int>(which.size()),
               "greybox initial state: {} samples cannot determine {} initial states", n, which.size());
  const IdData d = data.slice(0, n);
  const Eigen::VectorXd t = d.times();
  const Intersample hold = d.intersample(0) == Intersample::Zoh ? Intersample::Zoh : Intersample::Foh;
  const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(d.y().data(), d.y().size());
  Eigen::VectorXd x0 = model.initial_state_guess(data);
  auto state = [&](const Eigen::VectorXd& v) {
    Eigen::VectorXd x = x0;
    for (size_t k = 0; k < which.size(); ++k) x(which[k]) = v(static_cast<Eigen::Index>(k));
    return x;
  };
  const internal::LmEvaluate evaluate = [&](const Eigen::VectorXd& v, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    const GreyboxSensitivities s = model.sensitivities(d.u(), t, hold, state(v), {}, which, rtol);
    if (!s.ok) return false;
    r = y - Eigen::Map<const Eigen::VectorXd>(s.y.data(), s.y.size());
    if (J) {
      J->resize(r.size(), static_cast<Eigen::Index>(which.size()));
      for (int j = 0; j < model.ny(); ++j) J->middleRows(static_cast<Eigen::Index>(j) * n, n) = -s.dy[j];
    }
    return true;
  };
  Eigen::VectorXd v(static_cast<Eigen::Index>(which.size()));
  for (size_t k = 0; k < which.size(); ++k) v(static_cast<Eigen::Index>(k)) = x0(which[k]);
  const Eigen::VectorXd inf = Eigen::VectorXd::Constant(v.size(), INFINITY);
  internal::LmOptions o;
  o.max_iterations = 100;
  const internal::LmResult lm = internal::levenberg_marquardt(evaluate, v, -inf, inf, o);
  CTID_REQUIRE(std::isfinite(lm.cost), "greybox initial state: the model cannot be simulated on the first {} samples "
               "from its initial-state guess", n);
  return state(lm.x);
}

}  // namespace ctid
