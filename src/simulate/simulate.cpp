// ctid — simulate any model on a record with an explicit initial condition (include/ctid/simulate/simulate.hpp).
#include "ctid/simulate/simulate.hpp"

#include <cmath>

#include "ctid/core/check.hpp"
#include "ctid/simulate/lsim.hpp"

namespace ctid {

const char* to_string(InitialCondition initial) {
  switch (initial) {
    case InitialCondition::Rest: return "rest";
    case InitialCondition::Measured: return "measured";
    case InitialCondition::Estimated: return "estimated";
  }
  return "rest";
}

InitialCondition initial_condition_from_string(const std::string& name) {
  for (auto c : {InitialCondition::Rest, InitialCondition::Measured, InitialCondition::Estimated})
    if (name == to_string(c)) return c;
  CTID_REQUIRE(false, "initial condition '{}' is not one of rest, measured, estimated", name);
  return InitialCondition::Rest;
}

InitialCondition fit_initial_condition(const AnyModel& model, const Diagnostics& diagnostics) {
  if (std::holds_alternative<NarxModel>(model)) return InitialCondition::Measured;
  return diagnostics.has(diagnostic::x0) ? InitialCondition::Estimated : InitialCondition::Rest;
}

InitialCondition validation_initial_condition(const AnyModel& model) {
  if (std::holds_alternative<NarxModel>(model) || std::holds_alternative<NdeModel>(model)) return InitialCondition::Measured;
  if (std::holds_alternative<FsfModel>(model)) return InitialCondition::Rest;
  return InitialCondition::Estimated;
}

SimulateOptions simulate_options(const Result<AnyModel>& result, SimulationPurpose purpose,
                                 std::optional<InitialCondition> initial, int initial_samples) {
  const AnyModel& m = result.model;
  const Diagnostics& g = result.diagnostics;
  SimulateOptions o;
  if (initial) o.initial = *initial;
  else
    switch (purpose) {
      case SimulationPurpose::OwnFit: o.initial = fit_initial_condition(m, g); break;
      case SimulationPurpose::OtherRecord: o.initial = fit_initial_condition(m, Diagnostics{}); break;
      case SimulationPurpose::Validation: o.initial = validation_initial_condition(m); break;
      case SimulationPurpose::FreeRun:
        o.initial = std::holds_alternative<GreyboxModel>(m) ? fit_initial_condition(m, g) : InitialCondition::Rest;
        break;
    }
  CTID_REQUIRE(initial_samples == 0 || (o.initial == InitialCondition::Estimated && std::holds_alternative<GreyboxModel>(m)),
               "simulate: initial_samples needs the initial condition estimated and a grey-box model (got {} and a {} "
               "model)",
               to_string(o.initial), model_type_name(m));
  o.initial_samples = initial_samples;
  const bool fitted_x0 = o.initial == InitialCondition::Estimated && initial_samples == 0 && g.has(diagnostic::x0) &&
                         (purpose == SimulationPurpose::OwnFit || (purpose == SimulationPurpose::FreeRun && !is_linear(m)));
  if (fitted_x0) o.x0 = g.get(diagnostic::x0);
  return o;
}

Simulation simulate(const Result<AnyModel>& result, const IdData& data, SimulationPurpose purpose,
                    std::optional<InitialCondition> initial, int initial_samples) {
  return simulate(result.model, data, simulate_options(result, purpose, initial, initial_samples));
}

namespace {

// One linear state-space block of a model: its realisation, the input column that drives it and its delay.
struct Block {
  StateSpace ss;
  int input = 0;  ///< -1: all inputs (a state-space model)
  double delay = 0.0;
};

std::vector<Block> blocks_of(const AnyModel& model) {
  std::vector<Block> b;
  if (const auto* tf = std::get_if<TransferFunction>(&model)) b.push_back({tf->to_state_space(), 0, tf->io_delay()});
  if (const auto* m = std::get_if<MisoModel>(&model))
    for (int i = 0; i < m->nu(); ++i) {
      const TransferFunction& c = m->channels[static_cast<size_t>(i)];
      b.push_back({c.to_state_space(), i, c.io_delay()});
    }
  if (const auto* ss = std::get_if<StateSpace>(&model)) b.push_back({*ss, -1, 0.0});
  return b;
}

Eigen::MatrixXd lsim_block(const Block& b, const IdData& d, const Eigen::VectorXd& x0, bool zero_input) {
  LsimOptions o;
  o.x0 = x0;
  o.input_delay = b.delay;
  std::vector<Intersample> is;
  Eigen::MatrixXd u;
  if (b.input < 0) {
    u = d.u();
    for (int i = 0; i < d.nu(); ++i) is.push_back(d.intersample(i));
  } else {
    u = d.u().col(b.input);
    is.push_back(d.intersample(b.input));
  }
  if (zero_input) u.setZero();
  return lsim(b.ss, u, d.times(), is, o);
}

// Linear models: the blocks' outputs summed, from x0 (stacked block states; empty: rest), or with the
// least-squares x0 for Estimated.
Simulation simulate_linear(const AnyModel& model, const IdData& d, const SimulateOptions& o) {
  const std::vector<Block> blocks = blocks_of(model);
  int nx = 0;
  for (const auto& b : blocks) nx += b.ss.nx();
  CTID_REQUIRE(o.initial != InitialCondition::Measured,
               "simulate: a {} model has no output history to take from the record; use the initial condition rest "
               "or estimated",
               model_type_name(model));
  Simulation s;
  s.x0 = o.x0;
  const int ny = model_outputs(model);
  if (o.initial == InitialCondition::Estimated && o.x0.size() == 0) {
    CTID_REQUIRE(d.ny() == ny, "simulate: estimating the initial state needs the record's {} output(s) (it has {})", ny,
                 d.ny());
    // y = y_rest + O x0: O's column i is the free response from the i-th unit state.
    Eigen::MatrixXd rest = Eigen::MatrixXd::Zero(d.size(), ny);
    for (const auto& b : blocks) rest += lsim_block(b, d, Eigen::VectorXd(), false);
    Eigen::MatrixXd O(static_cast<Eigen::Index>(d.size()) * ny, nx);
    int col = 0;
    for (const auto& b : blocks)
      for (int i = 0; i < b.ss.nx(); ++i, ++col) {
        const Eigen::MatrixXd f = lsim_block(b, d, Eigen::VectorXd::Unit(b.ss.nx(), i), true);
        O.col(col) = f.reshaped();
      }
    const Eigen::MatrixXd r = d.y() - rest;
    s.x0 = nx > 0 ? Eigen::VectorXd(O.completeOrthogonalDecomposition().solve(r.reshaped())) : Eigen::VectorXd(0);
  }
  CTID_REQUIRE(s.x0.size() == 0 || s.x0.size() == nx, "simulate: x0 has {} entries; the {} model has {} states",
               s.x0.size(), model_type_name(model), nx);
  s.y = Eigen::MatrixXd::Zero(d.size(), ny);
  int at = 0;
  for (const auto& b : blocks) {
    const Eigen::VectorXd xb = s.x0.size() ? Eigen::VectorXd(s.x0.segment(at, b.ss.nx())) : Eigen::VectorXd();
    s.y += lsim_block(b, d, xb, false);
    at += b.ss.nx();
  }
  return s;
}

void require_uniform_at(const IdData& d, double ts, const char* what) {
  CTID_REQUIRE(d.is_uniform() && std::abs(d.ts() - ts) <= 1e-9 * ts,
               "simulate: the {} model runs at Ts = {} s; the record must be uniformly sampled at it (it is {})", what, ts,
               d.is_uniform() ? "sampled at " + std::to_string(d.ts()) + " s" : std::string("irregularly sampled"));
}

// An FSF model fitted to windowed data (a > 0) describes G(s + a): it cannot stand for the system.
void require_unwindowed(const FsfModel& m, const char* who) {
  CTID_REQUIRE(m.shift() == 0.0,
               "{}: the FSF model was fitted to exponentially windowed data (shift a = {} 1/s): it describes "
               "G(s + a), not the system; fit it with a = 0, or fit the physical parameters",
               who, m.shift());
}

Simulation simulate_fsf(const FsfModel& m, const IdData& d, const SimulateOptions& o) {
  CTID_REQUIRE(o.initial == InitialCondition::Rest,
               "simulate: an FSF model is a finite impulse response from rest; its initial condition can only be rest");
  require_unwindowed(m, "simulate");
  require_uniform_at(d, m.delta(), "FSF");
  return {m.simulate(d.u().col(0)), Eigen::VectorXd(), ""};
}

Simulation simulate_narx(const NarxModel& model, const IdData& d, const SimulateOptions& o) {
  require_uniform_at(d, model.ts(), "NARX");
  const NarxModel p = model.process();
  const int L = std::min(p.max_lag(), d.size());
  Simulation s;
  if (o.initial != InitialCondition::Rest) {
    if (o.x0.size()) {
      CTID_REQUIRE(o.x0.size() == L, "simulate: x0 of a NARX model is its first {} outputs (got {} values)", L, o.x0.size());
      s.x0 = o.x0;
    } else {
      CTID_REQUIRE(d.ny() >= 1, "simulate: the {} initial condition of a NARX model needs the record's output",
                   to_string(o.initial));
      s.x0 = d.y().col(0).head(L);
    }
  }
  bool escaped = false;
  s.y = p.simulate(d.u().col(0), s.x0, &escaped);
  if (escaped) s.problem = "the NARX simulation escapes (blows up) for this input";
  return s;
}

Simulation simulate_nde(const NdeModel& m, const IdData& d, const SimulateOptions& o) {
  Simulation s;
  if (o.initial == InitialCondition::Estimated) {
    CTID_REQUIRE(o.x0.size() > 0,
                 "simulate: an NDE model's estimated initial state comes from its output-error fit (the result's "
                 "diagnostics x0); none was given");
    s.x0 = o.x0;
  } else if (o.initial == InitialCondition::Measured) {
    CTID_REQUIRE(d.ny() >= 1, "simulate: the measured initial condition of an NDE model needs the record's output");
    int order = 0;
    for (const auto& t : m.terms())
      for (const auto& f : t.factors) order = std::max(order, f.input ? 0 : f.derivative);
    s.x0 = Eigen::VectorXd::Zero(std::max(order, 1));
    s.x0(0) = d.y()(0, 0);
  }
  Eigen::VectorXd t(d.size());
  for (int i = 0; i < d.size(); ++i) t(i) = d.time(i) - d.t0();
  const NdeSimulation r = m.simulate(d.u().col(0), t, d.intersample(0), s.x0);
  s.y = r.y;
  if (!r.ok()) s.problem = r.message;
  return s;
}

// Grey-box models: rest = zero state; measured = the model's initial state with each state that an output reads
// alone taken from that output's first sample; estimated = `x0`, else the state that best explains the record's first
// initial_samples samples (greybox_initial_state, greybox_initial_state.cpp).
Simulation simulate_greybox(const GreyboxModel& m, const IdData& d, const SimulateOptions& o) {
  Simulation s;
  if (o.initial == InitialCondition::Rest) {
    s.x0 = Eigen::VectorXd::Zero(m.nx());
  } else {
    CTID_REQUIRE(d.ny() == m.ny(), "simulate: the {} initial condition of a grey-box model needs the record's {} output(s) "
                 "(got {})", to_string(o.initial), m.ny(), d.ny());
    if (o.initial == InitialCondition::Measured) {
      s.x0 = m.initial_state_guess(d);
      for (int i = 0; i < m.nx(); ++i)
        if (m.spec().initial[i].estimate && m.output_of_state(i) >= 0) s.x0(i) = d.y()(0, m.output_of_state(i));
    } else {
      CTID_REQUIRE(o.x0.size() == 0 || o.x0.size() == m.nx(), "simulate: x0 has {} values, the grey-box model has {} states",
                   o.x0.size(), m.nx());
      s.x0 = o.x0.size() ? o.x0 : greybox_initial_state(m, d, o.initial_samples);
    }
  }
  const GreyboxSimulation r = m.simulate(d.u(), d.times(), greybox_intersample(d), s.x0);
  s.y = r.y;
  if (!r.ok()) s.problem = r.message;
  return s;
}

}  // namespace

Simulation simulate(const AnyModel& model, const IdData& data, const SimulateOptions& options) {
  CTID_REQUIRE(data.nu() == model_inputs(model), "simulate: the {} model has {} input(s) but the record has {}",
               model_type_name(model), model_inputs(model), data.nu());
  Simulation s;
  if (const auto* f = std::get_if<FsfModel>(&model)) s = simulate_fsf(*f, data, options);
  else if (const auto* n = std::get_if<NarxModel>(&model)) s = simulate_narx(*n, data, options);
  else if (const auto* e = std::get_if<NdeModel>(&model)) s = simulate_nde(*e, data, options);
  else if (const auto* g = std::get_if<GreyboxModel>(&model)) s = simulate_greybox(*g, data, options);
  else s = simulate_linear(model, data, options);
  if (!s.ok()) return s;
  // Diverged: a non-finite sample, or samples so large that their squares overflow (then every fit
  // measure and correlation would be Inf or 0/Inf).
  double acc = 0;
  for (Eigen::Index k = 0; k < s.y.rows(); ++k) {
    acc += s.y.row(k).squaredNorm();
    if (!std::isfinite(acc)) {
      s.problem = "the simulated output is not finite from sample " + std::to_string(k) + " (t = " +
                  std::to_string(data.time(static_cast<int>(k))) + " s): the model diverges on these inputs" +
                  unstable_poles_note(model);
      break;
    }
  }
  return s;
}

namespace {
// The linear models as one transfer function per input, for their responses; FSF and nonlinear models have none.
std::vector<TransferFunction> input_channels(const AnyModel& model) {
  if (const auto* g = std::get_if<TransferFunction>(&model)) return {*g};
  if (const auto* m = std::get_if<MisoModel>(&model)) return m->channels;
  if (const auto* ss = std::get_if<StateSpace>(&model)) {
    CTID_REQUIRE(ss->ny() == 1, "responses: a state-space model with {} outputs (one output so far)", ss->ny());
    std::vector<TransferFunction> out;
    for (int i = 0; i < ss->nu(); ++i) out.push_back(ss->to_transfer_function(0, i));
    return out;
  }
  return {};
}

void require_times(const Eigen::VectorXd& t) {
  CTID_REQUIRE(t.size() > 0 && t.allFinite() && t(0) >= 0, "responses: the times must be finite and >= 0");
  for (Eigen::Index k = 1; k < t.size(); ++k)
    CTID_REQUIRE(t(k) > t(k - 1), "responses: the times must increase (t[{}] = {} after {})", k, t(k), t(k - 1));
}

const FsfModel* unwindowed_fsf(const AnyModel& model) {
  const auto* f = std::get_if<FsfModel>(&model);
  if (f) require_unwindowed(*f, "responses");
  return f;
}

void refuse_nonlinear(const AnyModel& model, const char* what) {
  CTID_REQUIRE(is_linear(model), "responses: a {} model has no {} (a nonlinear model's response depends on the "
               "input; use its step response or simulate(), and the GFRFs for the frequency domain)",
               model_type_name(model), what);
}
}  // namespace

Eigen::MatrixXd model_step_response(const AnyModel& model, const Eigen::VectorXd& t, double amplitude) {
  require_times(t);
  CTID_REQUIRE(std::isfinite(amplitude), "responses: the step amplitude must be finite (got {})", amplitude);
  if (const FsfModel* f = unwindowed_fsf(model)) return amplitude * f->step_response(t);
  const std::vector<TransferFunction> ch = input_channels(model);
  if (!ch.empty()) {
    Eigen::MatrixXd out(t.size(), static_cast<Eigen::Index>(ch.size()));
    for (std::size_t i = 0; i < ch.size(); ++i) out.col(static_cast<Eigen::Index>(i)) = amplitude * step_response(ch[i], t);
    return out;
  }
  // NARX / NDE: simulated from rest under the step on the model's own input(s), one input at a time.
  if (const auto* n = std::get_if<NarxModel>(&model))
    for (Eigen::Index k = 0; k < t.size(); ++k)
      CTID_REQUIRE(std::abs(t(k) - static_cast<double>(k) * n->ts()) <= 1e-6 * n->ts(),
                   "responses: a NARX model steps on its own grid: t must be consecutive samples k Ts from 0 (Ts = {} s; "
                   "t[{}] = {} s)",
                   n->ts(), k, t(k));
  const int nu = model_inputs(model);
  Eigen::MatrixXd out(t.size(), nu);
  for (int i = 0; i < nu; ++i) {
    Eigen::MatrixXd u = Eigen::MatrixXd::Zero(t.size(), nu);
    u.col(i).setConstant(amplitude);
    const IdData d = IdData::from_times(u, Eigen::MatrixXd::Zero(t.size(), 1), t);
    const Simulation s = simulate(model, d);
    CTID_REQUIRE(s.ok(), "responses: the step response {}", s.problem);
    out.col(i) = s.y.col(0);
  }
  return out;
}

Eigen::MatrixXd model_impulse_response(const AnyModel& model, const Eigen::VectorXd& t) {
  require_times(t);
  refuse_nonlinear(model, "impulse response");
  if (const FsfModel* f = unwindowed_fsf(model)) return f->impulse_response(t);
  const std::vector<TransferFunction> ch = input_channels(model);
  Eigen::MatrixXd out(t.size(), static_cast<Eigen::Index>(ch.size()));
  for (std::size_t i = 0; i < ch.size(); ++i) out.col(static_cast<Eigen::Index>(i)) = impulse_response(ch[i], t);
  return out;
}

Eigen::MatrixXcd model_frequency_response(const AnyModel& model, const Eigen::VectorXd& w) {
  CTID_REQUIRE(w.allFinite(), "responses: the frequencies must be finite");
  refuse_nonlinear(model, "frequency response");
  if (const FsfModel* f = unwindowed_fsf(model)) return f->frequency_response(w);
  const std::vector<TransferFunction> ch = input_channels(model);
  Eigen::MatrixXcd out(w.size(), static_cast<Eigen::Index>(ch.size()));
  for (std::size_t i = 0; i < ch.size(); ++i) out.col(static_cast<Eigen::Index>(i)) = ch[i].frequency_response(w);
  return out;
}

}  // namespace ctid
