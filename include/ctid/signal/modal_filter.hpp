// ctid — modal filtering of sampled signals and the quadrature rules used by the modal-function
// estimators. El-Shafey (1987): modal functions (ES 2.26-2.45) and annihilating
// prefilters L u(t) = u(t) + sum_i l_i u(t - T_Li) with l = -c_c^T psi_c^{-1} (ES 3.38-3.47, ES-C6).
#pragma once

#include <Eigen/Dense>

#include "ctid/data/iddata.hpp"
#include "ctid/model/modal.hpp"

namespace ctid {

/// Quadrature over uniformly sampled signals. Simpson: composite Simpson, with the 3/8 rule on the
/// last three intervals when the interval count is odd (exact for cubics; error O(h^4)).
/// Trapezoid: O(h^2). Exact integration of piecewise-constant (ZOH) signals is offered where the
/// integrand structure allows it (see estimate/modal/modal.hpp).
enum class Quadrature { Simpson, Trapezoid };

/// Weights w (size intervals + 1) with integral over [0, intervals * h] of g ~ sum_i w_i g(i h).
/// Throws InvalidArgument for intervals < 1 or h <= 0.
Eigen::VectorXd quadrature_weights(int intervals, double h, Quadrature rule = Quadrature::Simpson);

/// Integer sample lags of shifts given in seconds; throws InvalidArgument naming the shift when one is
/// not a whole multiple of Ts (relative tolerance 1e-9). Negative shifts give negative lags.
Eigen::VectorXi shift_lags(const Eigen::VectorXd& shifts, double Ts);

/// Modal filter y_0(i) = lead * y(i) + sum_k weights_k y(i - lag_k) on a uniformly sampled signal
/// (lags from shift_lags; samples outside the record count as zero, i.e. the system at rest before
/// the record; the caller keeps to validity windows). Throws InvalidArgument for size mismatches.
Eigen::VectorXd modal_filter(const Eigen::VectorXd& y, double Ts, const Eigen::VectorXd& shifts,
                             const Eigen::VectorXd& weights, double lead = 1.0);

/// The same filter applied to every input and output column of a uniformly sampled record (the
/// filtered pair satisfies the same differential equation, ES 3.47). Throws InvalidArgument for
/// non-uniform data.
IdData modal_filter(const IdData& data, const Eigen::VectorXd& shifts, const Eigen::VectorXd& weights,
                    double lead = 1.0);

/// The generated input after the filter: same basis, c' = lead c + sum_k weights_k e^{-A^T T_k} c
/// (annihilated modes get c' = 0 up to round-off; pass the generator of the modes to keep).
InputGenerator modal_filter(const InputGenerator& input, const Eigen::VectorXd& shifts, const Eigen::VectorXd& weights,
                            double lead = 1.0);

/// Annihilating prefilter for the modes of a generator (ES-C6): l = -c^T psi_c^{-1} with psi_c rows
/// c^T e^{-A T_Li}; one shift per generator state. L applied to any free response of that generator
/// is zero after max(shifts). Throws InvalidArgument when psi_c is singular (shifts alias the modes).
Eigen::VectorXd annihilator(const InputGenerator& modes, const Eigen::VectorXd& shifts);

}  // namespace ctid
