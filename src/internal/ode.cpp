#include "internal/ode.hpp"

#include <algorithm>
#include <cmath>

namespace ctid::internal {

OdeOutcome dopri45(const OdeRhs& f, const Eigen::VectorXd& x0, const Eigen::MatrixXd& u, const Eigen::VectorXd& t,
                   bool hold, double rtol, double atol, Eigen::Index n_control, const OdeSample& sample,
                   long max_steps) {
  static const double c2 = 1. / 5, c3 = 3. / 10, c4 = 4. / 5, c5 = 8. / 9;
  static const double a21 = 1. / 5, a31 = 3. / 40, a32 = 9. / 40, a41 = 44. / 45, a42 = -56. / 15, a43 = 32. / 9,
                      a51 = 19372. / 6561, a52 = -25360. / 2187, a53 = 64448. / 6561, a54 = -212. / 729,
                      a61 = 9017. / 3168, a62 = -355. / 33, a63 = 46732. / 5247, a64 = 49. / 176, a65 = -5103. / 18656,
                      b1 = 35. / 384, b3 = 500. / 1113, b4 = 125. / 192, b5 = -2187. / 6784, b6 = 11. / 84,
                      e1 = 71. / 57600, e3 = -71. / 16695, e4 = 71. / 1920, e5 = -17253. / 339200, e6 = 22. / 525,
                      e7 = -1. / 40;
  const Eigen::Index n = x0.size();
  OdeOutcome out;
  const Eigen::Index nu = u.cols();
  Eigen::VectorXd ui(std::max<Eigen::Index>(nu, 1));
  Eigen::VectorXd x = x0, k1(n), k2(n), k3(n), k4(n), k5(n), k6(n), k7(n), xt(n), xn(n), errv(n);
  sample(0, x);
  double h = (t.size() > 1 ? t(1) - t(0) : 1.0) / 4;
  long steps = 0;
  const long budget = max_steps > 0 ? max_steps : 1000000L + 1000L * static_cast<long>(t.size());
  for (Eigen::Index k = 0; k + 1 < t.size(); ++k) {
    const double ta = t(k), tb = t(k + 1);
    // The inputs at a time inside [ta, tb] (into ui; the same values for every stage when held).
    auto uin = [&](double tt) {
      const double w = hold ? 0.0 : (tt - ta) / (tb - ta);
      for (Eigen::Index i = 0; i < nu; ++i) ui(i) = (1 - w) * u(k, i) + w * (hold ? 0.0 : u(k + 1, i));
      return ui.data();
    };
    double tt = ta;
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
      if (err <= 1.0) {
        tt += h;
        x = xn;
        k1 = k7;  // first same as last
      }
      h *= std::clamp(0.9 * std::pow(std::max(err, 1e-10), -0.2), 0.2, 5.0);
    }
    sample(k + 1, x);
  }
  return out;
}

}  // namespace ctid::internal
