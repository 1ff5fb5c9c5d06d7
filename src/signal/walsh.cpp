// Walsh functions and the fast Walsh-Hadamard transform (El-Shafey 1987, ES 3.18, 3.31-3.37).
#include "ctid/signal/walsh.hpp"

#include <bit>
#include <vector>

#include "ctid/core/check.hpp"

namespace ctid {

namespace {
int checked_log2(Eigen::Index N, const char* who) {
  CTID_REQUIRE(N >= 1 && std::has_single_bit(static_cast<unsigned long long>(N)),
               "{}: the number of Walsh functions must be a power of two (got {})", who, N);
  return std::countr_zero(static_cast<unsigned long long>(N));
}
// Natural (Hadamard) row of the sequency-k Walsh function: bit reversal of the Gray code of k.
unsigned hadamard_row(unsigned k, int m) {
  const unsigned g = k ^ (k >> 1);
  unsigned r = 0;
  for (int b = 0; b < m; ++b)
    if (g & (1u << b)) r |= 1u << (m - 1 - b);
  return r;
}
}  // namespace

Eigen::MatrixXd walsh_matrix(int N) {
  const int m = checked_log2(N, "walsh_matrix");
  Eigen::MatrixXd W(N, N);
  for (int k = 0; k < N; ++k) {
    const unsigned h = hadamard_row(static_cast<unsigned>(k), m);
    for (int j = 0; j < N; ++j) W(k, j) = std::popcount(h & static_cast<unsigned>(j)) % 2 ? -1.0 : 1.0;
  }
  return W;
}

Eigen::MatrixXd walsh_transform(const Eigen::MatrixXd& X) {
  const int m = checked_log2(X.rows(), "walsh_transform");
  const Eigen::Index N = X.rows();
  Eigen::MatrixXd H = X;
  for (Eigen::Index len = 1; len < N; len *= 2)
    for (Eigen::Index i = 0; i < N; i += 2 * len)
      for (Eigen::Index j = i; j < i + len; ++j) {
        const Eigen::RowVectorXd a = H.row(j), b = H.row(j + len);
        H.row(j) = a + b;
        H.row(j + len) = a - b;
      }
  Eigen::MatrixXd out(N, X.cols());
  for (Eigen::Index k = 0; k < N; ++k) out.row(k) = H.row(hadamard_row(static_cast<unsigned>(k), m));
  return out;
}

}  // namespace ctid
