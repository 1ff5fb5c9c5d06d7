#include "internal/ode.hpp"

#include <algorithm>
#include <cmath>

namespace ctid::internal {

InputReader::InputReader(const Eigen::MatrixXd& u, const Eigen::VectorXd& t, Between mode)
    : u_(u), t_(t), mode_(mode), ui_(std::max<Eigen::Index>(u.cols(), 1)) {}

const double* InputReader::at(Eigen::Index k, double tt) {
  const Eigen::Index nu = u_.cols(), N = u_.rows();
  const Eigen::Index k1 = std::min<Eigen::Index>(k + 1, N - 1);
  const double h = t_(k1) - t_(k), s = h > 0 ? (tt - t_(k)) / h : 0.0;
  if (mode_ == Between::Hold || s == 0.0) {
    for (Eigen::Index i = 0; i < nu; ++i) ui_(i) = u_(k, i);
  } else if (mode_ == Between::Linear) {
    for (Eigen::Index i = 0; i < nu; ++i) ui_(i) = (1 - s) * u_(k, i) + s * u_(k1, i);
  } else {
    // Lanczos: w(x) = sinc(x) sinc(x / a) for the samples at offsets j = -a+1 .. a, x = s - j; sin(pi (s - j)) =
    // (-1)^j sin(pi s).
    const double pi = 3.14159265358979323846, a = kTaps, sps = std::sin(pi * s);
    double total = 0;
    for (int j = -kTaps + 1; j <= kTaps; ++j) {
      const double x = s - j;
      const double w = std::abs(x) < 1e-12 ? 1.0
                                            : ((j % 2 == 0) ? sps : -sps) / (pi * x) * std::sin(pi * x / a) / (pi * x / a);
      w_[j + kTaps - 1] = w;
      total += w;
    }
    for (Eigen::Index i = 0; i < nu; ++i) {
      double v = 0;
      for (int j = -kTaps + 1; j <= kTaps; ++j)
        v += w_[j + kTaps - 1] * u_(std::clamp<Eigen::Index>(k + j, 0, N - 1), i);
      ui_(i) = v / total;
    }
  }
  return ui_.data();
}

OdeOutcome dopri45(const OdeRhs& f, const Eigen::VectorXd& x0, const Eigen::MatrixXd& u, const Eigen::VectorXd& t,
                   Between intersample, double rtol, double atol, Eigen::Index n_control, const OdeSample& sample,
                   long max_steps, const OdeEvents* events) {
  static const double c2 = 1. / 5, c3 = 3. / 10, c4 = 4. / 5, c5 = 8. / 9;
  static const double a21 = 1. / 5, a31 = 3. / 40, a32 = 9. / 40, a41 = 44. / 45, a42 = -56. / 15, a43 = 32. / 9,
                      a51 = 19372. / 6561, a52 = -25360. / 2187, a53 = 64448. / 6561, a54 = -212. / 729,
                      a61 = 9017. / 3168, a62 = -355. / 33, a63 = 46732. / 5247, a64 = 49. / 176, a65 = -5103. / 18656,
                      b1 = 35. / 384, b3 = 500. / 1113, b4 = 125. / 192, b5 = -2187. / 6784, b6 = 11. / 84,
                      e1 = 71. / 57600, e3 = -71. / 16695, e4 = 71. / 1920, e5 = -17253. / 339200, e6 = 22. / 525,
                      e7 = -1. / 40;
  const Eigen::Index n = x0.size();
  OdeOutcome out;
  InputReader reader(u, t, intersample);
  Eigen::VectorXd x = x0, k1(n), k2(n), k3(n), k4(n), k5(n), k6(n), k7(n), xt(n), xn(n), errv(n);
  const int ne = events ? events->count : 0;
  std::vector<double> g0(static_cast<size_t>(ne)), g1(g0), gi(g0);  // event values at a step's start, end, inside
  Eigen::VectorXd xi(n_control);                                       // the interpolated controlled components
  sample(0, x);
  double h = (t.size() > 1 ? t(1) - t(0) : 1.0) / 4;
  long steps = 0;
  const long budget = max_steps > 0 ? max_steps : 1000000L + 1000L * static_cast<long>(t.size());
  for (Eigen::Index k = 0; k + 1 < t.size(); ++k) {
    const double ta = t(k), tb = t(k + 1);
    auto uin = [&](double tt) { return reader.at(k, tt); };  // the inputs at a time inside [ta, tb]
    double tt = ta;
    int fired = 0;       // events in this interval
    int pending = -1;    // the event the step being tried ends on
    double h_free = h;   // the step size the controller wanted before a step was cut at an event
    // Fires event i at (tt, x); false when the integration must stop (refused, or chattering).
    auto fire = [&](int i) {
      out.refused = !events->fire(i, tt, x, uin(tt));
      out.chatter = ++fired > 1000;
      if (out.refused || out.chatter) {
        out.ok = false;
        out.t = tt;
        out.xmax = x.head(n_control).cwiseAbs().maxCoeff();
        return false;
      }
      events->values(tt, x.data(), uin(tt), g0.data());
      return true;
    };
    if (ne) {  // an input that jumps at ta can leave an event function <= 0 already
      events->values(tt, x.data(), uin(tt), g0.data());
      for (int i = 0; i < ne; ++i)
        if (g0[static_cast<size_t>(i)] <= 0 && !fire(i)) return out;
    }
    h = std::min(h, tb - ta);
    f(tt, x, uin(tt), k1);
    while (tt < tb) {
      if (tt + h > tb) h = tb - tt;
      xt = x + h * a21 * k1;
      f(tt + c2 * h, xt, uin(tt + c2 * h), k2);
      xt = x + h * (a31 * k1 + a32 * k2);
      f(tt + c3 * h, xt, uin(tt + c3 * h), k3);
      xt = x + h * (a41 * k1 + a42 * k2 + a43 * k3);
      f(tt + c4 * h, xt, uin(tt + c4 * h), k4);
      xt = x + h * (a51 * k1 + a52 * k2 + a53 * k3 + a54 * k4);
      f(tt + c5 * h, xt, uin(tt + c5 * h), k5);
      xt = x + h * (a61 * k1 + a62 * k2 + a63 * k3 + a64 * k4 + a65 * k5);
      f(tt + h, xt, uin(tt + h), k6);
      xn = x + h * (b1 * k1 + b3 * k3 + b4 * k4 + b5 * k5 + b6 * k6);
      f(tt + h, xn, uin(tt + h), k7);
      errv = h * (e1 * k1 + e3 * k3 + e4 * k4 + e5 * k5 + e6 * k6 + e7 * k7);
      double err = 0;
      for (Eigen::Index i = 0; i < n_control; ++i)
        err = std::max(err, std::abs(errv(i)) / (atol + rtol * std::max(std::abs(x(i)), std::abs(xn(i)))));
      const double xmax = xn.head(n_control).cwiseAbs().maxCoeff();
      if (++steps > budget) {
        out.ok = false;
        out.budget = true;
        out.t = tt;
        out.xmax = xmax;
        return out;
      }
      if (!std::isfinite(err) || !xn.allFinite() || xmax > 1e12 || h < 1e-14 * std::max(1.0, std::abs(tt))) {
        out.ok = false;
        out.collapsed = std::isfinite(err) && xn.allFinite() && xmax <= 1e12;
        out.t = tt;
        out.xmax = xmax;
        return out;
      }
      if (err > 1.0) {
        pending = -1;
        h *= std::clamp(0.9 * std::pow(err, -0.2), 0.2, 1.0);
        continue;
      }
      if (ne && pending < 0) {
        // The first event function to change sign inside the step, located on the cubic Hermite interpolant of the
        // step (Illinois iteration on the fraction th of the step).
        events->values(tt + h, xn.data(), uin(tt + h), g1.data());
        double first = 2.0;
        for (int i = 0; i < ne; ++i) {
          double ga = g0[static_cast<size_t>(i)], gb = g1[static_cast<size_t>(i)];
          if (!(ga > 0 && gb <= 0)) continue;
          double a = 0, b = 1;
          int side = 0;
          for (int it = 0; it < 60 && b - a > 1e-13; ++it) {
            const double th = std::clamp((a * gb - b * ga) / (gb - ga), a + 0.01 * (b - a), b - 0.01 * (b - a));
            const double h00 = (1 + 2 * th) * (1 - th) * (1 - th), h10 = th * (1 - th) * (1 - th),
                         h01 = th * th * (3 - 2 * th), h11 = -th * th * (1 - th);
            xi = h00 * x.head(n_control) + h01 * xn.head(n_control) +
                 h * (h10 * k1.head(n_control) + h11 * k7.head(n_control));
            events->values(tt + th * h, xi.data(), uin(tt + th * h), gi.data());
            const double gc = gi[static_cast<size_t>(i)];
            if (gc > 0) {
              a = th, ga = gc;
              if (side == 1) gb /= 2;
              side = 1;
            } else {
              b = th, gb = gc;
              if (side == -1) ga /= 2;
              side = -1;
            }
          }
          if (b < first) first = b, pending = i;
        }
        if (pending >= 0 && first < 1.0 - 1e-12) {
          if (first * h <= 1e-13 * std::max(1.0, std::abs(tt))) {
            if (!fire(pending)) return out;  // at the start of the step
          } else {
            h_free = h;
            h *= first;  // repeat the step to end on the event
            continue;
          }
          pending = -1;
          f(tt, x, uin(tt), k1);
          continue;
        }
      }
      tt += h;
      x = xn;
      k1 = k7;  // first same as last
      if (pending >= 0) {
        if (!fire(pending)) return out;
        pending = -1;
        f(tt, x, uin(tt), k1);
        h = std::max(h, h_free);
        continue;
      }
      if (ne) g0.swap(g1);
      h *= std::clamp(0.9 * std::pow(std::max(err, 1e-10), -0.2), 0.2, 5.0);
    }
    sample(k + 1, x);
  }
  return out;
}

}  // namespace ctid::internal
