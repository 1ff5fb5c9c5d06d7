#include "ctid/simulate/lsim.hpp"

#include <cmath>
#include <complex>
#include <vector>

#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/MatrixFunctions>

#include "ctid/core/check.hpp"

namespace ctid {

Eigen::MatrixXd expm(const Eigen::MatrixXd& M) {
  CTID_REQUIRE(M.rows() == M.cols(), "expm: the matrix must be square (got {}x{})", M.rows(), M.cols());
  CTID_REQUIRE(M.allFinite(), "expm: the matrix contains NaN or Inf");
  if (M.rows() == 0) return M;
  return M.exp();
}

Discretization discretize(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, double h) {
  CTID_REQUIRE(std::isfinite(h) && h > 0, "discretize: the interval must be positive and finite (got {})", h);
  const Eigen::Index n = A.rows(), m = B.cols();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 2 * m, n + 2 * m);
  M.topLeftCorner(n, n) = A * h;
  M.block(0, n, n, m) = B * h;
  // Unscaled identity: the exponential is exp(h [[A, B, 0], [0, 0, I/h], [0, 0, 0]]).
  M.block(n, n + m, m, m) = Eigen::MatrixXd::Identity(m, m);
  const Eigen::MatrixXd E = expm(M);
  Discretization d;
  d.h = h;
  d.Phi = E.topLeftCorner(n, n);
  d.Gamma0 = E.block(0, n, n, m);
  // E13 = int_0^h e^{A(h-s)} B (s/h) ds: the response to a unit change of slope over the interval.
  d.Gamma1 = E.block(0, n + m, n, m);
  return d;
}

namespace {

// A few discretisations keyed by interval length (uniform data need one, a
// non-integer delay two, irregular data one per interval).
class DiscretizationCache {
 public:
  DiscretizationCache(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const std::vector<Intersample>& is)
      : A_(A), B_(B), foh_(is.size()) {
    for (std::size_t j = 0; j < is.size(); ++j) foh_[j] = is[j] != Intersample::Zoh;
  }
  const Discretization& get(double h) {
    for (const auto& d : entries_)
      if (std::abs(d.h - h) <= 1e-13 * h) return d;
    if (entries_.size() >= 8) entries_.erase(entries_.begin());
    Discretization d = discretize(A_, B_, h);
    for (std::size_t j = 0; j < foh_.size(); ++j)
      if (!foh_[j]) d.Gamma1.col(j).setZero();
    entries_.push_back(std::move(d));
    return entries_.back();
  }

 private:
  const Eigen::MatrixXd& A_;
  const Eigen::MatrixXd& B_;
  std::vector<bool> foh_;
  std::vector<Discretization> entries_;
};

// Sample times: explicit, or t0 + k h without materialising them.
struct TimeAxis {
  const double* t = nullptr;
  double t0 = 0, h = 0;
  Eigen::Index n = 0;
  double operator()(Eigen::Index k) const { return t ? t[k] : t0 + double(k) * h; }
  Eigen::Index size() const { return n; }
};

// Delayed input v(s) = u(s - delay). Piece j covers [t_j + delay, t_{j+1} + delay):
// held at u_j (ZOH) or linear from u_j to u_{j+1} (FOH); zero before piece 0.
struct DelayedInput {
  const Eigen::Ref<const Eigen::MatrixXd>& u;
  const TimeAxis& t;
  const std::vector<Intersample>& is;
  double delay;
  Eigen::Index size() const { return t.size(); }
  double start(Eigen::Index j) const { return t(j) + delay; }
  void value(Eigen::Index j, double s, Eigen::VectorXd& out) const {
    for (Eigen::Index c = 0; c < u.cols(); ++c) {
      if (j < 0) { out(c) = 0.0; continue; }
      if (is[c] == Intersample::Zoh || j + 1 >= t.size()) { out(c) = u(j, c); continue; }
      const double a = (s - delay - t(j)) / (t(j + 1) - t(j));
      out(c) = u(j, c) + a * (u(j + 1, c) - u(j, c));
    }
  }
};

}  // namespace

namespace {
// The one-sample recursions below are bound by their state-to-state dependency chain, which leaves the hardware
// prefetcher too little lead on records that come from main memory: without this, 1e7 samples cost 35 % more per
// sample than 1e6 (bench_per_sample, lsim-data: 4.5 against 3.3 ns), with it the same. Once per cache line of the
// input's first column and the output's first column, 256 samples (2 kB) ahead.
inline void prefetch_ahead(const Eigen::Ref<const Eigen::MatrixXd>& u, Eigen::Ref<Eigen::MatrixXd>& y, Eigen::Index k) {
  constexpr Eigen::Index kAhead = 256;
  if ((k & 7) == 0 && k + kAhead < u.rows()) {
    __builtin_prefetch(u.data() + k + kAhead, 0, 0);
    __builtin_prefetch(y.data() + k + kAhead, 1, 0);
  }
}

// Uniform, delay-free single-input simulation with a compile-time state dimension
// (row-major Phi and C, column vectors G0, G1, D): the hot loop of fit reports and of the
// filtered-derivative banks of the refined IV and output-error estimators.
template <int n>
void simo_fixed(const double* Phi_rm, const double* g0, const double* g1, const double* c_rm, const double* dvec,
                const double* x0, const Eigen::Ref<const Eigen::MatrixXd>& u, Eigen::Ref<Eigen::MatrixXd> y) {
  double P[n * n], G0[n], G1[n], x[n];
  for (int i = 0; i < n * n; ++i) P[i] = Phi_rm[i];
  for (int i = 0; i < n; ++i) { G0[i] = g0[i]; G1[i] = g1[i]; x[i] = x0[i]; }
  const Eigen::Index N = u.rows();
  const Eigen::Index ny = y.cols();
  for (Eigen::Index k = 0; k < N; ++k) {
    const double uk = u(k, 0);
    prefetch_ahead(u, y, k);
    for (Eigen::Index j = 0; j < ny; ++j) {
      const double* cj = c_rm + j * n;
      double yk = dvec[j] * uk;
      for (int i = 0; i < n; ++i) yk += cj[i] * x[i];
      y(k, j) = yk;
    }
    if (k + 1 == N) break;
    const double du = u(k + 1, 0) - uk;
    double xn[n];
    for (int i = 0; i < n; ++i) {
      double acc = G0[i] * uk + G1[i] * du;
      for (int l = 0; l < n; ++l) acc += P[i * n + l] * x[l];
      xn[i] = acc;
    }
    for (int i = 0; i < n; ++i) x[i] = xn[i];
  }
}

// The single-input system in a real modal form of 2 x 2 blocks, so that a step costs O(n) instead of O(n^2)
// (Phi x for a dense Phi): z = T^-1 D^-1 x with D the radix-2 balancing of A and T its eigenvectors (real and
// imaginary parts of a complex pair; two real modes share a block; an odd n gets a silent padding state). Each block
// is discretised exactly (discretize() of the block-diagonal A). Built only when T is well conditioned (cond <= 1e5
// and A T = T M to 1e-12) and no mode is unstable: repeated or clustered poles keep the dense form.
struct ModalBlocks {
  int m = 0;                                  // blocks
  std::vector<double> phi, g0, g1, c, d, z0;  // phi: 4 per block (row-major 2 x 2); c: ny x 2m row-major
};

// Radix-2 diagonal balancing (Parlett-Reinsch): returns d with D^-1 A D balanced (rows and columns of like norms).
Eigen::VectorXd balancing(Eigen::MatrixXd A) {
  const Eigen::Index n = A.rows();
  Eigen::VectorXd d = Eigen::VectorXd::Ones(n);
  for (bool done = false; !done;) {
    done = true;
    for (Eigen::Index i = 0; i < n; ++i) {
      double c = 0, r = 0;
      for (Eigen::Index j = 0; j < n; ++j)
        if (j != i) {
          c += std::abs(A(j, i));
          r += std::abs(A(i, j));
        }
      if (c == 0 || r == 0) continue;
      const double s = c + r;
      double f = 1, g = r / 2;
      while (c < g) { f *= 2; c *= 4; }
      g = r * 2;
      while (c > g) { f /= 2; c /= 4; }
      if ((c + r / f) / f < 0.95 * s) {  // (c and r as scaled by f)
        done = false;
        d(i) *= f;
        A.row(i) /= f;
        A.col(i) *= f;
      }
    }
  }
  return d;
}

bool modal_blocks(const StateSpace& sys, double h, bool foh, const std::vector<double>& x0, ModalBlocks& mb) {
  const Eigen::Index n = sys.nx();
  const Eigen::VectorXd dbal = balancing(sys.A());
  const Eigen::MatrixXd Ab = dbal.cwiseInverse().asDiagonal() * sys.A() * dbal.asDiagonal();
  Eigen::EigenSolver<Eigen::MatrixXd> es(Ab);
  if (es.info() != Eigen::Success) return false;
  const Eigen::VectorXcd lam = es.eigenvalues();
  // Unstable modes grow until they overflow; in modal coordinates two of them can overflow with opposite signs
  // before the output does (inf - inf): unstable models keep the dense form, which fails no earlier than the output.
  if (lam.real().maxCoeff() > 0) return false;
  const Eigen::MatrixXcd V = es.eigenvectors();
  const Eigen::Index n2 = n + (n % 2);
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(n, n), M = Eigen::MatrixXd::Zero(n2, n2);  // M's padding block: zero
  std::vector<Eigen::Index> reals;
  Eigen::Index j = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::complex<double> l = lam(i);
    if (l.imag() == 0.0) {
      reals.push_back(i);
    } else if (l.imag() > 0) {
      if (j + 1 >= n) return false;
      T.col(j) = V.col(i).real();
      T.col(j + 1) = V.col(i).imag();
      M(j, j) = M(j + 1, j + 1) = l.real();
      M(j, j + 1) = l.imag();
      M(j + 1, j) = -l.imag();
      j += 2;
    }
  }
  for (Eigen::Index i : reals) {
    if (j >= n) return false;
    T.col(j) = V.col(i).real();
    M(j, j) = lam(i).real();
    ++j;
  }
  if (j != n) return false;
  // (An odd n's padding state has no column in T and a zero block in M: z = 0 for ever, no input, no output.)
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(T);
  const Eigen::VectorXd sv = svd.singularValues();
  if (!(sv(n - 1) > 0) || sv(0) / sv(n - 1) > 1e5) return false;
  if ((Ab * T - T * M.topLeftCorner(n, n)).norm() > 1e-12 * Ab.norm() * T.norm()) return false;
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(T);
  Eigen::MatrixXd Bm = Eigen::MatrixXd::Zero(n2, 1), Cm = Eigen::MatrixXd::Zero(sys.ny(), n2);
  Bm.topRows(n) = lu.solve(dbal.cwiseInverse().asDiagonal() * sys.B());
  Cm.leftCols(n) = sys.C() * dbal.asDiagonal() * T;
  Eigen::VectorXd z0 = Eigen::VectorXd::Zero(n2);
  z0.head(n) = lu.solve(dbal.cwiseInverse().cwiseProduct(Eigen::Map<const Eigen::VectorXd>(x0.data(), n)));
  const Discretization dz = discretize(M, Bm, h);
  mb.m = static_cast<int>(n2 / 2);
  mb.phi.resize(static_cast<std::size_t>(4 * mb.m));
  for (int b = 0; b < mb.m; ++b)
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 2; ++c) mb.phi[static_cast<std::size_t>(4 * b + 2 * r + c)] = dz.Phi(2 * b + r, 2 * b + c);
  mb.g0.assign(dz.Gamma0.data(), dz.Gamma0.data() + n2);
  if (foh) mb.g1.assign(dz.Gamma1.data(), dz.Gamma1.data() + n2);
  else mb.g1.assign(n2, 0.0);
  mb.c.resize(static_cast<std::size_t>(Cm.size()));
  for (Eigen::Index r = 0; r < Cm.rows(); ++r)
    for (Eigen::Index i = 0; i < n2; ++i) mb.c[static_cast<std::size_t>(r * n2 + i)] = Cm(r, i);
  mb.d.assign(sys.D().data(), sys.D().data() + sys.ny());
  mb.z0.assign(z0.data(), z0.data() + n2);
  return true;
}

// The step of ModalBlocks with m blocks known at compile time: per block z <- P z + G0 u (+ G1 du), 2 x 2.
template <int m, bool foh>
void modal_fixed(const ModalBlocks& f, const Eigen::Ref<const Eigen::MatrixXd>& u, Eigen::Ref<Eigen::MatrixXd> y) {
  constexpr int n = 2 * m;
  double P[4 * m], G0[n], G1[n], z[n];
  for (int i = 0; i < 4 * m; ++i) P[i] = f.phi[static_cast<std::size_t>(i)];
  for (int i = 0; i < n; ++i) {
    G0[i] = f.g0[static_cast<std::size_t>(i)];
    G1[i] = f.g1[static_cast<std::size_t>(i)];
    z[i] = f.z0[static_cast<std::size_t>(i)];
  }
  const double* c = f.c.data();
  const double* d = f.d.data();
  const Eigen::Index N = u.rows(), ny = y.cols();
  for (Eigen::Index k = 0; k < N; ++k) {
    const double uk = u(k, 0);
    prefetch_ahead(u, y, k);
    for (Eigen::Index j = 0; j < ny; ++j) {
      double yk = d[j] * uk;
      for (int i = 0; i < n; ++i) yk += c[j * n + i] * z[i];
      y(k, j) = yk;
    }
    if (k + 1 == N) break;
    const double du = foh ? u(k + 1, 0) - uk : 0.0;
    for (int b = 0; b < m; ++b) {
      const double p = z[2 * b], q = z[2 * b + 1];
      double i0 = G0[2 * b] * uk, i1 = G0[2 * b + 1] * uk;
      if constexpr (foh) {
        i0 += G1[2 * b] * du;
        i1 += G1[2 * b + 1] * du;
      }
      z[2 * b] = (P[4 * b] * p + P[4 * b + 1] * q) + i0;
      z[2 * b + 1] = (P[4 * b + 2] * p + P[4 * b + 3] * q) + i1;
    }
  }
}

template <int m>
void modal_run(const ModalBlocks& f, bool foh, const Eigen::Ref<const Eigen::MatrixXd>& u, Eigen::Ref<Eigen::MatrixXd> y) {
  if (foh) modal_fixed<m, true>(f, u, y);
  else modal_fixed<m, false>(f, u, y);
}

// Simulate into y (N x ny, sized by the caller).
void lsim_core(const StateSpace& sys, const Eigen::Ref<const Eigen::MatrixXd>& u, const TimeAxis& t, bool uniform,
               double h, const std::vector<Intersample>& intersample, const LsimOptions& o, Eigen::Ref<Eigen::MatrixXd> y) {
  const Eigen::Index N = t.size();
  CTID_REQUIRE(N >= 1, "lsim: at least one sample time is needed");
  CTID_REQUIRE(u.rows() == N, "lsim: u has {} samples but there are {} sample times", u.rows(), N);
  CTID_REQUIRE(u.cols() == sys.nu(), "lsim: the model has {} inputs but u has {} columns", sys.nu(), u.cols());
  CTID_REQUIRE(static_cast<int>(intersample.size()) == sys.nu(), "lsim: {} intersample entries for {} inputs",
               intersample.size(), sys.nu());
  CTID_REQUIRE(std::isfinite(o.input_delay) && o.input_delay >= 0, "lsim: the input delay must be >= 0 (got {})", o.input_delay);
  const int n = sys.nx();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  if (o.x0.size() > 0) {
    CTID_REQUIRE(o.x0.size() == n, "lsim: x0 has {} entries but the model has {} states", o.x0.size(), n);
    x = o.x0;
  }
  const int ny = sys.ny(), nu = sys.nu();
  CTID_ASSERT(y.rows() == N && y.cols() == ny);
  DiscretizationCache cache(sys.A(), sys.B(), intersample);
  DelayedInput v{u, t, intersample, o.input_delay};
  // Row-major copies of C and D and plain work arrays: the per-sample loops below do
  // no allocation and no dynamic-size expression evaluation.
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> C = sys.C(), D = sys.D();
  std::vector<double> xv(x.data(), x.data() + n), xn(n), va(nu), vb(nu);
  auto output = [&](Eigen::Index k, const double* in) {
    for (int j = 0; j < ny; ++j) {
      double acc = 0;
      for (int i = 0; i < n; ++i) acc += C(j, i) * xv[i];
      for (int c = 0; c < nu; ++c) acc += D(j, c) * in[c];
      y(k, j) = acc;
    }
  };
  // x <- Phi x + Gamma0 a + Gamma1 (b - a), with Phi etc. row-major in `rm`.
  struct RowMajor {
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Phi, G0, G1;
    double h = -1;
  } rm;
  auto load = [&](const Discretization& d) {
    if (d.h == rm.h) return;
    rm.Phi = d.Phi;
    rm.G0 = d.Gamma0;
    rm.G1 = d.Gamma1;
    rm.h = d.h;
  };
  auto advance = [&](const double* a, const double* b) {
    for (int i = 0; i < n; ++i) {
      double acc = 0;
      for (int l = 0; l < n; ++l) acc += rm.Phi(i, l) * xv[l];
      for (int c = 0; c < nu; ++c) acc += rm.G0(i, c) * a[c] + rm.G1(i, c) * (b[c] - a[c]);
      xn[i] = acc;
    }
    xv.swap(xn);
  };

  if (o.input_delay == 0.0 && uniform && N >= 2 && nu == 1 && n >= 4 && n <= 8) {  // orders 1-3: the dense step is as cheap
    ModalBlocks mb;
    const bool foh = intersample[0] != Intersample::Zoh;
    if (modal_blocks(sys, h, foh, xv, mb)) {
      switch (mb.m) {
        case 2: modal_run<2>(mb, foh, u, y); break;
        case 3: modal_run<3>(mb, foh, u, y); break;
        default: modal_run<4>(mb, foh, u, y); break;
      }
      return;
    }
  }
  if (o.input_delay == 0.0 && uniform && N >= 2 && nu == 1 && n >= 1 && n <= 8) {
    load(cache.get(h));
    const double* a[] = {rm.Phi.data(), rm.G0.data(), rm.G1.data(), C.data(), D.data()};
    switch (n) {
      case 1: simo_fixed<1>(a[0], a[1], a[2], a[3], a[4], xv.data(), u, y); break;
      case 2: simo_fixed<2>(a[0], a[1], a[2], a[3], a[4], xv.data(), u, y); break;
      case 3: simo_fixed<3>(a[0], a[1], a[2], a[3], a[4], xv.data(), u, y); break;
      case 4: simo_fixed<4>(a[0], a[1], a[2], a[3], a[4], xv.data(), u, y); break;
      case 5: simo_fixed<5>(a[0], a[1], a[2], a[3], a[4], xv.data(), u, y); break;
      case 6: simo_fixed<6>(a[0], a[1], a[2], a[3], a[4], xv.data(), u, y); break;
      case 7: simo_fixed<7>(a[0], a[1], a[2], a[3], a[4], xv.data(), u, y); break;
      default: simo_fixed<8>(a[0], a[1], a[2], a[3], a[4], xv.data(), u, y); break;
    }
    return;
  }
  if (o.input_delay == 0.0 && uniform && N >= 2) {
    // Fast path: one discretisation, no delay.
    load(cache.get(h));
    for (Eigen::Index k = 0; k < N; ++k) {
      for (int c = 0; c < nu; ++c) va[c] = u(k, c);
      output(k, va.data());
      if (k + 1 == N) break;
      for (int c = 0; c < nu; ++c) vb[c] = u(k + 1, c);
      advance(va.data(), vb.data());
    }
    return;
  }

  // General path: split each interval where the delayed input changes piece.
  Eigen::VectorXd ea(nu), eb(nu);
  const Eigen::Index M = v.size();
  Eigen::Index j = -1;
  const double snap0 = 1e-10 * std::max(h, 1e-300);
  while (j + 1 < M && v.start(j + 1) <= t(0) + snap0) ++j;
  for (Eigen::Index k = 0; k < N; ++k) {
    v.value(j, t(k), ea);
    output(k, ea.data());
    if (k + 1 == N) break;
    const double snap = 1e-10 * (t(k + 1) - t(k));
    double a = t(k);
    while (a < t(k + 1)) {
      double b = t(k + 1);
      if (j + 1 < M && v.start(j + 1) < b - snap) b = v.start(j + 1);
      v.value(j, a, ea);
      v.value(j, b, eb);
      load(cache.get(b - a));
      advance(ea.data(), eb.data());
      a = b;
      while (j + 1 < M && v.start(j + 1) <= a + snap) ++j;
    }
  }
}

// The time axis of uniformly sampled data, without materialising the times.
TimeAxis axis_of(const IdData& d) { return TimeAxis{nullptr, d.t0(), d.ts(), d.size()}; }

// A SISO transfer function (its delay included) on input u into y.
void lsim_tf_core(const TransferFunction& tf, const Eigen::Ref<const Eigen::VectorXd>& u, const TimeAxis& axis,
                  bool uniform, double h, Intersample is, Eigen::Ref<Eigen::VectorXd> y) {
  LsimOptions o;
  o.input_delay = tf.io_delay();
  const Eigen::Map<const Eigen::MatrixXd> um(u.data(), u.size(), 1);
  Eigen::Map<Eigen::MatrixXd> ym(y.data(), y.size(), 1);
  lsim_core(tf.to_state_space(), um, axis, uniform, h, {is}, o, ym);
}
}  // namespace

namespace {
// The checked time axis of explicit sample times (uniform: their common interval in h).
TimeAxis explicit_axis(const Eigen::Ref<const Eigen::VectorXd>& t, bool* uniform, double* h) {
  // One pass that counts (so that it vectorises): intervals that are not positive, and intervals further than 1e-9
  // of the mean one from it (uniform when none). The first bad interval is looked up only to name it.
  const Eigen::Index n = t.size();
  const double* p = t.data();
  *h = n < 2 ? 1.0 : (p[n - 1] - p[0]) / double(n - 1);
  const double mean = *h, tol = 1e-9 * *h;
  Eigen::Index bad = 0, uneven = 0;
  for (Eigen::Index k = 1; k < n; ++k) {
    const double dk = p[k] - p[k - 1];
    bad += !(dk > 0);
    uneven += !(std::abs(dk - mean) <= tol);
  }
  if (bad > 0)
    for (Eigen::Index k = 1; k < n; ++k)
      CTID_REQUIRE(p[k] > p[k - 1], "lsim: sample times must be strictly increasing (t[{}] = {} after {})", k, p[k],
                   p[k - 1]);
  *uniform = uneven == 0;
  return TimeAxis{p, 0.0, 0.0, n};
}
}  // namespace

void lsim_into(const StateSpace& sys, const Eigen::Ref<const Eigen::MatrixXd>& u, const Eigen::VectorXd& t,
               const std::vector<Intersample>& intersample, const LsimOptions& o, Eigen::MatrixXd& y) {
  bool uniform = false;
  double h = 0;
  const TimeAxis axis = explicit_axis(t, &uniform, &h);
  if (y.rows() != t.size() || y.cols() != sys.ny()) y.resize(t.size(), sys.ny());
  lsim_core(sys, u, axis, uniform, h, intersample, o, y);
}

Eigen::MatrixXd lsim(const StateSpace& sys, const Eigen::MatrixXd& u, const Eigen::VectorXd& t,
                     const std::vector<Intersample>& intersample, const LsimOptions& o) {
  Eigen::MatrixXd y;
  lsim_into(sys, u, t, intersample, o, y);
  return y;
}

Eigen::MatrixXd lsim(const StateSpace& sys, const IdData& data, const LsimOptions& o) {
  std::vector<Intersample> is(data.nu());
  for (int j = 0; j < data.nu(); ++j) is[j] = data.intersample(j);
  if (!data.is_uniform()) return lsim(sys, data.u(), data.times(), is, o);
  Eigen::MatrixXd y(data.size(), sys.ny());
  lsim_core(sys, data.u(), axis_of(data), true, data.ts(), is, o, y);
  return y;
}

Eigen::MatrixXd predict(const StateSpace& sys, const IdData& data, const LsimOptions& o) {
  if (!sys.has_innovation_gain()) return lsim(sys, data, o);
  const Eigen::Index nx = sys.nx(), nu = sys.nu(), ny = sys.ny(), N = data.size();
  CTID_REQUIRE(data.nu() == nu && data.ny() == ny, "predict: the model has {} inputs and {} outputs, the data {} and {}",
               nu, ny, data.nu(), data.ny());
  CTID_REQUIRE(o.input_delay == 0.0, "predict: an input delay is not supported (got {} s)", o.input_delay);
  CTID_REQUIRE(o.x0.size() == 0 || o.x0.size() == nx, "predict: x0 has {} entries, the model {} states", o.x0.size(), nx);
  // The inputs [u; e]: u with the data's intersample behaviour, the innovation held.
  Eigen::MatrixXd BK(nx, nu + ny);
  BK << sys.B(), sys.K();
  bool any_foh = false;
  for (int j = 0; j < nu; ++j) any_foh = any_foh || data.intersample(j) != Intersample::Zoh;
  Discretization dz;
  Eigen::MatrixXd y(N, ny);
  Eigen::VectorXd x = o.x0.size() ? o.x0 : Eigen::VectorXd::Zero(nx), e(ny);
  const Eigen::VectorXd t = data.times();
  for (Eigen::Index k = 0; k < N; ++k) {
    const Eigen::VectorXd uk = data.u().row(k).transpose();
    y.row(k) = (sys.C() * x + sys.D() * uk).transpose();
    if (k + 1 == N) break;
    e = data.y().row(k).transpose() - y.row(k).transpose();
    const double h = t(k + 1) - t(k);
    if (!(std::abs(dz.h - h) <= 1e-12 * h)) dz = discretize(sys.A(), BK, h);
    Eigen::VectorXd xn = dz.Phi * x + dz.Gamma0.leftCols(nu) * uk + dz.Gamma0.rightCols(ny) * e;
    if (any_foh)
      for (int j = 0; j < nu; ++j)
        if (data.intersample(j) != Intersample::Zoh) xn += dz.Gamma1.col(j) * (data.u()(k + 1, j) - uk(j));
    x = std::move(xn);
  }
  return y;
}

void lsim_into(const TransferFunction& tf, const Eigen::Ref<const Eigen::VectorXd>& u,
               const Eigen::Ref<const Eigen::VectorXd>& t, Intersample is, Eigen::Ref<Eigen::VectorXd> y) {
  CTID_REQUIRE(y.size() == u.size(), "lsim: the output has room for {} samples but the input has {}", y.size(), u.size());
  bool uniform = false;
  double h = 0;
  const TimeAxis axis = explicit_axis(t, &uniform, &h);
  lsim_tf_core(tf, u, axis, uniform, h, is, y);
}

void lsim_into(const TransferFunction& tf, const Eigen::Ref<const Eigen::VectorXd>& u, double ts, Intersample is,
               Eigen::Ref<Eigen::VectorXd> y) {
  CTID_REQUIRE(ts > 0 && std::isfinite(ts), "lsim: the sampling period must be positive and finite (got {})", ts);
  CTID_REQUIRE(y.size() == u.size(), "lsim: the output has room for {} samples but the input has {}", y.size(), u.size());
  lsim_tf_core(tf, u, TimeAxis{nullptr, 0.0, ts, u.size()}, true, ts, is, y);
}

Eigen::VectorXd lsim(const TransferFunction& tf, const Eigen::VectorXd& u, const Eigen::VectorXd& t, Intersample is) {
  Eigen::VectorXd y(u.size());
  lsim_into(tf, u, t, is, y);
  return y;
}

Eigen::VectorXd lsim(const TransferFunction& tf, const IdData& data, int input) {
  Eigen::VectorXd y(data.size());
  lsim_into(tf, data, input, y);
  return y;
}

void lsim_into(const TransferFunction& tf, const IdData& data, int input, Eigen::Ref<Eigen::VectorXd> y) {
  CTID_REQUIRE(input >= 0 && input < data.nu(), "lsim: input index {} out of range (data has {} inputs)", input, data.nu());
  CTID_REQUIRE(y.size() == data.size(), "lsim: the output has room for {} samples but the record has {}", y.size(), data.size());
  if (!data.is_uniform()) return lsim_into(tf, data.u().col(input), data.times(), data.intersample(input), y);
  lsim_tf_core(tf, data.u().col(input), axis_of(data), true, data.ts(), data.intersample(input), y);
}

Eigen::VectorXd lsim(const MisoModel& m, const IdData& data) {
  CTID_REQUIRE(m.nu() == data.nu(), "lsim: the model has {} inputs but the data have {}", m.nu(), data.nu());
  Eigen::VectorXd y = Eigen::VectorXd::Zero(data.size());
  for (int i = 0; i < m.nu(); ++i) y += lsim(m.channels[i], data, i);
  return y;
}

Eigen::VectorXd time_grid(double h, int n) {
  CTID_REQUIRE(h > 0 && std::isfinite(h), "time_grid: step must be positive (got {})", h);
  CTID_REQUIRE(n >= 1, "time_grid: need at least one point (got {})", n);
  return Eigen::VectorXd::LinSpaced(n, 0.0, h * (n - 1));
}

Eigen::VectorXd lsim(const StateSpace& sys, const InputGenerator& input, const Eigen::VectorXd& t,
                     const Eigen::VectorXd& x0) {
  CTID_REQUIRE(sys.nu() == 1 && sys.ny() == 1, "lsim: a generated input needs a SISO model (got {} inputs, {} outputs)",
               sys.nu(), sys.ny());
  CTID_REQUIRE(input.order() >= 1, "lsim: empty input generator");
  CTID_REQUIRE(x0.size() == 0 || x0.size() == sys.nx(), "lsim: x0 has {} entries for {} states", x0.size(), sys.nx());
  const int n = sys.nx(), nc = input.order();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + nc, n + nc);
  M.topLeftCorner(n, n) = sys.A();
  M.topRightCorner(n, nc) = sys.B() * input.c().transpose();
  M.bottomRightCorner(nc, nc) = input.A();
  Eigen::RowVectorXd Ca(n + nc);
  Ca << sys.C().row(0), sys.D()(0, 0) * input.c().transpose();
  Eigen::VectorXd z(n + nc);
  z << (x0.size() ? x0 : Eigen::VectorXd::Zero(n)), input.x0();
  Eigen::VectorXd y(t.size());
  double tp = 0.0, hp = -1.0;
  Eigen::MatrixXd Phi;
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    CTID_REQUIRE(std::isfinite(t(i)) && t(i) >= tp, "lsim: times must be finite, >= 0 and increasing (t[{}] = {})", i,
                 t(i));
    const double h = t(i) - tp;
    if (h > 0) {
      if (std::abs(h - hp) > 1e-12 * std::max(1.0, h)) {  // uniform grids: one exponential
        Phi = expm(M * h);
        hp = h;
      }
      z = Phi * z;
    }
    tp = t(i);
    y(i) = Ca.dot(z);
  }
  return y;
}

Eigen::VectorXd step_response(const TransferFunction& tf, const Eigen::VectorXd& t) {
  CTID_REQUIRE(t.size() >= 1 && t(0) >= 0, "step_response: times must start at t >= 0");
  // Prepend t = 0 so the step is applied at time zero.
  const bool has_zero = t(0) == 0.0;
  Eigen::VectorXd tt(t.size() + (has_zero ? 0 : 1));
  if (has_zero) tt = t;
  else { tt(0) = 0.0; tt.tail(t.size()) = t; }
  const Eigen::VectorXd y = lsim(tf, Eigen::VectorXd::Ones(tt.size()), tt, Intersample::Zoh);
  return has_zero ? y : Eigen::VectorXd(y.tail(t.size()));
}

namespace {
void require_response_times(const Eigen::VectorXd& t, const char* who) {
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    CTID_REQUIRE(std::isfinite(t(k)) && t(k) >= 0.0, "{}: times must be finite and >= 0 (t[{}] = {})", who, k, t(k));
    CTID_REQUIRE(k == 0 || t(k) > t(k - 1), "{}: times must increase (t[{}] = {} after {})", who, k, t(k), t(k - 1));
  }
}
}  // namespace

std::vector<Eigen::MatrixXd> step_response(const StateSpace& sys, const Eigen::VectorXd& t) {
  require_response_times(t, "step_response");
  const Eigen::Index n = sys.nx(), m = sys.nu();
  std::vector<Eigen::MatrixXd> out(static_cast<size_t>(m), Eigen::MatrixXd(t.size(), sys.ny()));
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + m, n + m);
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    M.topLeftCorner(n, n) = sys.A() * t(k);
    M.topRightCorner(n, m) = sys.B() * t(k);
    // Top-right block of the exponential: the states after a unit step of each input held over [0, t].
    const Eigen::MatrixXd X = t(k) > 0 ? Eigen::MatrixXd(expm(M).topRightCorner(n, m)) : Eigen::MatrixXd::Zero(n, m);
    const Eigen::MatrixXd Y = sys.C() * X + sys.D();
    for (Eigen::Index i = 0; i < m; ++i) out[static_cast<size_t>(i)].row(k) = Y.col(i).transpose();
  }
  return out;
}

std::vector<Eigen::MatrixXd> impulse_response(const StateSpace& sys, const Eigen::VectorXd& t) {
  require_response_times(t, "impulse_response");
  std::vector<Eigen::MatrixXd> out(static_cast<size_t>(sys.nu()), Eigen::MatrixXd(t.size(), sys.ny()));
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    const Eigen::MatrixXd Y = sys.C() * expm(sys.A() * t(k)) * sys.B();
    for (Eigen::Index i = 0; i < sys.nu(); ++i) out[static_cast<size_t>(i)].row(k) = Y.col(i).transpose();
  }
  return out;
}

std::vector<Eigen::MatrixXcd> frequency_response(const StateSpace& sys, const Eigen::VectorXd& w) {
  std::vector<Eigen::MatrixXcd> out;
  const Eigen::MatrixXcd A = sys.A().cast<std::complex<double>>(), B = sys.B().cast<std::complex<double>>();
  const Eigen::Index n = sys.nx();
  for (Eigen::Index k = 0; k < w.size(); ++k) {
    CTID_REQUIRE(std::isfinite(w(k)), "frequency_response: w[{}] is not finite", k);
    const Eigen::MatrixXcd R = (std::complex<double>(0, w(k)) * Eigen::MatrixXcd::Identity(n, n) - A).partialPivLu().solve(B);
    out.push_back(sys.C().cast<std::complex<double>>() * R + sys.D().cast<std::complex<double>>());
  }
  return out;
}

Eigen::VectorXd impulse_response(const TransferFunction& tf, const Eigen::VectorXd& t) {
  const StateSpace ss = tf.to_state_space();
  Eigen::VectorXd g = Eigen::VectorXd::Zero(t.size());
  const double td = tf.io_delay();
  Eigen::VectorXd x;
  Eigen::MatrixXd Phi;
  double tx = 0, last_h = -1;
  bool started = false;
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    if (k > 0) CTID_REQUIRE(t(k) > t(k - 1), "impulse_response: times must increase (t[{}] = {})", k, t(k));
    if (t(k) < td) continue;
    if (!started) {
      x = expm(ss.A() * (t(k) - td)) * ss.B().col(0);
      started = true;
    } else {
      const double h = t(k) - tx;
      if (h != last_h) { Phi = expm(ss.A() * h); last_h = h; }
      x = Phi * x;
    }
    tx = t(k);
    g(k) = (ss.C() * x)(0);
  }
  return g;
}

}  // namespace ctid
