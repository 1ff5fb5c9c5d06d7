// ctid — continuous-time state space  dx/dt = A x + B u,  y = C x + D u, optionally with an innovation gain K (the
// innovation form dx/dt = A x + B u + K e, y = C x + D u + e; see predict() in simulate/lsim.hpp).
#pragma once

#include <complex>
#include <vector>

#include <Eigen/Dense>

#include "ctid/model/transfer_function.hpp"

namespace ctid {

/// One mode of a state-space model: a real pole or a complex pair (listed once, the pole with imag > 0).
struct Mode {
  std::complex<double> pole;  ///< 1/s
  double wn = 0.0;            ///< natural frequency |pole| (rad/s)
  double zeta = 0.0;          ///< damping ratio -Re(pole)/|pole| (1 for a real stable pole, negative when unstable)
  /// Mode shape: the output direction C v of the pole's eigenvector v (ny entries), scaled to unit 2-norm with its
  /// largest entry real and positive — independent of the state coordinates.
  Eigen::VectorXcd shape;
};

class StateSpace {
 public:
  StateSpace() = default;
  /// Throws InvalidArgument for inconsistent sizes or non-finite entries.
  StateSpace(Eigen::MatrixXd A, Eigen::MatrixXd B, Eigen::MatrixXd C, Eigen::MatrixXd D);
  /// With an innovation gain K (nx x ny; empty: none). Throws InvalidArgument for a K of another size.
  StateSpace(Eigen::MatrixXd A, Eigen::MatrixXd B, Eigen::MatrixXd C, Eigen::MatrixXd D, Eigen::MatrixXd K);

  /// Controllable canonical (companion) form of a proper SISO transfer function:
  /// A first row = -[a1 .. an], sub-diagonal ones, B = e1, C = remainder numerator, D = direct term.
  static StateSpace controllable_canonical(const TransferFunction& tf);
  /// Observable canonical form: the transpose (dual) of the controllable form.
  static StateSpace observable_canonical(const TransferFunction& tf);

  const Eigen::MatrixXd& A() const { return A_; }
  const Eigen::MatrixXd& B() const { return B_; }
  const Eigen::MatrixXd& C() const { return C_; }
  const Eigen::MatrixXd& D() const { return D_; }
  /// The innovation gain (nx x ny), empty for an output-error model. It enters only predictions (predict()), never
  /// a simulation, a response or the poles.
  const Eigen::MatrixXd& K() const { return K_; }
  bool has_innovation_gain() const { return K_.size() > 0; }
  int nx() const { return static_cast<int>(A_.rows()); }
  int nu() const { return static_cast<int>(B_.cols()); }
  int ny() const { return static_cast<int>(C_.rows()); }

  Eigen::VectorXcd poles() const;
  /// The modes in order of increasing natural frequency (see Mode).
  std::vector<Mode> modes() const;
  bool is_stable() const;
  /// Transfer function from input `in` to output `out` (0-based), by
  /// C (sI-A)^{-1} B = [det(sI - A + B C) - det(sI - A)] / det(sI - A).
  TransferFunction to_transfer_function(int out = 0, int in = 0) const;
  /// G(j w) for one (out, in) pair at each w (rad/s).
  Eigen::VectorXcd frequency_response(const Eigen::VectorXd& w, int out = 0, int in = 0) const;

 private:
  Eigen::MatrixXd A_, B_, C_, D_, K_;
};

}  // namespace ctid
