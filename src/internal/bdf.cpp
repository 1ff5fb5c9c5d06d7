// ctid internal — stiff integration (internal/ode.hpp: bdf) by CVODES of SUNDIALS (Hindmarsh, Brown, Grant, Lee,
// Serban, Shumaker & Woodward 2005, "SUNDIALS: Suite of nonlinear and differential/algebraic equation solvers", ACM
// TOMS 31(3) 363-396; the sensitivity module: Serban & Hindmarsh 2005, "CVODES: the sensitivity-enabled ODE solver in
// SUNDIALS", Proc. ASME IDETC): variable-order BDF, Newton on the dense exact Jacobian, the staggered corrector for
// the forward sensitivities (outside the error test), CVODES's root finding for the state events, a stop time at
// every sample (the inputs are those of the current interval) and a restart where a held input jumps or an event
// changed the right-hand side or the state.
#include <cmath>

#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "internal/ode.hpp"

namespace ctid::internal {

namespace {

struct Problem {
  const OdeJacobianRhs* f = nullptr;
  const OdeEvents* events = nullptr;
  InputReader* reader = nullptr;
  Eigen::Index k = 0;  // the current sample interval [t(k), t(k + 1)]
  double ta = 0, tb = 1;
  Eigen::MatrixXd J, B;
  Eigen::VectorXd dx;
  const double* inputs(double t) { return reader->at(k, t); }
};

Problem& of(void* data) { return *static_cast<Problem*>(data); }

// A non-finite derivative is a recoverable error: CVODES retries with a smaller step.
int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* data) {
  Problem& p = of(data);
  (*p.f)(t, NV_DATA_S(y), p.inputs(t), NV_DATA_S(ydot), nullptr, nullptr);
  const Eigen::Map<const Eigen::VectorXd> d(NV_DATA_S(ydot), NV_LENGTH_S(ydot));
  return d.allFinite() ? 0 : 1;
}

int jacobian(sunrealtype t, N_Vector y, N_Vector, SUNMatrix Jm, void* data, N_Vector, N_Vector, N_Vector) {
  Problem& p = of(data);
  (*p.f)(t, NV_DATA_S(y), p.inputs(t), p.dx.data(), &p.J, nullptr);
  if (!p.J.allFinite()) return 1;
  for (Eigen::Index j = 0; j < p.J.cols(); ++j)
    for (Eigen::Index i = 0; i < p.J.rows(); ++i) SM_ELEMENT_D(Jm, i, j) = p.J(i, j);
  return 0;
}

int sensitivities(int q, sunrealtype t, N_Vector y, N_Vector, N_Vector* yS, N_Vector* ySdot, void* data, N_Vector,
                  N_Vector) {
  Problem& p = of(data);
  (*p.f)(t, NV_DATA_S(y), p.inputs(t), p.dx.data(), &p.J, &p.B);
  for (int j = 0; j < q; ++j) {
    Eigen::Map<Eigen::VectorXd> out(NV_DATA_S(ySdot[j]), p.J.rows());
    out.noalias() = p.J * Eigen::Map<const Eigen::VectorXd>(NV_DATA_S(yS[j]), p.J.rows()) + p.B.col(j);
    if (!out.allFinite()) return 1;
  }
  return 0;
}

int roots(sunrealtype t, N_Vector y, sunrealtype* g, void* data) {
  Problem& p = of(data);
  p.events->values(t, NV_DATA_S(y), p.inputs(t), g);
  return 0;
}

void silent(int, const char*, const char*, char*, void*) {}

// The SUNDIALS objects of one integration, freed on every path out.
struct Cvodes {
  SUNContext ctx = nullptr;
  void* mem = nullptr;
  N_Vector y = nullptr;
  N_Vector* yS = nullptr;
  int q = 0;
  SUNMatrix A = nullptr;
  SUNLinearSolver ls = nullptr;
  ~Cvodes() {
    if (yS) N_VDestroyVectorArray(yS, q);
    if (y) N_VDestroy(y);
    if (mem) CVodeFree(&mem);
    if (ls) SUNLinSolFree(ls);
    if (A) SUNMatDestroy(A);
    if (ctx) SUNContext_Free(&ctx);
  }
};

}  // namespace

OdeOutcome bdf(const OdeJacobianRhs& f, Eigen::Index n, const Eigen::VectorXd& a0, const Eigen::MatrixXd& u,
               const Eigen::VectorXd& t, Between intersample, double rtol, double atol, const OdeSample& sample, long max_steps,
               const OdeEvents* events) {
  OdeOutcome out;
  const int q = static_cast<int>((a0.size() - n) / n);
  Problem p;
  p.f = &f;
  p.events = events;
  InputReader reader(u, t, intersample);
  p.reader = &reader;
  p.J.resize(n, n);
  p.B.resize(n, q);
  p.dx.resize(n);
  Eigen::VectorXd a = a0;
  sample(0, a);
  if (t.size() < 2) return out;

  Cvodes c;
  c.q = q;
  bool ok = SUNContext_Create(nullptr, &c.ctx) == 0;
  ok = ok && (c.y = N_VNew_Serial(n, c.ctx)) != nullptr;
  ok = ok && (c.mem = CVodeCreate(CV_BDF, c.ctx)) != nullptr;
  if (!ok) throw std::bad_alloc();
  auto load = [&] {  // a -> y, yS
    std::copy(a.data(), a.data() + n, NV_DATA_S(c.y));
    for (int j = 0; j < q; ++j) std::copy(a.data() + n * (1 + j), a.data() + n * (2 + j), NV_DATA_S(c.yS[j]));
  };
  auto store = [&] {  // y, yS -> a
    std::copy(NV_DATA_S(c.y), NV_DATA_S(c.y) + n, a.data());
    for (int j = 0; j < q; ++j) std::copy(NV_DATA_S(c.yS[j]), NV_DATA_S(c.yS[j]) + n, a.data() + n * (1 + j));
  };
  std::copy(a.data(), a.data() + n, NV_DATA_S(c.y));
  CVodeSetErrHandlerFn(c.mem, silent, nullptr);
  CVodeInit(c.mem, rhs, t(0), c.y);
  CVodeSStolerances(c.mem, rtol, atol);
  CVodeSetUserData(c.mem, &p);
  c.A = SUNDenseMatrix(n, n, c.ctx);
  c.ls = SUNLinSol_Dense(c.y, c.A, c.ctx);
  CVodeSetLinearSolver(c.mem, c.ls, c.A);
  CVodeSetJacFn(c.mem, jacobian);
  const long budget = max_steps > 0 ? max_steps : 1000000L + 1000L * static_cast<long>(t.size());
  CVodeSetMaxNumSteps(c.mem, budget);
  if (q > 0) {
    c.yS = N_VCloneVectorArray(q, c.y);
    load();
    CVodeSensInit(c.mem, q, CV_STAGGERED, sensitivities, c.yS);
    std::vector<sunrealtype> abstol(static_cast<size_t>(q), atol);
    CVodeSensSStolerances(c.mem, rtol, abstol.data());
    CVodeSetSensErrCon(c.mem, SUNFALSE);
  }
  const int ne = events ? events->count : 0;
  std::vector<int> found(static_cast<size_t>(ne));
  std::vector<double> g(static_cast<size_t>(ne));
  if (ne) {
    CVodeRootInit(c.mem, ne, roots);
    std::vector<int> falling(static_cast<size_t>(ne), -1);  // an event where g goes from > 0 to <= 0
    CVodeSetRootDirection(c.mem, falling.data());
    CVodeSetNoInactiveRootWarn(c.mem);
  }
  long steps_before = 0;  // steps taken before the last restart (CVodeReInit zeroes the counter)
  auto steps = [&] {
    long s = 0;
    CVodeGetNumSteps(c.mem, &s);
    return steps_before + s;
  };
  auto restart = [&](double at) {
    steps_before = steps();
    load();
    CVodeReInit(c.mem, at, c.y);
    if (q > 0) CVodeSensReInit(c.mem, CV_STAGGERED, c.yS);
  };
  auto fail = [&](double at, bool budget_hit, bool collapsed) {
    out.ok = false;
    out.budget = budget_hit;
    out.collapsed = collapsed;
    out.t = at;
    out.xmax = a.head(n).cwiseAbs().maxCoeff();
    return out;
  };
  for (Eigen::Index k = 0; k + 1 < t.size(); ++k) {
    p.k = k, p.ta = t(k), p.tb = t(k + 1);
    bool jump = intersample == Between::Hold && k > 0 && u.row(k) != u.row(k - 1);
    int fired = 0;
    if (ne) {  // an input that jumps at t(k) can leave an event function <= 0 already
      events->values(p.ta, a.data(), p.inputs(p.ta), g.data());
      for (int i = 0; i < ne; ++i) {
        if (g[static_cast<size_t>(i)] > 0) continue;
        if (!events->fire(i, p.ta, a, p.inputs(p.ta))) {
          out.refused = true;
          return fail(p.ta, false, false);
        }
        jump = true;
        ++fired;
        events->values(p.ta, a.data(), p.inputs(p.ta), g.data());
      }
    }
    if (jump) restart(p.ta);
    CVodeSetStopTime(c.mem, p.tb);
    for (;;) {
      sunrealtype reached = p.ta;
      const int flag = CVode(c.mem, p.tb, c.y, &reached, CV_NORMAL);
      if (q > 0 && flag >= 0) CVodeGetSens(c.mem, &reached, c.yS);
      if (flag >= 0) store();
      if (flag < 0 || !a.head(n).allFinite() || a.head(n).cwiseAbs().maxCoeff() > 1e12) {
        const bool finite = a.head(n).allFinite() && a.head(n).cwiseAbs().maxCoeff() <= 1e12;
        return fail(reached, flag == CV_TOO_MUCH_WORK || steps() > budget, flag < 0 && finite);
      }
      if (steps() > budget) return fail(reached, true, false);
      if (flag != CV_ROOT_RETURN) break;
      CVodeGetRootInfo(c.mem, found.data());
      for (int i = 0; i < ne; ++i) {
        if (!found[static_cast<size_t>(i)]) continue;
        if (!events->fire(i, reached, a, p.inputs(reached))) {
          out.refused = true;
          return fail(reached, false, false);
        }
        break;  // one event at a time; the others are found again if they still hold
      }
      if (++fired > 1000) {
        out.chatter = true;
        return fail(reached, false, false);
      }
      restart(reached);
      CVodeSetStopTime(c.mem, p.tb);
    }
    sample(k + 1, a);
  }
  return out;
}

}  // namespace ctid::internal
