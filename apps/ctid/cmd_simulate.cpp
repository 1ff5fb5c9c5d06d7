// ctid simulate MODEL.json DATA [--out OUT.csv] [--snr DB --seed N]: linear models exactly, NARX models at their
// sampling period, NDE models by the adaptive integrator at the data's times.
#include <cstdio>
#include <functional>
#include <optional>

#include "common.hpp"

namespace ctid::cli {
extern std::function<int()> g_run;

namespace {
struct SimArgs {
  std::string model;
  DataArgs data;
  std::string out;
  double snr = std::numeric_limits<double>::quiet_NaN();
  unsigned long long seed = 1;
  bool force = false;
};


int run(const SimArgs& a) {
  check_outputs({a.out}, {a.data.path, a.model}, a.force);
  const IdData d = a.data.load(false);
  Eigen::MatrixXd y;
  std::vector<std::string> ynames;
  LinearModel m;
  bool nonlinear = false;
  try {
    m = read_model_json(a.model);
  } catch (const FileError& e) {
    const std::optional<NonlinearModel> nl = read_nonlinear_model(a.model);
    if (!nl) throw InputError(e.what());
    y = simulate_nonlinear(*nl, d, a.model);
    nonlinear = true;
    ynames = {"y"};
  }
  if (nonlinear) {
    // simulated by simulate_nonlinear
  } else if (const auto* tf = std::get_if<TransferFunction>(&m)) {
    if (d.nu() != 1) throw UsageError(detail::format("the transfer function has 1 input but {} input columns were selected", d.nu()));
    y = lsim(*tf, d, 0);
    require_finite_simulation(y, d, unstable_poles(MisoModel{{*tf}}));
    ynames = {"y"};
  } else if (const auto* mm = std::get_if<MisoModel>(&m)) {
    if (d.nu() != mm->nu())
      throw UsageError(detail::format("the model has {} inputs but {} input columns were selected", mm->nu(), d.nu()));
    y = lsim(*mm, d);
    require_finite_simulation(y, d, unstable_poles(*mm));
    ynames = {"y"};
  } else {
    const auto& ss = std::get<StateSpace>(m);
    if (d.nu() != ss.nu())
      throw UsageError(detail::format("the model has {} inputs but {} input columns were selected", ss.nu(), d.nu()));
    y = lsim(ss, d);
    require_finite_simulation(y, d, "");
    for (int j = 0; j < ss.ny(); ++j) ynames.push_back("y" + std::to_string(j + 1));
  }
  if (!std::isnan(a.snr)) {
    for (Eigen::Index j = 0; j < y.cols(); ++j) y.col(j) = add_noise_snr(y.col(j), a.snr, a.seed + static_cast<unsigned long long>(j));
  }
  Eigen::MatrixXd table(d.size(), 1 + d.nu() + y.cols());
  table.col(0) = d.times();
  table.middleCols(1, d.nu()) = d.u();
  table.rightCols(y.cols()) = y;
  std::vector<std::string> names{"t"};
  for (const auto& n : d.input_names()) names.push_back(n);
  for (const auto& n : ynames) names.push_back(n);
  if (a.out.empty()) {
    for (std::size_t i = 0; i < names.size(); ++i) std::printf("%s%s", i ? "," : "", names[i].c_str());
    std::printf("\n");
    for (Eigen::Index r = 0; r < table.rows(); ++r) {
      for (Eigen::Index c = 0; c < table.cols(); ++c) std::printf("%s%.17g", c ? "," : "", table(r, c));
      std::printf("\n");
    }
  } else {
    write_csv(a.out, names, table);
    std::printf("wrote %s (%d samples)\n", a.out.c_str(), d.size());
  }
  return kOk;
}
}  // namespace

void setup_simulate(CLI::App& app) {
  auto a = std::make_shared<SimArgs>();
  app.add_option("MODEL", a->model, "Model JSON (a result file or a bare model)")->required();
  app.add_option("DATA", a->data.path, "Table with the input column(s) and a time axis")->required();
  a->data.add_to(app, false);
  app.add_option("--out", a->out, "Write t, inputs and simulated outputs to this CSV (default: stdout)");
  app.add_option("--snr", a->snr, "Add white Gaussian noise at this signal-to-noise ratio (dB)");
  app.add_option("--seed", a->seed, "Seed of the noise")->capture_default_str();
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a] { g_run = [a] { return run(*a); }; });
}

}  // namespace ctid::cli
