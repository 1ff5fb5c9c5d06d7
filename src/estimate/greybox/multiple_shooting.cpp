// ctid — multiple shooting of the grey-box problem (see multiple_shooting.hpp; Bock & Plitt 1984; Bock 1983).
#include "estimate/greybox/multiple_shooting.hpp"

#include <algorithm>
#include <cmath>

#include "ctid/core/check.hpp"
#include "ctid/validate/metrics.hpp"

namespace ctid::greybox_detail {

bool wants_multiple_shooting(Problem& P) {
  if (P.opt.segments != 0) return P.opt.segments > 1;
  Eigen::VectorXd r0;
  return !P.evaluate(P.v0, r0, nullptr) || !(fit_report_or_inf(P.wy, P.wy - r0, P.p).fit_percent > -900.0);
}

MultipleShooting::MultipleShooting(Problem& problem, int segments)
    : P_(problem),
      seg_(static_cast<size_t>(problem.E)),
      offset_(static_cast<size_t>(problem.E), 0),
      scale_(Eigen::VectorXd::Ones(problem.nx)),
      rho_(Eigen::VectorXd::Ones(problem.nx)),
      all_states_(static_cast<size_t>(problem.nx)) {
  for (int i = 0; i < P_.nx; ++i) all_states_[static_cast<size_t>(i)] = i;
  mu_base_ = std::sqrt(P_.wy.squaredNorm() / static_cast<double>(std::max<Eigen::Index>(1, P_.wy.size())));
  if (!(mu_base_ > 0)) mu_base_ = 1.0;
  if (segments > 1) cut(segments, 0);
  else  // automatic: segments of 100 samples, halved (to 4) until every segment simulates from the start
    for (int length = 100;; length /= 2) {
      cut(0, length);
      bool ok = true;
      segment_guess(P_.v0, ok);
      if (ok || length <= 4) break;
    }
}

int MultipleShooting::segments() const { return ns_ / std::max(P_.nx, 1) + P_.E; }

// Cuts every record into segments: S each when given, else segments of `length` samples.
void MultipleShooting::cut(int S_given, int length) {
  ns_ = 0;
  for (int e = 0; e < P_.E; ++e) {
    const Record& d = P_.rec[static_cast<size_t>(e)];
    const int S = std::min(S_given > 1 ? S_given : (d.n - 1 + length - 1) / length, d.n - 1);
    offset_[static_cast<size_t>(e)] = ns_;
    auto& sg = seg_[static_cast<size_t>(e)];
    sg.clear();
    for (int k = 0; k < S; ++k) {
      const int b0 = static_cast<int>(std::llround(static_cast<double>(k) * (d.n - 1) / S));
      const int b1 = static_cast<int>(std::llround(static_cast<double>(k + 1) * (d.n - 1) / S));
      Segment g;
      g.first = b0;
      g.rows = k + 1 < S ? b1 - b0 : b1 - b0 + 1;
      g.u = d.u.middleRows(b0, b1 - b0 + 1);
      g.t = d.t.segment(b0, b1 - b0 + 1);
      sg.push_back(std::move(g));
    }
    ns_ += (S - 1) * P_.nx;
  }
}

// The residual (and Jacobian) of the segmented problem: weighted output errors, then the continuity residuals.
bool MultipleShooting::evaluate(const Eigen::VectorXd& vm, Eigen::VectorXd& r, Eigen::SparseMatrix<double>* J) {
  const int p = P_.p, pf = P_.pf, nx = P_.nx, nx0 = P_.nx0, ny = P_.ny;
  const Eigen::Index Ny = P_.y.size();
  auto put = [&](Eigen::Index row, Eigen::Index col, const Eigen::MatrixXd& block) {
    for (Eigen::Index c = 0; c < block.cols(); ++c)
      for (Eigen::Index i = 0; i < block.rows(); ++i)
        if (block(i, c) != 0.0) nz_.emplace_back(static_cast<int>(row + i), static_cast<int>(col + c), block(i, c));
  };
  const GreyboxModel m = P_.model_at(vm);
  r.setZero(Ny + ns_);
  nz_.clear();
  for (int e = 0; e < P_.E; ++e) {
    const Record& d = P_.rec[static_cast<size_t>(e)];
    const auto& sg = seg_[static_cast<size_t>(e)];
    const int S = static_cast<int>(sg.size());
    for (int k = 0; k < S; ++k) {
      const Segment& g = sg[static_cast<size_t>(k)];
      const Eigen::Index col_k = p + offset_[static_cast<size_t>(e)] + static_cast<Eigen::Index>(k - 1) * nx;
      const Eigen::VectorXd x0 = k == 0 ? P_.x0_of(m, vm, e) : Eigen::VectorXd(vm.segment(col_k, nx));
      Eigen::VectorXd x_end;
      if (!J) {
        const GreyboxSimulation sim = P_.simulate(m, d, g.u, g.t, x0);
        if (!sim.ok()) return P_.escape = sim.message, false;
        for (int j = 0; j < ny; ++j)
          r.segment(d.start + static_cast<Eigen::Index>(j) * d.n + g.first, g.rows) = P_.w(j) * sim.y.col(j).head(g.rows);
        x_end = sim.x.row(sim.x.rows() - 1).transpose();
      } else {
        const GreyboxSensitivities sn = P_.sensitivities(m, d, g.u, g.t, x0, k == 0 ? P_.free_x0 : all_states_, k == 0);
        if (!sn.ok) return P_.escape = sn.message, false;
        const int nq = k == 0 ? nx0 : nx;
        const Eigen::Index col_s = k == 0 ? pf + e * nx0 : col_k;
        for (int j = 0; j < ny; ++j) {
          const Eigen::Index row = d.start + static_cast<Eigen::Index>(j) * d.n + g.first;
          const Eigen::MatrixXd& dy = sn.dy[static_cast<size_t>(j)];
          r.segment(row, g.rows) = P_.w(j) * sn.y.col(j).head(g.rows);
          put(row, 0, -P_.w(j) * dy.topLeftCorner(g.rows, pf));
          if (nq) put(row, col_s, -P_.w(j) * dy.topRightCorner(g.rows, nq));
        }
        x_end = sn.x_end;
        if (k + 1 < S) {
          const Eigen::Index c = Ny + offset_[static_cast<size_t>(e)] + static_cast<Eigen::Index>(k) * nx;
          put(c, 0, rho_.asDiagonal() * sn.dx_end.leftCols(pf));
          if (nq) put(c, col_s, rho_.asDiagonal() * sn.dx_end.rightCols(nq));
          put(c, col_k + nx, Eigen::MatrixXd((-rho_).asDiagonal()));
        }
      }
      if (k + 1 < S) {
        const Eigen::Index c = Ny + offset_[static_cast<size_t>(e)] + static_cast<Eigen::Index>(k) * nx;
        r.segment(c, nx) = rho_.cwiseProduct(x_end - vm.segment(col_k + nx, nx));
      }
    }
  }
  r.head(Ny) = P_.wy - r.head(Ny);
  if (J) {
    J->resize(Ny + ns_, p + ns_);
    J->setFromTriplets(nz_.begin(), nz_.end());
  }
  return true;
}

// The segments' starting states, segment by segment (a greedy observer): an output that is a state alone gives
// that state from the data; the others either continue the previous segment's simulation or restart from the
// record's initial guess, whichever simulates the segment with the smaller output error. `ok`: every segment
// simulates from its start.
Eigen::VectorXd MultipleShooting::segment_guess(const Eigen::VectorXd& v, bool& ok) {
  const int p = P_.p, nx = P_.nx, ny = P_.ny;
  Eigen::VectorXd vm(p + ns_);
  vm.head(p) = v;
  ok = true;
  const GreyboxModel m = P_.model_at(v);
  for (int e = 0; e < P_.E; ++e) {
    const Record& d = P_.rec[static_cast<size_t>(e)];
    const auto& sg = seg_[static_cast<size_t>(e)];
    const Eigen::VectorXd guess = P_.x0_of(m, v, e);
    Eigen::VectorXd x = guess;
    for (size_t k = 0; k < sg.size(); ++k) {
      const Segment& g = sg[k];
      // The output error of the segment from x (infinite when it escapes), and its end state.
      auto run = [&](Eigen::VectorXd& start, Eigen::VectorXd& end) {
        if (k > 0)
          for (int i = 0; i < nx; ++i)
            if (const int o = P_.model.output_of_state(i); o >= 0) start(i) = d.y(static_cast<Eigen::Index>(o) * d.n + g.first);
        const GreyboxSimulation sim = P_.simulate(m, d, g.u, g.t, start);
        if (!sim.ok()) return static_cast<double>(INFINITY);
        end = sim.x.row(sim.x.rows() - 1).transpose();
        double cost = 0;
        for (int j = 0; j < ny; ++j)
          cost += (d.y.segment(static_cast<Eigen::Index>(j) * d.n + g.first, g.rows) - sim.y.col(j).head(g.rows)).squaredNorm();
        return cost;
      };
      Eigen::VectorXd a = x, b = guess, end_a, end_b;
      const double ca = run(a, end_a), cb = k > 0 ? run(b, end_b) : INFINITY;
      if (!std::isfinite(std::min(ca, cb))) ok = false;
      const bool take_b = cb < ca;
      if (k > 0) vm.segment(p + offset_[static_cast<size_t>(e)] + static_cast<Eigen::Index>(k - 1) * nx, nx) = take_b ? b : a;
      x = take_b ? end_b : (std::isfinite(ca) ? end_a : guess);
    }
  }
  return vm;
}

internal::LmResult MultipleShooting::search(const Eigen::VectorXd& v) {
  const int p = P_.p, nx = P_.nx;
  bool ok = true;
  Eigen::VectorXd vm = segment_guess(v, ok);
  for (int i = 0; i < nx; ++i) {
    double s2 = 0;
    for (int k = 0; k < ns_ / std::max(nx, 1); ++k)
      s2 += vm(p + static_cast<Eigen::Index>(k) * nx + i) * vm(p + static_cast<Eigen::Index>(k) * nx + i);
    scale_(i) = ns_ > 0 && s2 > 0 ? std::sqrt(s2 / (ns_ / nx)) : 1.0;
  }
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(p + ns_, -INFINITY), hi = Eigen::VectorXd::Constant(p + ns_, INFINITY);
  lo.head(p) = P_.lo;
  hi.head(p) = P_.hi;
  const internal::LmSparseEvaluate f = [this](const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::SparseMatrix<double>* J) {
    return evaluate(x, r, J);
  };
  const internal::LmOptions lmo = P_.lm_options();
  internal::LmResult lm;
  int iterations = 0;
  for (const double factor : {1.0, 1e2, 1e4}) {
    rho_ = (factor * mu_base_) * scale_.cwiseInverse();
    lm = internal::levenberg_marquardt(f, vm, lo, hi, lmo);
    iterations += lm.iterations;
    if (!std::isfinite(lm.cost) || lm.interrupted) break;
    vm = lm.x;
  }
  lm.iterations = iterations;
  return lm;
}

void MultipleShooting::settle(internal::LmResult& best, Eigen::VectorXd& segment_fit, std::vector<std::string>& warnings) {
  const int p = P_.p, nx = P_.nx;
  const Eigen::Index Ny = P_.y.size();
  if (std::isfinite(best.cost) && !best.interrupted) {
    const Eigen::VectorXd vm = best.x;
    Eigen::VectorXd rm, r1;
    evaluate(vm, rm, nullptr);
    defect_ = 0;
    for (Eigen::Index c = 0; c < ns_; ++c) defect_ = std::max(defect_, std::abs(rm(Ny + c)) / rho_(c % nx) / scale_(c % nx));
    const double segment_cost = 0.5 * rm.head(Ny).squaredNorm();
    internal::LmResult single;
    single.cost = INFINITY;
    P_.escape.clear();
    const bool runs = P_.evaluate(vm.head(p), r1, nullptr);
    const std::string free_run = runs ? "its free run drifts away from the data" : P_.escape;
    if (runs) single = P_.search(vm.head(p));
    if (std::isfinite(single.cost) && single.cost <= 1.05 * segment_cost) {
      single.iterations += best.iterations;
      best = single;
    } else {
      // The information about v with the segment states eliminated: the Schur complement of their block, the
      // constrained problem's information as the continuity weights grow.
      const Eigen::MatrixXd& F = best.jtj;
      const Eigen::MatrixXd Dinv_Bt = F.bottomRightCorner(ns_, ns_).ldlt().solve(F.bottomLeftCorner(ns_, p));
      segment_fit = P_.wy - rm.head(Ny);
      best.x = vm.head(p);
      best.jtj = F.topLeftCorner(p, p) - F.topRightCorner(p, ns_) * Dinv_Bt;
      best.cost = segment_cost;
      warnings.push_back(detail::format(
          "multiple shooting: the fitted model does not run free over the record{} ({}); the fit is that of {} "
          "segments, each from its estimated state (largest continuity defect {} of the state's scale)",
          P_.E > 1 ? "s" : "", free_run, segments(), defect_));
    }
  }
  if (best.x.size() > p) {  // an interrupted or failed multiple-shooting search: its parameters only
    best.x.conservativeResize(p);
    if (best.jtj.rows() > p) best.jtj = best.jtj.topLeftCorner(p, p).eval();
  }
}

}  // namespace ctid::greybox_detail
