// The example of docs/methods/billings-li.md, run by ctest: simulate the Billings & Li system (33) with a
// +-1 input held at 400 Hz with 20 dB output noise, identify a NARMAX model by FROLS, print the selected terms
// with their ERR, reconstruct the continuous-time equation by the Kernel Invariance Algorithm and refine its
// coefficients by output error.
#include <cmath>
#include <cstdio>
#include <random>

#include <ctid/ctid.hpp>

int main() {
  using namespace ctid;
  std::vector<NdeTerm> terms;
  for (const char* s : {"y", "Dy", "D^2y", "u", "y^2", "y*Dy"}) terms.push_back(NdeTerm::parse(s));
  const NdeModel truth(terms, (Eigen::VectorXd(6) << 1, 0.002, 1e-4, -1, 0.1, -0.006).finished());
  const int N = 1000;
  const double T = 0.0025;
  std::mt19937 rng(11);
  std::bernoulli_distribution coin(0.5);
  Eigen::VectorXd u(N);
  for (int i = 0; i < N; ++i) u(i) = coin(rng) ? 1.0 : -1.0;
  const NdeSimulation sim = truth.simulate(u, time_grid(T, N), Intersample::Zoh, {}, 1e-11);
  const IdData data(u, add_noise_snr(sim.y, 20.0, 7), T);

  const auto narx = narmax(data, narx_candidates(2, 6, 6), {.frols = {.max_terms = 20, .criterion = InformationCriterion::Aic}});
  std::printf("NARMAX: %d terms, free-run fit %.2f %%\n", narx.parameters.size(), narx.fit.fit_percent);
  for (int i = 0; i < 5; ++i)
    std::printf("  %-16s %10.5f  ERR %6.3f %%\n", narx.parameters.names[i].c_str(), narx.parameters.values(i),
                narx.diagnostics.get(diagnostic::err)(i));
  const NarxModel process = narx.model.process();  // drop the noise terms
  const auto lin = kia_linear(process, {.y_order = 2, .u_order = 0});
  const auto kia = kia_quadratic(process, lin.model, {.candidates = {NdeTerm::parse("y^2"), NdeTerm::parse("y*Dy")}});
  const auto refined = nde_oe(data, kia.model);
  std::printf("true:    %s\nKIA:     %s\nrefined: %s\n", truth.to_string(4).c_str(),
              kia.model.normalized().to_string(4).c_str(), refined.model.to_string(4).c_str());
  double worst = 0;
  for (const char* s : {"Dy", "D^2y", "u", "y^2", "y*Dy"})
    worst = std::max(worst, std::abs(refined.model.coefficient(s) / truth.coefficient(s) - 1));
  std::printf("largest relative coefficient error after refinement: %.2f %%\n", 100 * worst);
  return worst < 0.10 ? 0 : 1;
}
