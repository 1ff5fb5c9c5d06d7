// ctid — exact simulation of linear continuous-time models (docs/architecture.md, "Numerics").
//
// Between two sample times the input is either held (ZOH) or linear (FOH; BandLimited
// inputs are treated as FOH). Over an interval of length h the state moves exactly:
//   x(t+h) = Phi x(t) + Gamma0 u(t+) + Gamma1 (u((t+h)-) - u(t+)),
// where Phi, Gamma0 and h*Gamma1 are the blocks of exp([[A, B, 0], [0, 0, I], [0, 0, 0]] h)
// (Gamma1 = 0 for ZOH). Irregular sample times get a per-interval exponential; an input
// delay splits intervals where the delayed input changes, so delays need not be a
// multiple of the sampling period. The input is taken as zero before the first sample
// (the system at rest with x0 unless x0 is given).
#pragma once

#include <complex>
#include <vector>

#include <Eigen/Dense>

#include "ctid/data/iddata.hpp"
#include "ctid/model/miso.hpp"
#include "ctid/model/modal.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

/// Exact discretisation of (A, B) over one interval of length h (see file comment).
struct Discretization {
  Eigen::MatrixXd Phi, Gamma0, Gamma1;
  double h = 0.0;
};
/// Throws InvalidArgument for h <= 0 or non-finite.
Discretization discretize(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, double h);

/// Matrix exponential exp(M) (Pade with scaling and squaring).
Eigen::MatrixXd expm(const Eigen::MatrixXd& M);

struct LsimOptions {
  Eigen::VectorXd x0;         ///< initial state (empty: zero)
  double input_delay = 0.0;   ///< seconds, applied to every input (>= 0)
};

/// Simulate y (N x ny) for inputs u (N x nu) at times t (strictly increasing) with the
/// intersample behaviour of each input. Throws InvalidArgument for size mismatches.
Eigen::MatrixXd lsim(const StateSpace& sys, const Eigen::MatrixXd& u, const Eigen::VectorXd& t,
                     const std::vector<Intersample>& intersample, const LsimOptions& options = {});
/// The same into y, a caller's buffer: resized to N x ny only when its shape differs, so that a workspace reused over
/// the iterations of a fit is written in place (no allocation, no page faults); u is read in place (any column-major
/// block or map of N x nu).
void lsim_into(const StateSpace& sys, const Eigen::Ref<const Eigen::MatrixXd>& u, const Eigen::VectorXd& t,
               const std::vector<Intersample>& intersample, const LsimOptions& options, Eigen::MatrixXd& y);
/// Same on an experiment: uses its inputs, times and intersample behaviour.
Eigen::MatrixXd lsim(const StateSpace& sys, const IdData& data, const LsimOptions& options = {});
/// One-step-ahead predictions (N x ny) of a model with an innovation gain: the innovation form
/// dx/dt = A x + B u + K e(t), y = C x + D u + e, with the innovation held between samples at e_k = y_k - yhat_k,
/// yhat_k = C x_k + D u_k, x(t_0) = options.x0 (empty: zero) — exact for ZOH/FOH inputs on any sample times, and the
/// predictor ssest's prediction-error variant minimises. Without K: the simulation (lsim). Throws InvalidArgument
/// for mismatched sizes or an input delay (not supported here).
Eigen::MatrixXd predict(const StateSpace& sys, const IdData& data, const LsimOptions& options = {});
/// Simulate a SISO transfer function (with its delay) driven by input column `input`.
Eigen::VectorXd lsim(const TransferFunction& tf, const IdData& data, int input = 0);
/// The same into y (data.size() entries), e.g. a buffer reused over the iterations of a fit.
void lsim_into(const TransferFunction& tf, const IdData& data, int input, Eigen::Ref<Eigen::VectorXd> y);
/// Simulate a SISO transfer function on (u, t) with the given intersample behaviour.
Eigen::VectorXd lsim(const TransferFunction& tf, const Eigen::VectorXd& u, const Eigen::VectorXd& t,
                     Intersample intersample = Intersample::Zoh);
/// The same into y (u.size() entries, e.g. a numpy array's memory), u and t read in place; nothing is allocated
/// that grows with the record.
void lsim_into(const TransferFunction& tf, const Eigen::Ref<const Eigen::VectorXd>& u,
               const Eigen::Ref<const Eigen::VectorXd>& t, Intersample intersample, Eigen::Ref<Eigen::VectorXd> y);

/// The same on uniform samples t_k = k ts, k = 0..N-1 (ts in seconds, > 0 and finite; throws InvalidArgument
/// otherwise): equal to passing time_grid(ts, N), without reading (or checking) N sample times.
void lsim_into(const TransferFunction& tf, const Eigen::Ref<const Eigen::VectorXd>& u, double ts, Intersample is,
               Eigen::Ref<Eigen::VectorXd> y);
/// Simulate a MISO model: the sum of its channels, channel i driven by input column i.
/// Throws InvalidArgument when the data do not have one input per channel.
Eigen::VectorXd lsim(const MisoModel& model, const IdData& data);

/// Exact response of a SISO model to a generated input u = c^T x_c(t) (El-Shafey's input generator):
/// the matrix exponential of the system augmented with the generator, [x; x_c]' =
/// [[A, B c^T], [0, A_c]] [x; x_c], x_c(0) = input.x0(), x(0) = x0 (empty: zero). t increasing, >= 0.
Eigen::VectorXd lsim(const StateSpace& sys, const InputGenerator& input, const Eigen::VectorXd& t,
                     const Eigen::VectorXd& x0 = {});

/// Unit-step response at the times t (t >= 0, increasing): step applied at t = 0.
Eigen::VectorXd step_response(const TransferFunction& tf, const Eigen::VectorXd& t);
/// Impulse response g(t) = C e^{A (t - Td)} B for t >= Td, 0 before; a direct term
/// (Dirac at Td) is not representable on samples and is left out.
Eigen::VectorXd impulse_response(const TransferFunction& tf, const Eigen::VectorXd& t);
/// MIMO step responses: element i is the response of every output (N x ny) to a unit step on input i at
/// t = 0, from rest, at the times t (t >= 0, increasing): C int_0^t e^{A s} ds B e_i + D e_i, each time by the block
/// exponential of [[A, B], [0, 0]] t (exact). Throws InvalidArgument for bad times.
std::vector<Eigen::MatrixXd> step_response(const StateSpace& sys, const Eigen::VectorXd& t);
/// MIMO impulse responses: element i is C e^{A t} B e_i (N x ny) at the times t (t >= 0); the direct term D (a Dirac
/// at 0) is not representable on samples and is left out.
std::vector<Eigen::MatrixXd> impulse_response(const StateSpace& sys, const Eigen::VectorXd& t);
/// The frequency-response matrix G(j w_k) = C (j w_k I - A)^-1 B + D (ny x nu) at each w (rad/s).
std::vector<Eigen::MatrixXcd> frequency_response(const StateSpace& sys, const Eigen::VectorXd& w);

/// n equally spaced times 0, h, ..., (n-1) h.
Eigen::VectorXd time_grid(double h, int n);

}  // namespace ctid
