// GFRFs of polynomial NARX models (Billings & Li 1999, eqs 11-14, corrected recursion).
// See include/ctid/estimate/nonlinear/gfrf.hpp.
#include "ctid/estimate/nonlinear/gfrf.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "ctid/core/check.hpp"

namespace ctid {

namespace {
struct Term {
  double c;
  std::vector<int> ky, ku;  // output lags (k_1..k_p), input lags (k_{p+1}..k_{p+q})
};

class Kernels {
 public:
  explicit Kernels(const NarxModel& m) {
    for (size_t i = 0; i < m.terms().size(); ++i) {
      const NarxTerm& t = m.terms()[i];
      if (t.has_noise() || t.factors.empty()) continue;
      Term x{m.coefficients()(static_cast<Eigen::Index>(i)), {}, {}};
      for (const auto& f : t.factors) (f.signal == NarxSignal::Output ? x.ky : x.ku).push_back(f.lag);
      terms_.push_back(x);
    }
  }

  // Asymmetric H_n(z_0 .. z_{n-1}).
  Complex H(const Complex* z, int n) const {
    Complex prod = 1.0;
    for (int i = 0; i < n; ++i) prod *= z[i];
    Complex den = 1.0, num = 0.0;
    for (const auto& t : terms_) {
      const int p = static_cast<int>(t.ky.size()), q = static_cast<int>(t.ku.size());
      if (p == 1 && q == 0) {
        den -= t.c * std::pow(prod, -t.ky[0]);
      } else if (p == 0 && q == n) {
        Complex v = t.c;
        for (int i = 0; i < n; ++i) v *= std::pow(z[i], -t.ku[i]);
        num += v;
      } else if (p >= 1 && q >= 1 && p + q <= n) {
        // input factors on the last q arguments, H_{n-q,p} on the first n - q.
        Complex v = t.c;
        for (int j = 0; j < q; ++j) v *= std::pow(z[n - q + j], -t.ku[j]);
        num += v * Hnp(z, n - q, p, t.ky);
      } else if (p >= 2 && q == 0 && p <= n) {
        num += t.c * Hnp(z, n, p, t.ky);
      }
    }
    return num / den;
  }

 private:
  // H_{n,p}(z_0..z_{n-1}; k_1..k_p).
  Complex Hnp(const Complex* z, int n, int p, const std::vector<int>& k) const {
    if (p == 1) {
      Complex prod = 1.0;
      for (int i = 0; i < n; ++i) prod *= z[i];
      return H(z, n) * std::pow(prod, -k[0]);
    }
    Complex s = 0.0, prod = 1.0;
    for (int i = 1; i <= n - p + 1; ++i) {
      prod *= z[i - 1];
      s += H(z, i) * Hnp(z + i, n - i, p - 1, k) * std::pow(prod, -k[p - 1]);
    }
    return s;
  }

  std::vector<Term> terms_;
};

void check_points(const std::vector<Complex>& z, const char* who) {
  CTID_REQUIRE(!z.empty(), "{}: needs at least one frequency argument", who);
  CTID_REQUIRE(z.size() <= 8, "{}: order {} is beyond what the recursion is meant for (<= 8)", who, z.size());
  for (size_t i = 0; i < z.size(); ++i)
    CTID_REQUIRE(std::isfinite(z[i].real()) && std::isfinite(z[i].imag()), "{}: argument {} is not finite", who, i + 1);
}
}  // namespace

Complex narx_gfrf_asymmetric(const NarxModel& model, const std::vector<Complex>& z) {
  check_points(z, "narx_gfrf");
  for (size_t i = 0; i < z.size(); ++i) CTID_REQUIRE(std::abs(z[i]) > 0, "narx_gfrf: z_{} = 0", i + 1);
  return Kernels(model).H(z.data(), static_cast<int>(z.size()));
}

Complex narx_gfrf(const NarxModel& model, const std::vector<Complex>& z) {
  check_points(z, "narx_gfrf");
  for (size_t i = 0; i < z.size(); ++i) CTID_REQUIRE(std::abs(z[i]) > 0, "narx_gfrf: z_{} = 0", i + 1);
  const Kernels k(model);
  std::vector<int> idx(z.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::vector<Complex> w(z.size());
  Complex s = 0.0;
  int count = 0;
  do {
    for (size_t i = 0; i < idx.size(); ++i) w[i] = z[idx[i]];
    s += k.H(w.data(), static_cast<int>(w.size()));
    ++count;
  } while (std::next_permutation(idx.begin(), idx.end()));
  return s / static_cast<double>(count);
}

Complex zoh_factor(Complex s, double T) {
  const Complex x = s * T;
  if (std::abs(x) < 1e-4) return 1.0 - x / 2.0 + x * x / 6.0;
  return (1.0 - std::exp(-x)) / x;
}

Complex narx_gfrf_ct(const NarxModel& model, const std::vector<Complex>& s, bool zoh) {
  check_points(s, "narx_gfrf_ct");
  std::vector<Complex> z(s.size());
  Complex hold = 1.0;
  for (size_t i = 0; i < s.size(); ++i) {
    z[i] = std::exp(s[i] * model.ts());
    if (zoh) hold *= zoh_factor(s[i], model.ts());
  }
  return narx_gfrf(model, z) / hold;
}

}  // namespace ctid
