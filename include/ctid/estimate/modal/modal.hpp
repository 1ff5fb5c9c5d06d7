// ctid — El-Shafey (1987), "Linear Continuous-time System Identification and State Observer Design by Modal
// Analysis" (PhD thesis):
// estimation of modal parameters and what is derived from them (labels of docs/methods/el-shafey.md):
//   ES-C3  discrete samples, least squares and instrumental variables (ES 3.1-3.10, 3.19-3.20)
//   ES-C4  Fourier modulating functions with the c_{j-1} recursion (ES 3.11-3.30; Omega of ES 3.25)
//   ES-C5  Walsh (block-pulse) functions with the edge recursion (ES 3.18, 3.31-3.37)
//   ES-C8  a and b by Theorems 4.1 and 4.2 (ES 4.15-4.31)
//   ES-C9  poles from a free-response data matrix, Newton's identities (ES 4.37-4.63, index fix of
//          ES 4.50), augmentation and deflation for generated inputs; Prony's method as the baseline.
//   ES-C10 frequency response at the harmonics of a periodic input (ES 5.1-5.14)
//   ES-C11 step response from piecewise-constant inputs with extrapolation (ES 5.15-5.37)
//   ES-C12 impulse response from the step response with negative shifts (ES 5.38-5.42)
// Prefiltered pairs (ES-C6) use signal/modal_filter.hpp; the output-modal-function route (ES-C7) and
// the stacked theorems are in model/modal.hpp; the observer (ES-C13, C14) in estimate/modal/modal_observer.hpp.
//
// Data are uniformly sampled (Ts); the record starts at rest unless the validity windows exclude its
// start; samples before the record count as zero. Times are seconds from the first sample.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "ctid/core/types.hpp"
#include "ctid/data/frequency_data.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/options.hpp"
#include "ctid/model/modal.hpp"
#include "ctid/model/transfer_function.hpp"
#include "ctid/signal/modal_filter.hpp"

namespace ctid {

/// A time interval [start, start + length] (seconds from the first sample) in which the modal-function
/// relation holds: the input is one free response of its generator since at least T_n before start.
struct ModalWindow {
  double start = 0.0;
  double length = 0.0;
};

/// Validity windows of a piecewise-constant input (ES-C11 "constant-input windows"): from `settle`
/// seconds (>= T_n) after each level switch (t = 0 counts as a switch) to the sample before the next
/// switch; windows shorter than min_length are dropped. Throws InvalidArgument for a multi-input record.
std::vector<ModalWindow> piecewise_constant_windows(const IdData& data, double settle, double min_length = 0.0);

enum class ModalBasis {
  Discrete,  ///< the equations at sample instants (ES-C3); only j = 0
  Fourier,   ///< Fourier modulating functions on each window (ES-C4)
  Walsh      ///< Walsh / block-pulse functions on each window (ES-C5)
};

struct ModalOptions {
  /// T_1 < ... < T_n (seconds, > 0, multiples of Ts); n = system order. Empty in modal_fit: uniform shifts chosen
  /// for `order` (choose_modal_shifts on a pre-estimate of that order; see modal_fit).
  Eigen::VectorXd shifts;
  int order = 0;                     ///< system order n when shifts is empty (0 with shifts given, or their count)
  /// none: automatic — Walsh for a piecewise-constant input in modal_fit (the thesis' choice for step inputs),
  /// Fourier otherwise.
  std::optional<ModalBasis> basis;
  int max_order = 0;                 ///< estimate p_j, q_j for j = 0..max_order (> 0 needs Fourier or Walsh)
  std::vector<ModalWindow> windows;  ///< empty: one window from T_n to the end of the record
  /// Fourier: 2m functions (even, >= 2) on the concatenation of the windows (local time runs on from one
  /// window to the next; j > 0 needs a single window). Walsh: N = 2^k functions (blocks) on each window.
  /// 0: automatic (6 Fourier, 8 Walsh functions).
  int functions = 0;
  Quadrature quadrature = Quadrature::Simpson;  ///< Fourier/Walsh integrals; Trapezoid reproduces the thesis
  int stride = 1;                    ///< Discrete: every stride-th sample of each window is an equation
  double iv_shift = 0.0;             ///< Discrete: > 0 uses instruments y(t - T_i + iv_shift) (ES 3.19-3.20)
  /// modal_fit: input delay (s, >= 0, a whole multiple of Ts): the fit runs on the input delayed by it (zero
  /// before the record) and the model carries it as its io_delay. modal_estimate refuses a delay.
  double delay = 0.0;
  /// Throws InvalidOptions naming the field (shifts not increasing or not > 0, functions, stride, ...).
  void validate() const;
  /// The automatic choices made: basis (Walsh when piecewise_constant, else Fourier) and functions (6 or 8).
  ModalOptions resolved(bool piecewise_constant) const;
};
template <>
const OptionTable<ModalOptions>& option_table<ModalOptions>();

/// Shifts given in samples (the setting shift_samples=S1,..,Sn of modal, poles and modal_response) in seconds,
/// S_i Ts. Throws InvalidOptions naming `method` when an S_i is not a whole number of samples (0..1e9), or when
/// shifts in seconds were given as well (`given` not empty).
Eigen::VectorXd shifts_from_samples(const std::string& method, const std::vector<double>& samples, double ts,
                                    const Eigen::VectorXd& given);

/// Modal parameters p_j and modal-function coefficients q_j (j = 0..max_order) from one record.
/// input_basis: N x n_c samples of the input generator basis x_c(t) (InputGenerator::basis at the
/// sample times, or u itself for a piecewise-constant input treated window by window; 0 columns for a
/// free response). Parameters are named p<j>_<i> and q<j>_<k>; their covariance is that of each
/// regression given the previous order's estimates. fit.mse is the mean squared j = 0 equation error.
/// Throws InvalidArgument for shifts or windows off the sample grid, windows outside the record,
/// too few equations, a Walsh block shorter than one sample.
Result<ModalModel> modal_estimate(const IdData& data, const Eigen::MatrixXd& input_basis, const ModalOptions& options);
/// Same with the basis of a known input generator evaluated at the sample times.
Result<ModalModel> modal_estimate(const IdData& data, const InputGenerator& input, const ModalOptions& options);

/// Transfer function by Theorems 4.1 and 4.2 (ES-C8): p_0..p_n and q_0..q_n estimated with
/// options.max_order = n (set automatically), then a = -P^{-T} p_n and b from the q's. The input must
/// have at least n modes. fit compares the model's exact response to the generated input (from rest)
/// with the measured output.
Result<TransferFunction> modal_transfer_function(const IdData& data, const InputGenerator& input,
                                                 ModalOptions options);

/// One-call parametric identification by modal functions for the two input types of the thesis.
///  * input given (a generated input, e.g. sinusoids): p_0..p_n and q_0..q_n on options.windows
///    (default: [T_n, end]) and Theorems 4.1 and 4.2 (ES-C8); needs >= n input modes and nb == n.
///  * input == nullptr (a piecewise-constant input): validity windows from every level switch
///    (piecewise_constant_windows, settle T_n; trimmed to whole Walsh blocks, or the longest one for
///    Fourier) unless options.windows is set; the input itself is the
///    basis (one constant mode per window). a by Theorem 4.1 when options.max_order >= n (Walsh
///    across windows, or Fourier on one window); with the Discrete basis and uniform shifts
///    T_i = i T, the poles are s_k = ln(z_k)/T from z^n + p_01 z^{n-1} + .. + p_0n = 0 (ES-C1 scalar form).
///    The numerator (nb coefficients b_0..b_{nb-1}) is linear once A(s) is known: least squares of the
///    output on the exact responses of s^j/A(s) to the held input, from rest.
/// Shifts left empty (options.order = n): T_i = i d with the spacing d (a multiple of Ts) that minimises cond(psi)
/// of a pre-estimate of order n (SRIVC, or LSSVF when SRIVC is not usable) — choose_modal_shifts — with T_n at
/// most half the median level duration of a piecewise-constant input (a quarter of the record for a generated
/// one), so that windows remain after every switch; stated in diagnostics.choices.
/// fit compares the model's simulated output with the data. Throws InvalidArgument as modal_estimate,
/// or when nb is outside [1, n], or the shifts are not uniform for the Discrete piecewise route.
Result<TransferFunction> modal_fit(const IdData& data, int nb, ModalOptions options,
                                  const InputGenerator* input = nullptr);
/// Several records (experiments of one system, one sampling period, each starting at rest) with piecewise-constant
/// inputs, fitted jointly: the modal equations of every record's validity windows are pooled (Walsh and Discrete:
/// all windows; Fourier: the longest window of all records), the numerator's least squares stacks the records, and
/// fit is the simulation fit over all records (diagnostics "experiments"). options.windows must be empty for more
/// than one record (each record's windows come from its level switches); a generated input (input != nullptr) takes
/// one record. Throws InvalidArgument as the one-record form.
Result<TransferFunction> modal_fit(const std::vector<IdData>& data, int nb, ModalOptions options,
                                  const InputGenerator* input = nullptr);

/// The generator of the given angular frequencies (rad/s; 0 = a constant level, w > 0 = a sinusoid pair) whose
/// coefficients are fitted to the measured input of `data` by least squares — the input model of modal_fit for a
/// recorded sum of sinusoids. Throws InvalidArgument for a negative or non-finite frequency, or data without one
/// input.
InputGenerator generator_fitted_to_input(const std::vector<double>& frequencies, const IdData& data);

/// Characteristic polynomial det(sI - M) by Newton's identities with T_k = trace(M^k) (ES 4.50 with
/// the index fix of ES 4.37-4.63): a_{n-1} = -T_1, a_{n-k} = -(a_{n-k+1} T_1 + ... + a_{n-1} T_{k-1} + T_k)/k.
Polynomial newton_characteristic_polynomial(const Eigen::MatrixXd& M);

struct FreeResponseOptions {
  Eigen::VectorXd shifts;   ///< T_1..T_n' (seconds, distinct, multiples of Ts); n' = order (+ generator order)
  double start = 0.0;       ///< t_o1 (seconds); t_o1 - T_i must lie in the record
  double interval = 0.0;    ///< t_fk - t_ok (seconds, > 0, multiple of Ts)
  double spacing = 0.0;     ///< t_o(k+1) - t_ok (seconds, > 0, multiple of Ts)
  int pairs = 0;            ///< N >= n' instant pairs
  Quadrature quadrature = Quadrature::Simpson;
  /// Characteristic polynomial of a known input generator (forced response, ES 4.56-4.62): the
  /// estimate of order n' is deflated by it. Default 1: a free response.
  Polynomial generator{1.0};
  void validate() const;
};

/// Poles estimated from data; the polynomial coefficients are descending and monic.
struct PoleEstimate {
  Eigen::VectorXcd poles;        ///< of the system (after deflation), s-plane
  Polynomial characteristic;     ///< of the system (after deflation)
  Eigen::VectorXcd all_poles;    ///< before deflation (Theorem 4.3: system and generator)
  Polynomial augmented;          ///< before deflation
  Eigen::MatrixXd lambda;        ///< Theorem 4.3's Lambda = psi A psi^{-1} (data-matrix method); empty for Prony
  double condition = 0.0;        ///< Z Z^T (data matrix) or R^T R (Prony), 2-norm
  std::vector<std::string> warnings;
};

/// Theorem 4.3 (ES-C9): Y_N = [y(t_fk - T_i) - y(t_ok - T_i)], Z_N = [int_{t_ok}^{t_fk} y(t - T_i) dt],
/// Lambda = Y Z^T (Z Z^T)^{-1}, poles = eig(Lambda), polynomial by Newton's identities, then deflation
/// of the generator polynomial by least squares on the coefficients. y: the free (or generated-input)
/// response sampled at Ts. Throws InvalidArgument for instants outside the record or off the grid,
/// pairs < n', or a generator polynomial of degree >= n'.
PoleEstimate free_response_poles(const Eigen::VectorXd& y, double Ts, const FreeResponseOptions& options);

struct PronyOptions {
  int order = 0;     ///< number of exponentials
  int spacing = 1;   ///< sample spacing T = spacing * Ts of the Prony samples
  int equations = 0; ///< N >= order
  int start = 0;     ///< first sample index used
};

/// Prony's method (ES Ex. 4.8, reconstructed): y(m) + sum_k p_k y(m - k) = 0 on samples spaced T,
/// least squares, poles s = ln(z)/T of z^order + p_1 z^{order-1} + ... . Reports cond(R^T R) and a
/// warning that imaginary parts are only known modulo 2 pi / T (aliasing band (-pi/T, pi/T]).
PoleEstimate prony(const Eigen::VectorXd& y, double Ts, const PronyOptions& options);

/// Settings of compare_poles (the `ctid poles` command), in seconds; 0 means "chosen from the record".
struct PolesOptions {
  /// T_1..T_n' (s, distinct whole multiples of Ts): one per pole of the system and of the generator. Empty: T_i = i d,
  /// d the spacing of least cond(psi) (choose_modal_shifts) for Prony's pre-estimate of order n' (its sample spacing
  /// the best conditioned), T_n' at most half the time the response stays above 5 % of its peak.
  Eigen::VectorXd shifts;
  double start = 0.0;          ///< t_o1 (s); 0: the largest shift
  double interval = 0.0;       ///< t_fk - t_ok (s); 0: the first shift, at least 2 Ts
  double spacing = 0.0;        ///< t_o(k+1) - t_ok (s); 0: the interval
  int pairs = 0;               ///< instant pairs; 0: as many as the record holds
  Quadrature quadrature = Quadrature::Simpson;
  /// Frequencies (rad/s; 0 = a constant) of a known generated input forcing the response: the augmented estimate
  /// is deflated by their modes (ES 4.56-4.62). Empty: a free response.
  Eigen::VectorXd generator;
  double prony_spacing = 0.0;  ///< spacing of Prony's samples (s, a multiple of Ts); 0: the first shift
  int prony_equations = 0;     ///< Prony's equations; 0: as many as the record holds
  double prony_start = 0.0;    ///< time of Prony's first sample (s)
  void validate() const;
};
/// The settings of PolesOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<PolesOptions>& option_table<PolesOptions>();

/// The two pole estimates of one response, with the settings they used (defaults resolved).
struct PolesComparison {
  PoleEstimate data_matrix;           ///< Theorem 4.3 (deflated by the generator)
  std::optional<PoleEstimate> prony;  ///< Prony of the augmented order; empty when the record cannot hold it
  std::string prony_problem;          ///< why Prony was not computed ("" when it was)
  FreeResponseOptions free_response;  ///< the data-matrix settings used
  PronyOptions prony_options;         ///< Prony's settings used
  std::vector<std::string> choices;   ///< automatic choices (the shifts when left empty), one sentence each
};

/// El-Shafey's data-matrix poles (free_response_poles) of a free or generator-forced response y (uniform, Ts s)
/// next to Prony's (prony) at the augmented order `order` + the generator's modes — the comparison of ES Ex. 4.8,
/// with every instant (the shifts too) chosen from the record unless given. Throws InvalidOptions when the count of
/// the shifts is not order + generator modes, InvalidArgument when the record cannot hold the instants or is zero.
PolesComparison compare_poles(const Eigen::VectorXd& y, double Ts, int order, const PolesOptions& options);

// ---- Nonparametric responses (ES-C10 .. ES-C12) ----------------------------------------------

/// A response estimated on a time grid (seconds) — the same quantities FsfModel::step_response /
/// impulse_response give at chosen times.
struct TimeResponse {
  Eigen::VectorXd t;
  Eigen::VectorXd value;
};

/// Frequency response at the harmonics of a periodic input, with the correlations it came from.
struct HarmonicResponse {
  FrequencyData response;  ///< w = k w_o, G = H(j k w_o)
  Eigen::MatrixXd nu;      ///< rows k: [int sin(k w_o tau) u_0, int cos(k w_o tau) u_0] (un-normalised, ES 5.1 ff.)
  Eigen::MatrixXd q;       ///< rows k: the same correlations of y_0
};

/// ES-C10 (ES 5.1-5.14): frequency response at harmonics k of a periodic input of period `period`,
/// from (u_0, y_0) = (u, y) filtered with the output modal parameters p_0 of `model` (transients
/// annihilated, so one period starting at window_start >= T_n suffices; unstable systems too).
/// [Re H, Im H] = q^T [[nu_1, nu_2], [-nu_2, nu_1]]^{-1}. u_0 is integrated exactly when the input is
/// held (Zoh data: square waves), otherwise with `rule`; y_0 with `rule`. Throws InvalidArgument when
/// the window leaves the record or is off the sample grid, or a harmonic is < 1 or not excited (nu = 0).
HarmonicResponse modal_frequency_response(const IdData& data, const ModalModel& model, double period,
                                          const std::vector<int>& harmonics, double window_start,
                                          Quadrature rule = Quadrature::Simpson);

/// Delta L of ES 5.27-5.29 ((n+1) x (n+1), unit lower triangular): Delta lower bidiagonal (1 on the
/// diagonal, -1 below), L lower-triangular Toeplitz with first column [1, p_01 .. p_0n]; with shifts
/// T_i = i T, y_0(kT + s) = [u(k) .. u(k-n)] Delta L [g(s) .. g(s + nT)]^T.
Eigen::MatrixXd modal_delta_l(const Eigen::RowVectorXd& p0);

/// ES-C11 (ES 5.15-5.37): step response g on [0, horizon] from a piecewise-constant input whose levels
/// change only at multiples of `level_period` T, given output modal parameters p_0 for the shifts
/// T_i = i T (from modal_estimate on the constant-input windows). For every offset s in [0, T):
/// y_0(kT + s) = u(k)^T Delta L g(s), u(k) = [u(k) .. u(k-n)], solved by least squares over all periods
/// k >= n, then extrapolated with g(s + (n+k)T) = q_00 - sum_i p_0i g(s + (n+k-i)T). The initial state
/// need not be zero. Throws InvalidArgument for shifts that are not i T, a level period off the sample
/// grid, an input that changes inside a period, or too few distinct level sequences.
TimeResponse modal_step_response(const IdData& data, const ModalModel& model, double level_period, double horizon);

/// ES-C12 (ES 5.38-5.42): impulse response from a step response g (uniform grid from t = 0) with
/// negative shifts: h(t) = q_10 - sum_i p_1i g(t - T_i). p_1 and g(T_o) by Fourier functions (2m =
/// functions) on [0, T_o]; q_10 by ES 5.42.
struct ImpulseFromStep {
  TimeResponse impulse;   ///< h on [0, end of g - max |T_i|]
  Eigen::VectorXd p1;     ///< estimated p_1 for the given shifts
  double q10 = 0.0;       ///< the constant output-derivative modal function of the step
  double g_To = 0.0;      ///< the estimated g(T_o)
};
/// Throws InvalidArgument for non-negative shifts or shifts off the grid, T_o off the grid or beyond
/// the step response, fewer functions than n + 1, or a non-uniform grid.
ImpulseFromStep modal_impulse_from_step(const TimeResponse& step, const Eigen::VectorXd& negative_shifts, double To,
                                        int functions = 6, Quadrature rule = Quadrature::Simpson);

/// Which response modal_response estimates.
enum class ResponseKind { Step, Impulse, Frequency };

/// Settings of modal_response (the `ctid response --method modal` command) besides ModalOptions, in seconds.
struct ModalResponseOptions {
  /// Step/impulse: the level period T of the piecewise-constant input (levels change only at multiples of it);
  /// frequency: the period of the periodic input. Required (> 0).
  double period = 0.0;
  double horizon = 0.0;        ///< step/impulse: length of the response (s); 0: 10 period (order + 1)
  Eigen::VectorXd harmonics;   ///< frequency: the harmonics k (whole numbers >= 1) of 2 pi / period; empty: 1,3,5,7,9
  double window_start = -1.0;  ///< frequency: start of the one-period window (s); -1: T_n (the largest shift)
  void validate() const;
};
/// The settings of ModalResponseOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<ModalResponseOptions>& option_table<ModalResponseOptions>();

/// A nonparametric response and what it came from.
struct ModalResponse {
  ResponseKind kind = ResponseKind::Step;
  TimeResponse time;            ///< step or impulse response (kind Step/Impulse)
  HarmonicResponse frequency;   ///< frequency response at the harmonics (kind Frequency)
  Result<ModalModel> p0;        ///< the output modal parameters p_0 from the constant-input windows
  ModalOptions modal;           ///< the modal settings used (defaults resolved: shifts, windows, basis)
};

/// El-Shafey ch. 5 as one call — the `ctid response --method modal` workflow: p_0 from the windows where the
/// piecewise-constant input is constant (modal_estimate, max_order 0, basis Discrete unless set), then the step
/// response (ES-C11), the impulse response from it (ES-C12; negative shifts -T_i, Fourier functions on the first
/// half of the horizon) or the frequency response at the harmonics (ES-C10). Shifts default to i period
/// (step/impulse) or i Ts round(period / ((order + 1) Ts)) (frequency). Throws InvalidOptions for bad settings or
/// a shift count other than `order`, InvalidArgument when the input never stays constant long enough.
ModalResponse modal_response(const IdData& data, int order, ResponseKind kind, const ModalResponseOptions& options,
                             const ModalOptions& modal = {});

}  // namespace ctid
