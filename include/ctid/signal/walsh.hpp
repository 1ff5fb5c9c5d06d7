// ctid — Walsh functions and the fast Walsh-Hadamard transform, used by the Walsh-function
// modal-parameter estimator of El-Shafey (1987) (ES 3.18, 3.31-3.37).
#pragma once

#include <Eigen/Dense>

namespace ctid {

/// Walsh matrix of size N = 2^m in sequency order: row k is the k-th Walsh function (k sign
/// changes) sampled on N equal blocks; entries +-1, Psi Psi^T = N I. Throws InvalidArgument unless N
/// is a power of two >= 1.
Eigen::MatrixXd walsh_matrix(int N);

/// Psi * X for the sequency-ordered Walsh matrix, by the fast Walsh-Hadamard transform
/// (O(N log N) per column). X has N = 2^m rows. Throws InvalidArgument otherwise.
Eigen::MatrixXd walsh_transform(const Eigen::MatrixXd& X);

}  // namespace ctid
