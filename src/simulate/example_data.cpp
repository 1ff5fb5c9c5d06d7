// ctid — simulated example records for the README and docs/ (every documented command runs verbatim).
// The systems are the source documents' and the tests' own: Gawthrop & Wang's unstable circuit under PD control
// (Gawthrop & Wang 2005, §5, simulated), El-Shafey's S3 and S4 (ES Tables 3.1, 4.8), Billings & Li's system (33), the Rao-Garnier
// fourth-order benchmark; inputs and noise are seeded, so every record is the same on every machine.
#include "ctid/simulate/example_data.hpp"

#include <cmath>
#include <complex>
#include <cstdint>

#include "ctid/core/check.hpp"
#include "ctid/core/names.hpp"
#include "ctid/data/input_design.hpp"
#include "ctid/model/greybox.hpp"
#include "ctid/model/modal.hpp"
#include "ctid/model/nde.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/model/transfer_function.hpp"
#include "ctid/simulate/closed_loop.hpp"
#include "ctid/simulate/lsim.hpp"

namespace ctid {
namespace {

const TransferFunction kS3(Eigen::VectorXd{{13.0, 52.0}}, Eigen::VectorXd{{1.0, 4.0, 30.0, 52.0}});
const TransferFunction kS4(Eigen::VectorXd{{400.0, 400.0}}, Eigen::VectorXd{{1.0, 6.0, 115.25, 221.0, 338.0}});
const TransferFunction kRaoGarnier(Eigen::VectorXd{{-6400.0, 1600.0}},
                                   Eigen::VectorXd{{1.0, 5.0, 408.0, 416.0, 1600.0}});
const TransferFunction kSecond(Eigen::VectorXd{{1.0, 3.0}}, Eigen::VectorXd{{1.0, 1.2, 4.0}});

Eigen::MatrixXd columns(std::initializer_list<Eigen::VectorXd> cols) {
  Eigen::MatrixXd m(cols.begin()->size(), static_cast<Eigen::Index>(cols.size()));
  Eigen::Index j = 0;
  for (const auto& c : cols) m.col(j++) = c;
  return m;
}

Eigen::VectorXd delayed(const Eigen::VectorXd& u, int k) {
  Eigen::VectorXd d = Eigen::VectorXd::Zero(u.size());
  d.tail(u.size() - k) = u.head(u.size() - k);
  return d;
}

ExampleData circuit() {
  // 1/(s^2 - 1) under the digital PD controller u = 3 (w - y - d), d the filtered derivative of the measured y, w a
  // +-0.5 square wave of period 4.5 s; Ts = 0.01 s, 4000 samples; measurement noise std 0.01 (inside the loop).
  const double Ts = 0.01;
  const int M = 4000;
  Eigen::VectorXd w(M);
  for (int i = 0; i < M; ++i) w(i) = (i / 150) % 3 == 0 ? 0.5 : -0.5;
  const IdData loop = simulate_closed_loop(TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 0.0, -1.0}}),
                                           RstController::pid(3.0, 0.0, 3.0, 0.1, Ts), w, Ts, white_noise(M, 0.01, 17));
  const Eigen::MatrixXd m = columns({time_grid(Ts, M), loop.u().col(0), loop.y().col(0)});
  return {"circuit",
          "Gawthrop & Wang's unstable circuit k1/(s^2 - k2), k1 = k2 = 1, under digital PD control (Gawthrop & Wang 2005, §5, simulated); "
          "Ts = 0.01 s, 4000 samples, measurement noise std 0.01 inside the loop",
          {"t", "u", "y"}, m};
}

ExampleData free_response() {
  const double Ts = 0.0075;
  const Eigen::VectorXd t = time_grid(Ts, 600);
  return {"free",
          "El-Shafey's S4 = 400 (s + 1)/(s^4 + 6 s^3 + 115.25 s^2 + 221 s + 338) released from y = 0.2, Dy = 10 "
          "(ES Ex. 4.6), free response, Ts = 0.0075 s, 600 samples, noise-free",
          {"y"},
          columns({lsim(phase_variable_form(kS4), InputGenerator::constant(0.0), t, Eigen::Vector4d(0.2, 10.0, 0, 0))})};
}

ExampleData forced() {
  const double Ts = 0.0098;
  const Eigen::VectorXd t = time_grid(Ts, 800);
  return {"forced",
          "El-Shafey's S3 = (13 s + 52)/(s^3 + 4 s^2 + 30 s + 52) from rest driven by sin 4t (ES Ex. 4.7), output "
          "only, Ts = 0.0098 s, 800 samples, noise-free",
          {"y"},
          columns({lsim(kS3.to_state_space(), InputGenerator::sinusoid(4.0, 1.0), t)})};
}

ExampleData steps() {
  const double Ts = 0.0098;
  const int N = 1280;
  Eigen::VectorXd u(N);
  const double levels[4] = {1, 2, -1, -2};
  for (int i = 0; i < N; ++i) u(i) = levels[(i / 80) % 4];
  return {"steps",
          "El-Shafey's S3 = (13 s + 52)/(s^3 + 4 s^2 + 30 s + 52) from rest, input levels 1, 2, -1, -2 held 80 "
          "samples each (repeated), Ts = 0.0098 s, 1280 samples, noise-free",
          {"u", "y"}, columns({u, lsim(kS3, u, time_grid(Ts, N))})};
}

ExampleData sines() {
  const double Ts = 0.0075;
  const InputGenerator g = InputGenerator::sinusoid(4.0, 1.0) + InputGenerator::sinusoid(1.5, 0.0, 0.7);
  const Eigen::VectorXd t = time_grid(Ts, 1500);
  return {"sines",
          "El-Shafey's S3 = (13 s + 52)/(s^3 + 4 s^2 + 30 s + 52) from rest driven by sin 4t + 0.7 cos 1.5t, "
          "Ts = 0.0075 s, 1500 samples, noise-free",
          {"u", "y"}, columns({g(t), lsim(kS3.to_state_space(), g, t)})};
}

ExampleData billings_li() {
  std::vector<NdeTerm> terms;
  for (const char* s : {"y", "Dy", "D^2y", "u", "y^2", "y*Dy"}) terms.push_back(NdeTerm::parse(s));
  const NdeModel truth(terms, Eigen::VectorXd{{1, 0.002, 1e-4, -1, 0.1, -0.006}});
  const int N = 1000;
  Eigen::VectorXd u(N);
  for (int i = 0; i < N; ++i) u(i) = ((i * 7919 + i / 3) % 5) < 2 ? 1.0 : -1.0;  // the CLI test's +-1 sequence
  const Eigen::VectorXd y = truth.simulate(u, time_grid(0.0025, N), Intersample::Zoh, {}, 1e-11).y;
  return {"bl",
          "Billings & Li's system (33): y + 0.002 Dy + 1e-4 D^2y - u + 0.1 y^2 - 0.006 y Dy = 0, deterministic +-1 input "
          "(40 % at +1) held over Ts = 0.0025 s, 1000 samples, noise-free",
          {"u", "y"}, columns({u, y})};
}

// A PRBS record (t, u, y) of `g` with white output noise at 20 dB SNR.
ExampleData prbs_record(const char* name, const std::string& system, const TransferFunction& g, double Ts, int N,
                        int register_length, std::uint64_t noise_seed) {
  const Eigen::VectorXd u = prbs(N, {.register_length = register_length, .clock_period = 4});
  const Eigen::VectorXd t = time_grid(Ts, N);
  return {name,
          detail::format("{}, PRBS input ({}-bit register, 4 samples per bit), Ts = {} s, {} samples, white output noise "
                         "at 20 dB SNR",
                         system, register_length, Ts, N),
          {"t", "u", "y"}, columns({t, u, add_noise_snr(lsim(g, u, t), 20.0, noise_seed)})};
}

ExampleData rao_garnier() {
  return prbs_record("data",
                     "The Rao-Garnier benchmark (-6400 s + 1600)/(s^4 + 5 s^3 + 408 s^2 + 416 s + 1600)",
                     kRaoGarnier, 0.01, 4000, 10, 5);
}

ExampleData second_order() {
  return prbs_record("second", "(s + 3)/(s^2 + 1.2 s + 4)", kSecond, 0.05, 2000, 9, 6);
}

ExampleData miso() {
  const double Ts = 0.05;
  const int N = 3000;
  const Eigen::VectorXd t = time_grid(Ts, N);
  const Eigen::VectorXd u1 = random_binary(N, 11, 5), u2 = random_binary(N, 12, 5);
  const TransferFunction g1(Eigen::VectorXd{{5.0}}, Eigen::VectorXd{{1.0, 2.0, 5.0}});
  const TransferFunction g2(Eigen::VectorXd{{2.0}}, Eigen::VectorXd{{1.0, 3.0, 2.0}});
  const Eigen::VectorXd y = lsim(g1, delayed(u1, 3), t) + lsim(g2, delayed(u2, 5), t);
  return {"miso",
          "y = 5/(s^2 + 2 s + 5) u1 delayed 3 samples + 2/(s^2 + 3 s + 2) u2 delayed 5 samples, random binary inputs "
          "(5 samples per bit), Ts = 0.05 s, 3000 samples, white output noise at 20 dB SNR",
          {"t", "u1", "u2", "y"}, columns({t, u1, u2, add_noise_snr(y, 20.0, 13)})};
}

ExampleData closed_loop() {
  // Plant G = B/A = (s + 3)/(s^2 + 1.2 s + 4) under the PI controller C = Nc/Dc = (10 s + 15)/s, the reference added at
  // the plant input (u = r - C y_measured), y_measured = G u + v: with P = A Dc + B Nc,
  // y = (B Dc r + A Dc v)/P and u = (A Dc r - A Nc v)/P, r and v held over each sample.
  const double Ts = 0.05;
  const int N = 4000;
  const Eigen::VectorXd t = time_grid(Ts, N);
  const Eigen::VectorXd r = prbs(N, {.register_length = 10, .clock_period = 6});
  const Eigen::VectorXd v = white_noise(N, 0.02, 21);
  const Polynomial A = kSecond.den(), B = kSecond.num(), Nc{10.0, 15.0}, Dc{1.0, 0.0};
  const Polynomial P = A * Dc + B * Nc;
  const Eigen::VectorXd y = lsim(TransferFunction(B * Dc, P), r, t) + lsim(TransferFunction(A * Dc, P), v, t);
  const Eigen::VectorXd u = lsim(TransferFunction(A * Dc, P), r, t) - lsim(TransferFunction(A * Nc, P), v, t);
  return {"loop",
          "Closed loop: plant (s + 3)/(s^2 + 1.2 s + 4) under the PI controller (10 s + 15)/s, reference r (PRBS, "
          "10-bit register, 6 samples per bit) added at the plant input, u = r - C y; measurement noise std 0.02 "
          "inside the loop; Ts = 0.05 s, 4000 samples",
          {"t", "r", "u", "y"}, columns({t, r, u, y})};
}

ExampleData frequency() {
  const int N = 300;
  const Eigen::VectorXd w = Eigen::VectorXd::LinSpaced(N, -1.0, 2.0).unaryExpr([](double e) { return std::pow(10.0, e); });
  const Eigen::VectorXd n1 = white_noise(N, 0.01, 31), n2 = white_noise(N, 0.01, 32);
  Eigen::VectorXd re(N), im(N);
  for (int k = 0; k < N; ++k) {
    const std::complex<double> g = kRaoGarnier(std::complex<double>(0.0, w(k))) * std::complex<double>(1 + n1(k), n2(k));
    re(k) = g.real();
    im(k) = g.imag();
  }
  return {"freq",
          "Frequency response of the Rao-Garnier benchmark (-6400 s + 1600)/(s^4 + 5 s^3 + 408 s^2 + 416 s + 1600) "
          "at 300 log-spaced frequencies from 0.1 to 100 rad/s, relative complex noise std 1 %",
          {"w", "re", "im"}, columns({w, re, im})};
}

ExampleData mimo() {
  // Two lightly damped modes (wn = 2 rad/s, zeta = 0.05; wn = 5 rad/s, zeta = 0.1) seen by two outputs.
  Eigen::MatrixXd Am = Eigen::MatrixXd::Zero(4, 4);
  Am.block(0, 0, 2, 2) << 0, 1, -4, -0.2;
  Am.block(2, 2, 2, 2) << 0, 1, -25, -1;
  Eigen::MatrixXd Bm(4, 2), Cm(2, 4);
  Bm << 0, 0, 1, 0.5, 0, 0, 0.4, 1;
  Cm << 1, 0, 0.5, 0, 0.3, 0, 1, 0;
  const StateSpace sys(Am, Bm, Cm, Eigen::MatrixXd::Zero(2, 2));
  const double Ts = 0.05;
  const int N = 4000;
  Eigen::MatrixXd u(N, 2);
  u << random_binary(N, 41, 4), random_binary(N, 42, 4);
  const Eigen::MatrixXd y =
      lsim(sys, u, time_grid(Ts, N), {Intersample::Zoh, Intersample::Zoh});
  return {"mimo",
          "Two inputs, two outputs, two modes (wn = 2 rad/s, zeta = 0.05; wn = 5 rad/s, zeta = 0.1), no feedthrough; "
          "random binary inputs (4 samples per bit), Ts = 0.05 s, 4000 samples, white output noise std 0.01",
          {"u1", "u2", "y1", "y2"},
          columns({u.col(0), u.col(1), Eigen::VectorXd(y.col(0) + white_noise(N, 0.01, 43)),
                   Eigen::VectorXd(y.col(1) + white_noise(N, 0.01, 44))})};
}

// docs/methods/greybox.md's mass on a spring with viscous and Coulomb-like friction, the model file
// examples/data/spring_greybox.json: dq/dt = v, dv/dt = (force - k q - c v - fc tanh(v/0.05))/m with the truth
// k = 2.5, c = 0.3, fc = 0.2, m = 1. The force steps every second to a level in [-3, 3] (a deterministic sequence per
// record), Ts = 0.01 s, 1500 samples, the position with white noise of standard deviation 0.005; records differ in
// their force sequence, initial position and noise.
ExampleData spring(const char* name, double phase, double q0, std::uint64_t noise_seed) {
  GreyboxSpec s;
  s.inputs = {"force"};
  s.states = {"q", "v"};
  s.outputs = {{"position", "q"}};
  s.parameters = {{"k", 2.5}, {"c", 0.3}, {"fc", 0.2}, {"m", 1.0}};
  s.equations = {"v", "(force - k*q - c*v - fc*tanh(v/0.05))/m"};
  s.initial = {{}, {}};
  const GreyboxModel truth(s);
  const int N = 1500;
  const double Ts = 0.01;
  const Eigen::VectorXd t = time_grid(Ts, N);
  Eigen::MatrixXd force(N, 1);
  for (int k = 0; k < N; ++k) force(k, 0) = 3.0 * std::sin(phase + 2.399963 * (k / 100));  // golden-angle steps
  const GreyboxSimulation sim = truth.simulate(force, t, Intersample::Zoh, Eigen::Vector2d(q0, 0.0), 1e-10);
  CTID_REQUIRE(sim.ok(), "example_data: the spring record did not simulate: {}", sim.message);
  return {name,
          detail::format("The mass-spring with friction of docs/methods/greybox.md (examples/data/spring_greybox.json) "
                         "with k = 2.5, c = 0.3, fc = 0.2, m = 1, q(0) = {}, v(0) = 0: force steps every 1 s, Ts = 0.01 s, "
                         "1500 samples, position noise std 0.005",
                         q0),
          {"t", "force", "position"},
          columns({t, force.col(0), Eigen::VectorXd(sim.y.col(0) + white_noise(N, 0.005, noise_seed))})};
}

// docs/methods/greybox.md's magnetic levitation (python/examples/greybox_levitation.py): a steel ball under an
// electromagnet, dy/dt = v, dv/dt = g - k i^2/y^2 - c v with k = 1e-4, c = 2, g = 9.81 (unstable in open loop: pole
// +44 1/s at a 1 cm gap), recorded under the PD loop i = 3.132092 + 600 (y - r) + 9 v around the reference
// r = 0.01 + 0.0015 sin(2 pi 0.7 t) + 0.001 sin(2 pi 2.3 t) m; Ts = 1 ms, 3000 samples, the current (a continuous
// signal: first-order hold) and the gap with white noise of 10 um. The open-loop plant is
// examples/data/levitation_greybox.json.
ExampleData levitation() {
  GreyboxSpec s;
  s.inputs = {"r"};
  s.states = {"y", "v"};
  s.outputs = {{"y", "y"}, {"i", "3.132092 + 600*(y - r) + 9*v"}};
  s.parameters = {{"k", 1e-4}, {"c", 2.0}, {"g", 9.81}};
  s.equations = {"v", "g - k*(3.132092 + 600*(y - r) + 9*v)^2/y^2 - c*v"};
  s.initial = {{"0.01"}, {}};
  const GreyboxModel loop(s);
  const int N = 3000;
  const Eigen::VectorXd t = time_grid(0.001, N);
  const double pi = 3.141592653589793;
  const Eigen::MatrixXd r = (0.01 + 0.0015 * (2 * pi * 0.7 * t.array()).sin() + 0.001 * (2 * pi * 2.3 * t.array()).sin()).matrix();
  const GreyboxSimulation sim = loop.simulate(r, t, Intersample::Foh, Eigen::Vector2d(0.01, 0.0), 1e-11);
  CTID_REQUIRE(sim.ok(), "example_data: the levitation record did not simulate: {}", sim.message);
  return {"levitation",
          "The magnetic levitation of docs/methods/greybox.md: dv/dt = g - k i^2/y^2 - c v with k = 1e-4, c = 2, g = 9.81, "
          "under the PD loop i = 3.132092 + 600 (y - r) + 9 v, r two sines around 1 cm; Ts = 0.001 s, 3000 samples, the "
          "current i (first-order hold) and the gap y (m) with noise std 1e-5",
          {"t", "i", "y"},
          columns({t, sim.y.col(1), Eigen::VectorXd(sim.y.col(0) + white_noise(N, 1e-5, 61))})};
}

struct Entry {
  const char* name;
  ExampleData (*make)();
};
constexpr Entry kEntries[] = {{"data", rao_garnier}, {"second", second_order}, {"miso", miso},   {"loop", closed_loop},
                              {"freq", frequency},   {"mimo", mimo},           {"circuit", circuit}, {"steps", steps},
                              {"sines", sines},      {"free", free_response},  {"forced", forced}, {"bl", billings_li},
                              {"spring", [] { return spring("spring", 0.0, 0.4, 51); }},
                              {"spring-b", [] { return spring("spring-b", 1.0, -0.3, 52); }},
                              {"spring-test", [] { return spring("spring-test", 2.0, 0.2, 53); }},
                              {"levitation", levitation}};

}  // namespace

std::vector<std::string> example_data_names() {
  std::vector<std::string> names;
  for (const Entry& e : kEntries) names.emplace_back(e.name);
  return names;
}

ExampleData example_data(const std::string& name) {
  for (const Entry& e : kEntries)
    if (name == e.name) return e.make();
  const std::vector<std::string> names = example_data_names();
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  const std::string near = closest_name(name, names);
  CTID_REQUIRE(false, "example_data: no example record '{}'{} (known: {})", name,
               near.empty() ? std::string() : "; did you mean '" + near + "'?", list);
  return {};
}

}  // namespace ctid
