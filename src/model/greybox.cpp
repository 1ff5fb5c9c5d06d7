// ctid — nonlinear grey-box models (include/ctid/model/greybox.hpp): compilation of the equations, simulation and
// forward sensitivities (Ljung 1999 §7; Hairer, Norsett & Wanner I.14: the variational equations).
#include "ctid/model/greybox.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <set>

#include "ctid/core/check.hpp"
#include "ctid/core/error.hpp"
#include "ctid/core/names.hpp"
#include "ctid/model/expression.hpp"
#include "internal/ode.hpp"

namespace ctid {

// Every expression reads z = [x (nx), u (nu), theta (np), t]; initial-state expressions read theta only.
struct GreyboxModel::Compiled {
  std::vector<Expression> f, h, x0;  // x0[i] empty (no text) for an estimated state without a start
  int nz = 0;
  // Switching surfaces s(x, theta) = 0: the distinct arguments of the equations' sign() calls that read no input
  // and not t; surface_of[i][j] is the surface of the j-th sign() call of equation i, or -1 (sign of its argument).
  std::vector<Expression> surfaces;
  std::vector<std::vector<int>> surface_of;
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
    CTID_REQUIRE(name != "t", "greybox model: {} name 't' is reserved: t is the time in the equations", kind);
    CTID_REQUIRE(!Expression::is_function(name), "greybox model: {} name '{}' is reserved: {} is a function", kind,
                 name, name);
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
  std::vector<std::string> surface_text;
  for (const Expression& f : c->f) {
    c->surface_of.emplace_back();
    for (const std::string& arg : f.sign_arguments()) {
      Expression a(arg, vars);
      bool state_only = !a.uses()[static_cast<size_t>(c->nz - 1)];
      for (int k = nx(); k < nx() + nu(); ++k) state_only = state_only && !a.uses()[static_cast<size_t>(k)];
      std::string key = arg;
      key.erase(std::remove_if(key.begin(), key.end(), [](unsigned char ch) { return std::isspace(ch); }), key.end());
      int index = -1;
      if (state_only) {
        index = static_cast<int>(std::find(surface_text.begin(), surface_text.end(), key) - surface_text.begin());
        if (index == static_cast<int>(surface_text.size())) {
          surface_text.push_back(key);
          c->surfaces.push_back(std::move(a));
        }
      }
      c->surface_of.back().push_back(index);
    }
  }
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
                              const Eigen::VectorXd& x0, Intersample intersample) {
  CTID_REQUIRE(u.rows() == t.size(), "greybox simulate: {} input rows for {} times", u.rows(), t.size());
  CTID_REQUIRE(u.cols() == m.nu(), "greybox simulate: {} input columns for the model's {} inputs", u.cols(), m.nu());
  CTID_REQUIRE(t.size() >= 1, "greybox simulate: no samples");
  for (Eigen::Index k = 1; k < t.size(); ++k)
    CTID_REQUIRE(t(k) > t(k - 1), "greybox simulate: times must increase (t[{}] = {}, t[{}] = {})", k - 1, t(k - 1), k, t(k));
  if (intersample == Intersample::BandLimited && t.size() > 2) {
    const double h = (t(t.size() - 1) - t(0)) / static_cast<double>(t.size() - 1);
    for (Eigen::Index k = 1; k < t.size(); ++k)
      CTID_REQUIRE(std::abs(t(k) - t(k - 1) - h) <= 1e-6 * h,
                   "greybox simulate: band-limited inputs need uniformly sampled times (t[{}] - t[{}] = {} s, the mean "
                   "spacing is {} s); use foh for an irregularly sampled record", k, k - 1, t(k) - t(k - 1), h);
  }
  CTID_REQUIRE(x0.size() == 0 || x0.size() == m.nx(), "greybox simulate: x0 has {} entries, the model has {} states",
               x0.size(), m.nx());
  for (Eigen::Index i = 0; i < x0.size(); ++i)  // a given state is used as given: NaN is not "the default"
    CTID_REQUIRE(std::isfinite(x0(i)), "greybox simulate: x0[{}] ({}(0)) is {}; give a finite initial state (or none: "
                 "the model's own, its unset states at 0)", i, m.spec().states[static_cast<size_t>(i)], x0(i));
  Eigen::VectorXd start = x0.size() ? x0 : m.initial_state();
  for (Eigen::Index i = 0; i < start.size(); ++i)
    if (std::isnan(start(i))) start(i) = 0.0;
  CTID_REQUIRE(start.allFinite(), "greybox simulate: the initial state is not finite");
  return start;
}

// The expressions' variables z = [x, u, theta, t] at one instant (theta loaded once).
class Variables {
 public:
  Variables(const GreyboxModel& g, int nz) : z_(static_cast<size_t>(nz)), n_(g.nx()), m_(g.nu()) {
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

// The right-hand side with its switching surfaces s_k(x, theta) = 0 (the sign() arguments that read only states and
// parameters; Filippov 1988, Differential Equations with Discontinuous Righthand Sides, §2.4 and §4.2). Off a
// surface, sign(s_k) is held at the mode +-1 of the side the trajectory is on, so that f is smooth between events;
// the integrator locates where s_k changes sign (internal::OdeEvents). There, with f+ and f- the fields with
// sign(s_k) = +1 and -1 and a+- = ds/dx . f+-:
//   a+ < 0 < a-  (both fields point at the surface): a sliding mode (e.g. friction sticking), the Filippov field
//                f = alpha f+ + (1 - alpha) f-, alpha = a- / (a- - a+), which keeps ds/dt = 0; it ends where a+ or a-
//                reaches 0 (the field on that side turns away from the surface; f is continuous there);
//   otherwise    the trajectory crosses to the side the fields point to.
// At a crossing or the start of a sliding mode (a state event at time tau) the sensitivities jump (Rozenvasser 1967;
// Hiskens & Pai 2000, IEEE TCAS-I 47(2) eq. 13):
//   S+ = S- + (f_before - f_after) dtau/dq,   dtau/dq = -(ds/dx S- + ds/dq) / (ds/dx f_before),
// and inside a sliding mode they follow the Jacobian of the Filippov field, with the derivatives of alpha (the
// second derivatives of s along f by a central difference of its exact gradient: zero for a surface linear in the
// states, as sign(v)). At most one surface slides at a time (two at once is refused with a message).
class Switching {
 public:
  Switching(const std::vector<Expression>& f, const std::vector<Expression>& surfaces,
            const std::vector<std::vector<int>>& surface_of, int nx, int nz)
      : f_(f), s_(surfaces), of_(surface_of), n_(nx), nz_(nz), mode_(surfaces.size(), 1.0) {
    for (const auto& calls : of_) signs_.emplace_back(calls.size(), NAN);
    for (size_t k = 0; k < s_.size(); ++k) hold(static_cast<int>(k), 1.0);
    gs_.resize(static_cast<size_t>(nz));
    gp_.resize(static_cast<size_t>(nz));
    gm_.resize(static_cast<size_t>(nz));
    zz_.resize(static_cast<size_t>(nz));
    dap_.resize(nz), dam_.resize(nz), dalpha_.resize(nz);
    fp_.resize(nx), fm_.resize(nx);
    Gp_.resize(nx, nz), Gm_.resize(nx, nz);
  }
  int surfaces() const { return static_cast<int>(s_.size()); }
  int sliding() const {
    for (size_t k = 0; k < mode_.size(); ++k)
      if (mode_[k] == 0.0) return static_cast<int>(k);
    return -1;
  }
  std::string message;  // why the integration was stopped by a switching problem

  // dx = f(z); with G (nx x nz) also its Jacobian.
  void rhs(const double* z, double* dx, Eigen::MatrixXd* G) {
    const int k = sliding();
    if (k < 0) return fields(z, dx, G);
    hold(k, 1.0);
    fields(z, fp_.data(), G ? &Gp_ : nullptr);
    hold(k, -1.0);
    fields(z, fm_.data(), G ? &Gm_ : nullptr);
    const Expression& s = s_[static_cast<size_t>(k)];
    s.gradient(z, gs_.data());
    const double ap = slope(fp_), am = slope(fm_), d = am - ap;
    const double alpha = d > 0 ? std::clamp(am / d, 0.0, 1.0) : 0.5;
    for (int i = 0; i < n_; ++i) dx[i] = alpha * fp_(i) + (1 - alpha) * fm_(i);
    if (!G) return;
    // d alpha = (a- d a+ - a+ d a-) / d^2, d a+- = ds/dx . G+- + (d^2 s/dx dz) f+- (the latter by central differences).
    gradient_slope(z, fp_, Gp_, dap_);
    gradient_slope(z, fm_, Gm_, dam_);
    if (d > 0) dalpha_ = (am * dap_ - ap * dam_) / (d * d);
    else dalpha_.setZero();
    G->noalias() = alpha * Gp_ + (1 - alpha) * Gm_;
    G->noalias() += (fp_ - fm_) * dalpha_;
  }

  // The event functions at z: per surface, mode * s off it; -a+ and a- on it (an event where one reaches 0).
  void values(const double* z, double* g) {
    for (int k = 0; k < surfaces(); ++k) {
      const double m = mode_[static_cast<size_t>(k)];
      if (m != 0.0) {
        g[2 * k] = m * s_[static_cast<size_t>(k)](z);
        g[2 * k + 1] = 1.0;  // inactive (a constant that never reaches 0)
      } else {
        const auto [ap, am] = slopes(k, z);
        g[2 * k] = -ap;
        g[2 * k + 1] = am;
      }
    }
  }

  // The mode of surface k at z (on it, or having just reached it), given the mode it had.
  double decide(int k, const double* z, double old) {
    const auto [ap, am] = slopes(k, z);
    if (ap < 0 && am > 0) return 0.0;
    if (am > 0) return 1.0;   // both fields point to the + side
    if (ap < 0) return -1.0;  // both to the - side
    return old != 0.0 ? old : (ap >= -am ? 1.0 : -1.0);  // both away from the surface: stay
  }
  // The start: the side of each surface the state is on (on a surface, the mode decide() gives); false (message
  // set) when two surfaces would slide at once.
  bool start(const double* z) {
    for (int k = 0; k < surfaces(); ++k) {
      const double sv = s_[static_cast<size_t>(k)](z);
      const double m = sv > 0 ? 1.0 : sv < 0 ? -1.0 : decide(k, z, 0.0);
      if (m == 0.0 && sliding() >= 0) return refuse(k);
      set(k, m);
    }
    return true;
  }
  // An event of surface k at z: the new mode, or NaN when two surfaces would slide at once (message set). With S
  // (nx x q, the sensitivities, and dsdq the direct derivatives of s with respect to the q quantities) the jump.
  bool event(int k, const double* z, Eigen::Map<Eigen::MatrixXd>* S, const std::vector<int>& q_to_z) {
    const double old = mode_[static_cast<size_t>(k)];
    const double now = decide(k, z, old);
    if (now == old) return true;
    if (now == 0.0 && sliding() >= 0) return refuse(k);
    if (S && old != 0.0) {  // a crossing, or the start of a sliding mode: the sensitivities jump
      Eigen::VectorXd before(n_), after(n_);
      fields(z, before.data(), nullptr);
      set(k, now);
      rhs(z, after.data(), nullptr);
      s_[static_cast<size_t>(k)].gradient(z, gs_.data());
      const double den = slope(before);
      if (std::abs(den) > 1e-12 * Eigen::Map<const Eigen::VectorXd>(gs_.data(), n_).norm() * before.norm()) {
        const Eigen::VectorXd jump = before - after;
        for (Eigen::Index j = 0; j < S->cols(); ++j) {
          const int zj = q_to_z[static_cast<size_t>(j)];
          double num = zj >= 0 ? gs_[static_cast<size_t>(zj)] : 0.0;
          for (int i = 0; i < n_; ++i) num += gs_[static_cast<size_t>(i)] * (*S)(i, j);
          S->col(j) += jump * (-num / den);
        }
      }  // else a grazing contact: dtau/dq is unbounded, the jump is left out
      return true;
    }
    set(k, now);
    return true;
  }

 private:
  bool refuse(int k) {
    const std::string& a = s_[static_cast<size_t>(sliding())].text();
    const std::string& b = s_[static_cast<size_t>(k)].text();
    message = detail::format("two switching surfaces slide at once ({} = 0 and {} = 0): not supported; smooth one of the "
                             "sign() laws, e.g. tanh({}/0.01)", a, b, b);
    return false;
  }
  void set(int k, double m) {
    mode_[static_cast<size_t>(k)] = m;
    if (m != 0.0) hold(k, m);
  }
  // Every sign() call on surface k evaluates to v.
  void hold(int k, double v) {
    for (size_t i = 0; i < of_.size(); ++i)
      for (size_t j = 0; j < of_[i].size(); ++j)
        if (of_[i][j] == k) signs_[i][j] = v;
  }
  void fields(const double* z, double* dx, Eigen::MatrixXd* G) {
    for (int i = 0; i < n_; ++i) {
      const double* sg = signs_[static_cast<size_t>(i)].empty() ? nullptr : signs_[static_cast<size_t>(i)].data();
      if (!G) {
        dx[i] = f_[static_cast<size_t>(i)](z, sg);
        continue;
      }
      dx[i] = f_[static_cast<size_t>(i)].gradient(z, gp_.data(), sg);
      for (int c = 0; c < nz_; ++c) (*G)(i, c) = gp_[static_cast<size_t>(c)];
    }
  }
  double slope(const Eigen::VectorXd& fv) const {
    double a = 0;
    for (int i = 0; i < n_; ++i) a += gs_[static_cast<size_t>(i)] * fv(i);
    return a;
  }
  // a+ and a- of surface k at z (the mode of k unchanged).
  std::pair<double, double> slopes(int k, const double* z) {
    const double m = mode_[static_cast<size_t>(k)];
    s_[static_cast<size_t>(k)].gradient(z, gs_.data());
    hold(k, 1.0);
    fields(z, fp_.data(), nullptr);
    hold(k, -1.0);
    fields(z, fm_.data(), nullptr);
    if (m != 0.0) hold(k, m);
    return {slope(fp_), slope(fm_)};
  }
  // d(ds/dx . f)/dz = ds/dx . G + (d/dz ds/dx) . f, the second term as the central difference of the gradient of s
  // along f: (grad s(x + e f) - grad s(x - e f)) / (2 e).
  void gradient_slope(const double* z, const Eigen::VectorXd& fv, const Eigen::MatrixXd& G, Eigen::RowVectorXd& d) {
    d.setZero();
    for (int i = 0; i < n_; ++i) d += gs_[static_cast<size_t>(i)] * G.row(i);
    const int k = sliding();
    const double fn = fv.norm();
    if (fn == 0.0) return;
    double xn = 0;
    for (int i = 0; i < n_; ++i) xn = std::max(xn, std::abs(z[i]));
    const double e = 1e-6 * (1.0 + xn) / fn;
    std::copy(z, z + nz_, zz_.begin());
    for (int i = 0; i < n_; ++i) zz_[static_cast<size_t>(i)] = z[i] + e * fv(i);
    s_[static_cast<size_t>(k)].gradient(zz_.data(), gp_.data());
    for (int i = 0; i < n_; ++i) zz_[static_cast<size_t>(i)] = z[i] - e * fv(i);
    s_[static_cast<size_t>(k)].gradient(zz_.data(), gm_.data());
    for (int c = 0; c < nz_; ++c) d(c) += (gp_[static_cast<size_t>(c)] - gm_[static_cast<size_t>(c)]) / (2 * e);
  }

  const std::vector<Expression>& f_;
  const std::vector<Expression>& s_;
  const std::vector<std::vector<int>>& of_;
  int n_, nz_;
  std::vector<double> mode_;                // +1, -1, or 0 (sliding) per surface
  std::vector<std::vector<double>> signs_;  // per equation, the value of each sign() call (NaN: its argument's sign)
  std::vector<double> gs_, gp_, gm_, zz_;   // gradients (nz), a shifted point
  Eigen::VectorXd fp_, fm_;
  Eigen::MatrixXd Gp_, Gm_;
  Eigen::RowVectorXd dap_, dam_, dalpha_;  // d a+, d a-, d alpha (nz)
};

// Greybox integrations give up after 200 steps per sample on average (a stiff system or parameters that make it
// so, e.g. a drawn start of a multi-start search): far beyond what a model at the data's time scale needs.
long step_budget(const Eigen::VectorXd& t) { return 10000L + 200L * static_cast<long>(t.size()); }

std::string escape_message(const internal::OdeOutcome& o, const Switching& sw) {
  if (o.refused) return detail::format("the integration stopped at t = {} s: {}", o.t, sw.message);
  if (o.chatter)
    return detail::format("the integration stopped at t = {} s: more than 1000 switchings of sign() within one sample "
                          "interval (a Zeno-type chattering the model cannot leave); smooth the law, e.g. tanh(v/0.01) for "
                          "sign(v)", o.t);
  if (o.budget || o.collapsed)
    return detail::format("the integration stalled at t = {} s ({}) with the state finite: the model is stiff at these "
                          "parameters (the explicit integrator gives up after 200 steps per sample; integrator=bdf "
                          "integrates stiff models, and auto, the default, switches to it), its right-hand side "
                          "switches back and forth across a discontinuity that is not a sign() of the states (e.g. sign(u - v) of an input; smooth it, e.g. tanh((u - v)/0.01)), "
                          "or the state runs into a singularity of it (e.g. a division by a state that reaches 0)",
                          o.t, o.budget ? "more than 200 steps per sample" : "the step size collapsed");
  return detail::format("the solution escapes at t = {} s (|x| = {}): the model is unstable for this input, or its "
                        "parameters are far from the data's", o.t, o.xmax);
}
}  // namespace

namespace {
// Integrates [x; S] (S: the sensitivities to the quantities q_to_z, n x q column by column after x; q = 0: the states
// alone) from a0 with the switching surfaces' events: Dormand-Prince 5(4), or CVODES's BDF, or (Auto) Dormand-Prince
// and, where it needs more than its step budget (a stiff model), BDF. reset() is called before each attempt.
internal::OdeOutcome integrate(Switching& sw, Variables& z, int n, int nz, const std::vector<int>& q_to_z,
                               const Eigen::VectorXd& a0, const Eigen::MatrixXd& u, const Eigen::VectorXd& t,
                               Intersample intersample, double rtol, GreyboxIntegrator integrator,
                               const internal::OdeSample& sample, const std::function<void()>& reset,
                               GreyboxIntegrator& used) {
  const int q = static_cast<int>(q_to_z.size());
  Eigen::MatrixXd G(n, nz);
  // dS_j/dt = (df/dx) S_j + df/dz[q_to_z[j]] (no direct term for an initial state).
  const internal::OdeRhs explicit_rhs = [&](double tt, const Eigen::VectorXd& a, const double* ui, Eigen::VectorXd& da) {
    sw.rhs(z.at(tt, a.data(), ui), da.data(), q ? &G : nullptr);
    for (int j = 0; j < q; ++j) {
      const double* S = a.data() + n + static_cast<Eigen::Index>(n) * j;
      const int zj = q_to_z[static_cast<size_t>(j)];
      for (int i = 0; i < n; ++i) {
        double d = zj >= 0 ? G(i, zj) : 0.0;
        for (int k = 0; k < n; ++k) d += G(i, k) * S[k];
        da(n + static_cast<Eigen::Index>(n) * j + i) = d;
      }
    }
  };
  const internal::OdeJacobianRhs stiff_rhs = [&](double tt, const double* x, const double* ui, double* dx,
                                                 Eigen::MatrixXd* J, Eigen::MatrixXd* B) {
    sw.rhs(z.at(tt, x, ui), dx, J || B ? &G : nullptr);
    if (J) *J = G.leftCols(n);
    if (B)
      for (int j = 0; j < q; ++j) {
        if (q_to_z[static_cast<size_t>(j)] >= 0) B->col(j) = G.col(q_to_z[static_cast<size_t>(j)]);
        else B->col(j).setZero();
      }
  };
  const internal::Between between = intersample == Intersample::Zoh           ? internal::Between::Hold
                                    : intersample == Intersample::BandLimited ? internal::Between::BandLimited
                                                                              : internal::Between::Linear;
  internal::OdeEvents events;
  events.count = 2 * sw.surfaces();
  events.values = [&](double tt, const double* x, const double* ui, double* g) { sw.values(z.at(tt, x, ui), g); };
  events.fire = [&](int i, double tt, Eigen::VectorXd& a, const double* ui) {
    Eigen::Map<Eigen::MatrixXd> S(a.data() + n, n, q);
    return sw.event(i / 2, z.at(tt, a.data(), ui), q ? &S : nullptr, q_to_z);
  };
  auto run = [&](bool stiff) {
    reset();
    if (sw.surfaces() && !sw.start(z.at(t(0), a0.data(), u, 0))) {
      internal::OdeOutcome o;
      o.ok = false;
      o.refused = true;
      o.t = t(0);
      return o;
    }
    const internal::OdeEvents* ev = sw.surfaces() ? &events : nullptr;
    return stiff ? internal::bdf(stiff_rhs, n, a0, u, t, between, rtol, 1e-3 * rtol, sample, step_budget(t), ev)
                 : internal::dopri45(explicit_rhs, a0, u, t, between, rtol, 1e-3 * rtol, n, sample, step_budget(t), ev);
  };
  used = integrator == GreyboxIntegrator::Bdf ? GreyboxIntegrator::Bdf : GreyboxIntegrator::Explicit;
  internal::OdeOutcome o = run(used == GreyboxIntegrator::Bdf);
  if (integrator == GreyboxIntegrator::Auto && !o.ok && o.budget) o = run(true), used = GreyboxIntegrator::Bdf;
  return o;
}
}  // namespace

GreyboxSimulation GreyboxModel::simulate(const Eigen::MatrixXd& u, const Eigen::VectorXd& t, Intersample intersample,
                                         const Eigen::VectorXd& x0, double rtol, GreyboxIntegrator integrator) const {
  const Eigen::VectorXd start = checked_start(*this, u, t, x0, intersample);
  const Compiled& c = *c_;
  const int n = nx();
  Variables z(*this, c.nz);
  Switching sw(c.f, c.surfaces, c.surface_of, n, c.nz);
  GreyboxSimulation out;
  const internal::OdeOutcome o = integrate(
      sw, z, n, c.nz, {}, start, u, t, intersample, rtol, integrator,
      [&](Eigen::Index k, const Eigen::VectorXd& x) {
        const double* v = z.at(t(k), x.data(), u, k);
        out.x.row(k) = x.transpose();
        for (int j = 0; j < ny(); ++j) out.y(k, j) = c.h[j](v);
      },
      [&] {
        out.y = Eigen::MatrixXd::Constant(t.size(), ny(), NAN);
        out.x = Eigen::MatrixXd::Constant(t.size(), n, NAN);
      },
      out.integrator);
  if (!o.ok) {
    out.termination = Termination::NumericalFailure;
    out.message = escape_message(o, sw);
  }
  return out;
}

GreyboxSensitivities GreyboxModel::sensitivities(const Eigen::MatrixXd& u, const Eigen::VectorXd& t, Intersample intersample,
                                                 const Eigen::VectorXd& x0, const std::vector<int>& free,
                                                 const std::vector<int>& free_x0, double rtol,
                                                 bool x0_from_parameters, GreyboxIntegrator integrator) const {
  const Eigen::VectorXd start = checked_start(*this, u, t, x0, intersample);
  const Compiled& c = *c_;
  const int n = nx(), m = nu(), p = np(), ny_ = ny();
  for (int j : free) CTID_REQUIRE(j >= 0 && j < p, "greybox sensitivities: parameter index {} of {}", j, p);
  for (int j : free_x0) CTID_REQUIRE(j >= 0 && j < n, "greybox sensitivities: state index {} of {}", j, n);
  const int nf = static_cast<int>(free.size()), q = nf + static_cast<int>(free_x0.size());
  // Column j of S is the derivative with respect to z[q_to_z[j]] (a parameter) or an initial state (-1).
  std::vector<int> q_to_z(static_cast<size_t>(q), -1);
  for (int j = 0; j < nf; ++j) q_to_z[static_cast<size_t>(j)] = n + m + free[static_cast<size_t>(j)];
  Variables z(*this, c.nz);
  Switching sw(c.f, c.surfaces, c.surface_of, n, c.nz);
  std::vector<double> g(static_cast<size_t>(c.nz));
  // The derivative along column j of S of the output whose gradient g holds: dh/dx . S_j + dh/dz[q_to_z[j]].
  auto chain = [&](const double* S, int j) {
    const int zj = q_to_z[static_cast<size_t>(j)];
    double d = zj >= 0 ? g[static_cast<size_t>(zj)] : 0.0;
    for (int k = 0; k < n; ++k) d += g[static_cast<size_t>(k)] * S[k];
    return d;
  };
  Eigen::VectorXd a0 = Eigen::VectorXd::Zero(n + static_cast<Eigen::Index>(n) * q);
  a0.head(n) = start;
  if (x0_from_parameters) {
    const Eigen::MatrixXd dx0 = initial_state_jacobian();
    for (int j = 0; j < nf; ++j) a0.segment(n + static_cast<Eigen::Index>(n) * j, n) = dx0.col(free[static_cast<size_t>(j)]);
  }
  for (size_t k = 0; k < free_x0.size(); ++k) a0(n + static_cast<Eigen::Index>(n) * (nf + static_cast<int>(k)) + free_x0[k]) = 1.0;
  GreyboxSensitivities out;
  const internal::OdeOutcome o = integrate(
      sw, z, n, c.nz, q_to_z, a0, u, t, intersample, rtol, integrator,
      [&](Eigen::Index k, const Eigen::VectorXd& a) {
        const double* v = z.at(t(k), a.data(), u, k);
        for (int o2 = 0; o2 < ny_; ++o2) {
          out.y(k, o2) = c.h[o2].gradient(v, g.data());
          for (int j = 0; j < q; ++j)
            out.dy[static_cast<size_t>(o2)](k, j) = chain(a.data() + n + static_cast<Eigen::Index>(n) * j, j);
        }
        if (k + 1 == t.size()) {
          out.x_end = a.head(n);
          out.dx_end = Eigen::Map<const Eigen::MatrixXd>(a.data() + n, n, q);
        }
      },
      [&] {
        out.y = Eigen::MatrixXd::Constant(t.size(), ny_, NAN);
        out.dy.assign(static_cast<size_t>(ny_), Eigen::MatrixXd::Constant(t.size(), q, NAN));
      },
      out.integrator);
  if (!o.ok) {
    out.ok = false;
    out.message = escape_message(o, sw);
  }
  return out;
}

Intersample greybox_intersample(const IdData& data) {
  bool zoh = true, bl = true;
  for (int i = 0; i < data.nu(); ++i) {
    zoh = zoh && data.intersample(i) == Intersample::Zoh;
    bl = bl && data.intersample(i) == Intersample::BandLimited;
  }
  return zoh ? Intersample::Zoh : bl ? Intersample::BandLimited : Intersample::Foh;
}

}  // namespace ctid
