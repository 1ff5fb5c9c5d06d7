// State-space estimators' shared scales and fits — see estimate/state_space/state_space_common.hpp.
#include "estimate/state_space/state_space_common.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

#include "ctid/core/check.hpp"
#include "ctid/validate/metrics.hpp"
#include "ctid/validate/uncertainty.hpp"

namespace ctid::ss_detail {

Eigen::VectorXd channel_scales(std::span<const IdData> records, bool outputs) {
  const Eigen::Index n = outputs ? records.front().ny() : records.front().nu();
  Eigen::VectorXd s(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    double sum = 0.0, count = 0.0, squares = 0.0;
    for (const IdData& d : records) {
      sum += (outputs ? d.y() : d.u()).col(j).sum();
      count += static_cast<double>(d.size());
    }
    const double mean = sum / count;
    for (const IdData& d : records) squares += ((outputs ? d.y() : d.u()).col(j).array() - mean).square().sum();
    const double v = std::sqrt(squares / count);
    s(j) = v > 0 && std::isfinite(v) ? v : 1.0;
  }
  return s;
}

Fits fits_of(std::span<const IdData> records, std::span<const Eigen::MatrixXd> yhat, const Eigen::VectorXd& sy,
             int n_parameters) {
  const Eigen::Index ny = records.front().ny();
  Eigen::Index n = 0;
  for (const IdData& d : records) n += d.size();
  Eigen::VectorXd y(n * ny), h(n * ny), yj(n), hj(n);
  Fits f;
  f.per_output.resize(ny);
  for (Eigen::Index j = 0; j < ny; ++j) {
    Eigen::Index at = 0;
    for (size_t e = 0; e < records.size(); ++e) {
      const Eigen::Index m = records[e].size();
      yj.segment(at, m) = records[e].y().col(j);
      hj.segment(at, m) = yhat[e].col(j);
      at += m;
    }
    f.per_output(j) = fit_report_or_inf(yj, hj, n_parameters).fit_percent;
    // Each output about its own mean and scale, so that every output counts alike in the overall fit.
    const double mean = yj.mean();
    y.segment(j * n, n) = (yj.array() - mean) / sy(j);
    h.segment(j * n, n) = (hj.array() - mean) / sy(j);
  }
  f.all = fit_report_or_inf(y, h, n_parameters);
  return f;
}

Eigen::VectorXd pack(const Layout& L, const Point& m) {
  Eigen::VectorXd v(L.size());
  for (int i = 0; i < L.nx; ++i)
    for (int j = 0; j < L.nx; ++j) v(L.a(i, j)) = m.A(i, j);
  for (int i = 0; i < L.nx; ++i)
    for (int j = 0; j < L.nu; ++j) v(L.b(i, j)) = m.B(i, j);
  for (int i = 0; i < L.ny; ++i)
    for (int j = 0; j < L.nx; ++j) v(L.c(i, j)) = m.C(i, j);
  for (int i = 0; i < L.ny; ++i)
    for (int j = 0; j < L.nu; ++j) v(L.d(i, j)) = m.D(i, j);
  for (int i = 0; i < L.nx; ++i)
    for (int j = 0; j < L.nk; ++j) v(L.k(i, j)) = m.K(i, j);
  for (int e = 0; e < L.E; ++e)
    for (int i = 0; i < L.nx; ++i) v(L.x0(e, i)) = m.x0[static_cast<size_t>(e)](i);
  return v;
}

Point unpack(const Layout& L, const Eigen::VectorXd& v) {
  Point m{Eigen::MatrixXd(L.nx, L.nx), Eigen::MatrixXd(L.nx, L.nu), Eigen::MatrixXd(L.ny, L.nx),
          Eigen::MatrixXd(L.ny, L.nu), std::vector<Eigen::VectorXd>(static_cast<size_t>(L.E), Eigen::VectorXd(L.nx)), Eigen::MatrixXd()};
  for (int i = 0; i < L.nx; ++i)
    for (int j = 0; j < L.nx; ++j) m.A(i, j) = v(L.a(i, j));
  for (int i = 0; i < L.nx; ++i)
    for (int j = 0; j < L.nu; ++j) m.B(i, j) = v(L.b(i, j));
  for (int i = 0; i < L.ny; ++i)
    for (int j = 0; j < L.nx; ++j) m.C(i, j) = v(L.c(i, j));
  for (int i = 0; i < L.ny; ++i)
    for (int j = 0; j < L.nu; ++j) m.D(i, j) = v(L.d(i, j));
  if (L.nk > 0) m.K.resize(L.nx, L.nk);
  for (int i = 0; i < L.nx; ++i)
    for (int j = 0; j < L.nk; ++j) m.K(i, j) = v(L.k(i, j));
  for (int e = 0; e < L.E; ++e)
    for (int i = 0; i < L.nx; ++i) m.x0[static_cast<size_t>(e)](i) = v(L.x0(e, i));
  return m;
}


// Data-driven local coordinates: an orthonormal basis of the free entries of (A, B, C, D) orthogonal to the tangent of
// the change-of-basis manifold that keeps the held entries (McKelvey et al. 2004 eq. 10: the tangent at T = I + X
// is (XA - AX, XB, -CX, 0), and XK for an innovation gain), plus each free initial-state entry on its own (no change
// of basis moves (A, B, C, D) and x0 alone, so this removes the same redundancy; a direction of x0 alone needs no sensitivity exponential).
// `similar` receives the dimension of the tangent removed.
Eigen::MatrixXd local_directions(const Layout& L, const Point& m, const std::vector<bool>& held, int* similar) {
  const Eigen::Index n = L.size(), nx = L.nx, nm = L.x0(0, 0);  // nm: the entries of (A, B, C, D)
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(nm, nx * nx);
  for (int i = 0; i < L.nx; ++i)
    for (int j = 0; j < L.nx; ++j) {
      const Eigen::Index col = i * nx + j;  // X = e_i e_j^T
      for (int c = 0; c < L.nx; ++c) M(L.a(i, c), col) += m.A(j, c);    // X A: row i gets A's row j
      for (int r = 0; r < L.nx; ++r) M(L.a(r, j), col) -= m.A(r, i);    // A X: column j gets A's column i
      for (int c = 0; c < L.nu; ++c) M(L.b(i, c), col) += m.B(j, c);    // X B
      for (int r = 0; r < L.ny; ++r) M(L.c(r, j), col) -= m.C(r, i);    // -C X
      for (int c = 0; c < L.nk; ++c) M(L.k(i, c), col) += m.K(j, c);    // X K
    }
  std::vector<Eigen::Index> free_rows, held_rows, free_x0;
  for (Eigen::Index k = 0; k < nm; ++k) (held[static_cast<size_t>(k)] ? held_rows : free_rows).push_back(k);
  for (Eigen::Index k = nm; k < n; ++k)
    if (!held[static_cast<size_t>(k)]) free_x0.push_back(k);
  // Changes of basis that keep every held entry: the null space of the held rows of M.
  Eigen::MatrixXd keep = Eigen::MatrixXd::Identity(nx * nx, nx * nx);
  if (!held_rows.empty()) {
    Eigen::MatrixXd Mh(static_cast<Eigen::Index>(held_rows.size()), nx * nx);
    for (size_t k = 0; k < held_rows.size(); ++k) Mh.row(static_cast<Eigen::Index>(k)) = M.row(held_rows[k]);
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(Mh, Eigen::ComputeFullV);
    const Eigen::VectorXd& s = svd.singularValues();
    const double tol = 1e-10 * std::max(s.size() ? s(0) : 0.0, 1.0);
    Eigen::Index rank = 0;
    while (rank < s.size() && s(rank) > tol) ++rank;
    keep = svd.matrixV().rightCols(nx * nx - rank);
  }
  const Eigen::Index nf = static_cast<Eigen::Index>(free_rows.size());
  Eigen::MatrixXd T(nf, keep.cols());
  const Eigen::MatrixXd MK = M * keep;
  for (Eigen::Index k = 0; k < nf; ++k) T.row(k) = MK.row(free_rows[static_cast<size_t>(k)]);
  Eigen::Index rank = 0;
  Eigen::MatrixXd U = Eigen::MatrixXd::Identity(nf, nf);
  if (T.cols() > 0 && nf > 0) {
    // The complement of T's range: the trailing columns of Q of a rank-revealing QR (an SVD gives the same subspace
    // at many times the cost: it dominated searches of 20 states and more).
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(T);
    qr.setThreshold(1e-10);
    rank = qr.rank();
    U = qr.householderQ();
  }
  if (similar) *similar = static_cast<int>(rank);
  const Eigen::Index nq = nf - rank, nx0 = static_cast<Eigen::Index>(free_x0.size());
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(n, nq + nx0);
  for (Eigen::Index k = 0; k < nf; ++k) Q.row(free_rows[static_cast<size_t>(k)]).head(nq) = U.row(k).tail(nq);
  for (Eigen::Index k = 0; k < nx0; ++k) Q(free_x0[static_cast<size_t>(k)], nq + k) = 1.0;
  return Q;
}

std::vector<Point> directions_of(const Layout& L, const Eigen::MatrixXd& Q) {
  std::vector<Point> dirs;
  for (Eigen::Index d = 0; d < Q.cols(); ++d) dirs.push_back(unpack(L, Q.col(d)));
  return dirs;
}


// A change of state coordinates x = T z applied to a model.
Point transformed(const Point& m, const Eigen::MatrixXd& T) {
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(T);
  Point r{lu.solve(m.A * T), lu.solve(m.B), m.C * T, m.D, {}, m.K.size() ? Eigen::MatrixXd(lu.solve(m.K)) : m.K};
  for (const auto& x : m.x0) r.x0.push_back(lu.solve(x));
  return r;
}

// Input and output scaling of a model: u = su .* u_s, y = sy .* y_s.
Point scaled(const Point& m, const Eigen::VectorXd& su, const Eigen::VectorXd& sy) {
  // The innovation e = y - yhat scales like y: K e = (K diag(sy)) e_s.
  return {m.A, m.B * su.asDiagonal(), sy.cwiseInverse().asDiagonal() * m.C,
          sy.cwiseInverse().asDiagonal() * m.D * su.asDiagonal(), m.x0,
          m.K.size() ? Eigen::MatrixXd(m.K * sy.asDiagonal()) : m.K};
}
Point unscaled(const Point& m, const Eigen::VectorXd& su, const Eigen::VectorXd& sy) {
  return scaled(m, su.cwiseInverse(), sy.cwiseInverse());
}

bool modal_form(const Point& m, int integrators, ModalForm& out) {
  const int nx = static_cast<int>(m.A.rows());
  Eigen::EigenSolver<Eigen::MatrixXd> es(m.A);
  if (es.info() != Eigen::Success) return false;
  const Eigen::VectorXcd lam = es.eigenvalues();
  const Eigen::MatrixXcd V = es.eigenvectors();
  // The integrators' states come first and stay as they are (their columns of A are zero).
  struct Entry {
    double wn;
    int index;
  };
  std::vector<Entry> order;
  for (int i = 0; i < nx; ++i) {
    if (lam(i).imag() < 0) continue;  // a pair is listed once, by its member with imag > 0
    order.push_back({std::abs(lam(i)), i});
  }
  // The integrator poles: the `integrators` real eigenvalues nearest 0 (exactly 0 by construction).
  std::sort(order.begin(), order.end(), [](const Entry& a, const Entry& b) { return a.wn < b.wn; });
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(nx, nx);
  int col = 0;
  out.names.clear();
  out.c_held.clear();
  if (integrators > 0) {
    T.leftCols(integrators) = Eigen::MatrixXd::Identity(nx, integrators);
    col = integrators;
  }
  int skipped = 0;
  for (const Entry& en : order) {
    const std::complex<double> l = lam(en.index);
    if (skipped < integrators && l.imag() == 0.0) {
      ++skipped;
      continue;
    }
    if (l.imag() == 0.0) {
      T.col(col) = V.col(en.index).real();
      out.names.push_back("pole" + std::to_string(col + 1));
      ++col;
    } else {
      if (col + 2 > nx) return false;
      T.col(col) = V.col(en.index).real();
      T.col(col + 1) = V.col(en.index).imag();
      out.names.push_back("sigma" + std::to_string(col + 1));
      out.names.push_back("omega" + std::to_string(col + 1));
      col += 2;
    }
  }
  if (col != nx) return false;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(T);
  const Eigen::VectorXd& sv = svd.singularValues();
  if (!(sv(nx - 1) > 1e-10 * sv(0))) return false;
  Point p = transformed(m, T);
  // Exact block structure, and each mode's scale fixed by the largest entry of its C column(s).
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(nx, nx);
  Eigen::MatrixXd S = Eigen::MatrixXd::Identity(nx, nx);  // the per-mode rescaling
  if (integrators > 0) {
    // Rows of C that make the integrators' block of C the identity.
    const Eigen::MatrixXd Ci = p.C.leftCols(integrators);
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Ci.transpose());
    if (qr.rank() < integrators) return false;
    Eigen::MatrixXd sub(integrators, integrators);
    for (int k = 0; k < integrators; ++k) {
      const int row = static_cast<int>(qr.colsPermutation().indices()(k));
      sub.row(k) = Ci.row(row);
      for (int c = 0; c < integrators; ++c) out.c_held.emplace_back(row, c, c == k ? 1.0 : 0.0);
    }
    S.topLeftCorner(integrators, integrators) = sub.inverse();
  }
  for (int a = integrators; a < nx;) {
    const bool pair = out.names[static_cast<size_t>(a - integrators)].rfind("sigma", 0) == 0;
    Eigen::Index row = 0;
    if (!pair) {
      A(a, a) = p.A(a, a);
      p.C.col(a).cwiseAbs().maxCoeff(&row);
      if (!(std::abs(p.C(row, a)) > 0)) return false;
      S(a, a) = 1.0 / p.C(row, a);
      out.c_held.emplace_back(static_cast<int>(row), a, 1.0);
      a += 1;
    } else {
      const double sigma = 0.5 * (p.A(a, a) + p.A(a + 1, a + 1)), omega = 0.5 * (p.A(a, a + 1) - p.A(a + 1, a));
      A(a, a) = A(a + 1, a + 1) = sigma;
      A(a, a + 1) = omega;
      A(a + 1, a) = -omega;
      (p.C.col(a).array().square() + p.C.col(a + 1).array().square()).maxCoeff(&row);
      const double c1 = p.C(row, a), c2 = p.C(row, a + 1), n2 = c1 * c1 + c2 * c2;
      if (!(n2 > 0)) return false;
      // z -> (alpha I + beta J) z commutes with the block; it maps [c1, c2] to [1, 0].
      const double al = c1 / n2, be = -c2 / n2;
      S(a, a) = al;
      S(a, a + 1) = be;
      S(a + 1, a) = -be;
      S(a + 1, a + 1) = al;
      out.c_held.emplace_back(static_cast<int>(row), a, 1.0);
      out.c_held.emplace_back(static_cast<int>(row), a + 1, 0.0);
      a += 2;
    }
  }
  p.A = A;
  p = transformed(p, S);
  p.A = A;  // exact (the scaling commutes with each block)
  for (const auto& [r, c, v] : out.c_held) p.C(r, c) = v;  // exact normalisation
  out.model = p;
  return true;
}


// Every pole in the open left half plane, apart from the k held integrators (A's first k columns are zero, so the
// other poles are those of the lower-right block).
bool stable(const Eigen::MatrixXd& A, int k) {
  const Eigen::Index n = A.rows() - k;
  if (n <= 0) return true;
  const Eigen::VectorXcd p = A.bottomRightCorner(n, n).eigenvalues();
  return p.allFinite() && (p.real().array() < 0.0).all();
}


std::string entry_name(char M, int i, int j) {
  std::string s(1, M);
  s += std::to_string(i + 1);
  s += '_';
  s += std::to_string(j + 1);
  return s;
}


void describe(Result<StateSpace>& res, Point& fin, const Layout& L, const std::vector<bool>& held, bool user_coordinates,
              int integrators, bool estimate_d) {
  std::vector<std::string> pnames;
  std::vector<bool> pfixed;
  std::vector<double> vals;
  auto add = [&](std::string name, double value, bool fixed) {
    pnames.push_back(std::move(name));
    vals.push_back(value);
    pfixed.push_back(fixed);
  };
  auto add_entries = [&](char M, const Eigen::MatrixXd& X, auto is_held) {
    for (int i = 0; i < X.rows(); ++i)
      for (int j = 0; j < X.cols(); ++j) add(entry_name(M, i, j), X(i, j), is_held(i, j));
  };
  auto held_at = [&](Eigen::Index (Layout::*at)(int, int) const) {
    return [&, at](int i, int j) { return static_cast<bool>(held[static_cast<size_t>((L.*at)(i, j))]); };
  };
  ModalForm mf;
  const bool modal = !user_coordinates && modal_form(fin, integrators, mf);
  if (!user_coordinates && !modal)
    res.diagnostics.warnings.push_back("the model has nearly repeated poles: it is returned in the search's coordinates, "
                                       "where its entries are not determined (poles and responses are)");
  if (modal) {
    fin = mf.model;
    for (int k = 0; k < integrators; ++k) add("pole" + std::to_string(k + 1), 0.0, true);  // held at 0
    for (const std::string& n : mf.names) {
      const int a = std::stoi(n.substr(n[0] == 'p' ? 4 : 5)) - 1;
      add(n, n[0] == 'o' ? fin.A(a, a + 1) : fin.A(a, a), false);
    }
    add_entries('B', fin.B, [](int, int) { return false; });
    add_entries('C', fin.C, [&](int i, int j) {
      bool norm = false;
      for (const auto& [r, c, v] : mf.c_held) norm = norm || (r == i && c == j);
      return norm;
    });
  } else {
    add_entries('A', fin.A, held_at(&Layout::a));
    add_entries('B', fin.B, held_at(&Layout::b));
    add_entries('C', fin.C, held_at(&Layout::c));
  }
  if (estimate_d) add_entries('D', fin.D, held_at(&Layout::d));
  if (L.nk > 0) add_entries('K', fin.K, held_at(&Layout::k));
  res.model = StateSpace(fin.A, fin.B, fin.C, fin.D, fin.K);
  res.parameters.names = pnames;
  res.parameters.values = Eigen::Map<const Eigen::VectorXd>(vals.data(), static_cast<Eigen::Index>(vals.size()));
  res.parameters.fixed = pfixed;
}

Eigen::MatrixXd inverse_normal(const Eigen::MatrixXd& JtJ, Eigen::Index np) {
  const Eigen::VectorXd dg = JtJ.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd Sc = dg.asDiagonal() * JtJ * dg.asDiagonal();
  Eigen::LDLT<Eigen::MatrixXd> ldlt(Sc);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Sc, Eigen::EigenvaluesOnly);
  if (ldlt.info() != Eigen::Success || !(eig.eigenvalues()(0) > 1e-13 * eig.eigenvalues().maxCoeff())) return {};
  const Eigen::MatrixXd full =
      dg.asDiagonal() * ldlt.solve(Eigen::MatrixXd::Identity(Sc.rows(), Sc.cols())) * dg.asDiagonal();
  return full.topLeftCorner(np, np);
}

// A from shift invariance of O: O(ny:) = O(:-ny) A_step.
Eigen::MatrixXd shift_invariance(const Eigen::MatrixXd& O, int ny) {
  const Eigen::Index rows = O.rows() - ny;
  return O.topRows(rows).completeOrthogonalDecomposition().solve(O.bottomRows(rows));
}

// A with each eigenvalue re + j im of re > 0 moved to -re + j im (same eigenvectors): the stable model nearest in
// its modes. A spurious noise mode (typical of a subspace estimate from noisy, finely sampled data) then becomes a fast
// stable mode instead of a response that overflows over the record.
Eigen::MatrixXd reflected_into_left_half_plane(const Eigen::MatrixXd& A) {
  Eigen::EigenSolver<Eigen::MatrixXd> es(A);
  Eigen::VectorXcd l = es.eigenvalues();
  if (es.info() != Eigen::Success || (l.real().array() <= 0.0).all()) return A;
  for (Eigen::Index i = 0; i < l.size(); ++i)
    if (l(i).real() > 0.0) l(i) = std::complex<double>(-l(i).real(), l(i).imag());
  const Eigen::MatrixXcd V = es.eigenvectors();
  const Eigen::MatrixXd R = (V * l.asDiagonal() * V.inverse()).real();
  return R.allFinite() ? R : A;
}

void report_modes(Result<StateSpace>& res) {
  const std::vector<ModeUncertainty> mu = mode_uncertainty(res);
  Eigen::VectorXd wn_std(static_cast<Eigen::Index>(mu.size())), zeta_std(static_cast<Eigen::Index>(mu.size()));
  for (size_t k = 0; k < mu.size(); ++k) {
    wn_std(static_cast<Eigen::Index>(k)) = mu[k].wn_std;
    zeta_std(static_cast<Eigen::Index>(k)) = mu[k].zeta_std;
  }
  res.diagnostics.set(diagnostic::mode_wn_std, wn_std);
  res.diagnostics.set(diagnostic::mode_zeta_std, zeta_std);
  int unstable = 0;
  for (const auto& p : res.model.poles()) unstable += p.real() > 1e-12 * (1.0 + std::abs(p));
  if (unstable > 0)
    res.diagnostics.warnings.push_back(detail::format("the model has {} pole(s) in the right half plane", unstable));
}

}  // namespace ctid::ss_detail
