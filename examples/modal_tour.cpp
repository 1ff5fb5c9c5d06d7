// The examples of docs/methods/el-shafey.md, run by ctest: modal parameters of a known model, Fourier
// estimation to the third derivative, a transfer function from a two-sinusoid test, poles from a wideband
// free response (data matrix against Prony), step and impulse responses from piecewise-constant data,
// the dead-beat observer, and the modal route on the bundled hair-dryer record compared with SRIVC and FSF.
#include <cmath>
#include <cstdio>
#include <numbers>

#include <ctid/ctid.hpp>

int main() {
  using namespace ctid;
  const double pi = std::numbers::pi, Ts = pi / 420;
  const TransferFunction s3(Polynomial{13.0, 52.0}, Polynomial{1.0, 4.0, 30.0, 52.0});
  const Eigen::Vector3d shifts(40 * Ts, 80 * Ts, 120 * Ts);
  bool ok = true;

  // 1. Modal parameters of a known model (ES Table 2.1) and the conditioning of psi.
  const ModalParameters mp = modal_parameters(s3, shifts, 3);
  std::printf("p_0 = [%.4f %.4f %.4f], cond(psi) = %.1f\n", mp.P(0, 0), mp.P(0, 1), mp.P(0, 2), mp.condition);

  // 2. Two sinusoids drive S3 from rest; Fourier functions give p_0..p_3 and q_0..q_3, Theorems 4.1/4.2 the model.
  const InputGenerator g = InputGenerator::sinusoid(4.0, 1.0) + InputGenerator::sinusoid(1.5, 0.0, 0.7);
  const Eigen::VectorXd t = time_grid(Ts, 1500);
  const IdData sines(g(t), lsim(s3.to_state_space(), g, t), Ts);  // noise-free: see the page on noise
  const auto tf = modal_fit(sines, 3, {.shifts = shifts, .functions = 10}, &g);
  std::printf("two-sinusoid test: %s   fit %.2f %%\n", tf.model.to_string(4).c_str(), tf.fit.fit_percent);
  ok = ok && std::abs(tf.model.den().coefficient_of_power(0) - 52.0) < 1e-3;

  // 3. A wideband free response: Prony at a coarse spacing aliases the 100 rad/s mode, Theorem 4.3 does not.
  const double Tw = 2 * pi / 3 / 666;
  const Eigen::VectorXd tw = time_grid(Tw, 2000);
  const Eigen::VectorXd y = (-tw).array().exp() * (3 * tw).array().sin() + (100 * tw).array().cos();
  const PoleEstimate pr = prony(y, Tw, {.order = 4, .spacing = 33, .equations = 10});
  const PoleEstimate dm = free_response_poles(y, Tw, {.shifts = Eigen::Vector4d(33, 66, 99, 132) * Tw, .start = 132 * Tw,
                                                      .interval = 33 * Tw, .spacing = 33 * Tw, .pairs = 10});
  auto fastest = [](const Eigen::VectorXcd& p) {
    double m = 0;
    for (auto z : p) m = std::max(m, std::abs(z.imag()));
    return m;
  };
  std::printf("fastest mode: Prony %.2f rad/s (cond %.3g), data matrix %.2f rad/s (cond %.3g)\n", fastest(pr.poles),
              pr.condition, fastest(dm.poles), dm.condition);
  ok = ok && std::abs(fastest(dm.poles) - 100) < 0.1 && std::abs(fastest(pr.poles) - 100) > 50;

  // 4. Piecewise-constant input (+1, +2, -1, -2 each 80 samples): p_0 on the constant windows, then the step
  //    response (ES-C11) and the impulse response with negative shifts (ES-C12).
  const double Tp = pi / 320, T = 20 * Tp;
  Eigen::VectorXd u(320);
  for (int i = 0; i < 320; ++i) u(i) = (i / 80 == 0) ? 1 : (i / 80 == 1) ? 2 : (i / 80 == 2) ? -1 : -2;
  const IdData steps(u, lsim(s3, u, time_grid(Tp, 320)), Tp);
  ModalOptions o{.shifts = Eigen::Vector3d(T, 2 * T, 3 * T), .basis = ModalBasis::Discrete};
  o.windows = piecewise_constant_windows(steps, 3 * T);
  const auto m0 = modal_estimate(steps, steps.u(), o);
  const TimeResponse gs = modal_step_response(steps, m0.model, T, 640 * Tp);
  const ImpulseFromStep h = modal_impulse_from_step(gs, Eigen::Vector3d(-40, -80, -120) * Tp, 192 * Tp);
  const double eg = (gs.value - step_response(s3, gs.t)).cwiseAbs().maxCoeff();
  const double eh = (h.impulse.value - impulse_response(s3, h.impulse.t)).cwiseAbs().maxCoeff();
  std::printf("step response error %.1e, impulse response error %.1e (q_10 = %.3f)\n", eg, eh, h.q10);
  ok = ok && eg < 1e-8 && eh < 1e-5;

  // 5. Dead-beat observer of (6.5 s + 52)/(s^3 + 4 s^2 + 30 s + 52) for levels held 0.2 s, sampled at 0.01 s.
  const DeadbeatObserver obs = DeadbeatObserver::from_model(TransferFunction(Polynomial{6.5, 52.0}, s3.den()), 0.2, 0.01);
  std::printf("observer: discrete gains Q =\n");
  for (int i = 0; i < 3; ++i)
    std::printf("  %10.6f %10.6f %10.6f\n", obs.Q_discrete()(i, 0), obs.Q_discrete()(i, 1), obs.Q_discrete()(i, 2));

  // 6. Real data: the DaISy hair dryer (bundled; Ts = 0.08 s, means removed). Its input is a binary sequence that
  //    may switch at every sample, so the level period is Ts; the delay of 2 samples found by SRIVC is applied to
  //    the input first. p_0 on the constant windows (shifts 1, 2 samples), then ES-C11's step response.
  const IdData raw = load_iddata(CTID_EXAMPLES_DATA_DIR "/dryer.dat", {.inputs = {"1"}, .outputs = {"2"}, .ts = 0.08});
  const IdData dryer = raw.detrend(Detrend::Mean);
  const auto sr = srivc(dryer, {.nb = 2, .nf = 2, .nk = 2});
  const auto fs = fsf(dryer, {.T = 4.0, .n = 21});
  Eigen::VectorXd ud = Eigen::VectorXd::Zero(dryer.size());
  ud.tail(dryer.size() - 2) = dryer.u().col(0).head(dryer.size() - 2);
  const IdData delayed(ud, dryer.y(), 0.08);
  ModalOptions od{.shifts = Eigen::Vector2d(0.08, 0.16), .basis = ModalBasis::Discrete};
  od.windows = piecewise_constant_windows(delayed, 0.16);
  const auto md = modal_estimate(delayed, delayed.u(), od);
  const TimeResponse gd = modal_step_response(delayed, md.model, 0.08, 3.84);
  const auto mf = modal_fit(delayed, 2, {.shifts = Eigen::Vector2d(0.08, 0.16), .basis = ModalBasis::Discrete});
  std::printf("dryer: %zu constant-input windows; modal model %s (fit %.1f %%), srivc fit %.1f %%\n", od.windows.size(),
              mf.model.to_string(4).c_str(), mf.fit.fit_percent, sr.fit.fit_percent);
  std::printf("  t (s)   modal    srivc    fsf\n");
  double worst = 0;
  for (int k : {0, 2, 4, 6, 10, 20, 30, 46}) {
    const double tk = gd.t(k) + 0.16;  // the modal response is of the delayed input
    const Eigen::VectorXd tt{{tk}};
    const double s = step_response(sr.model, tt)(0), f = fs.model.step_response(tt)(0);
    std::printf("  %5.2f  %7.4f  %7.4f  %7.4f\n", tk, gd.value(k), s, f);
    worst = std::max(worst, std::abs(gd.value(k) - s));
  }
  ok = ok && worst < 0.05 && mf.fit.fit_percent > 80;
  return ok ? 0 : 1;
}
