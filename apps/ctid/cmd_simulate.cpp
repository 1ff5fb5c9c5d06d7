// ctid simulate MODEL.json DATA [--out OUT.csv] [--initial rest|measured|estimated] [--snr DB --seed N]: any
// result or model file ctid writes, simulated by simulate() (simulate/simulate.hpp).
#include <cmath>
#include <cstdio>
#include <functional>

#include "common.hpp"

namespace ctid::cli {

namespace {
struct SimArgs {
  std::string model;
  DataArgs data;
  std::string out;
  double snr = std::numeric_limits<double>::quiet_NaN();
  unsigned long long seed = 1;
  std::string initial;  // "": the library's default for a free run (simulate_options, SimulationPurpose::FreeRun)
  int initial_samples = 0;
  bool force = false;
};


int run(const SimArgs& a) {
  check_output_files({a.out}, {a.data.path, a.model}, a.force);
  const ResultFile f = read_result_file(a.model);
  // The record's output is read where the initial condition needs it (a fitted x0 does not).
  const SimulateOptions so = simulate_options_of(f.result, SimulationPurpose::FreeRun, a.initial, a.initial_samples);
  const bool reads_output = so.initial != InitialCondition::Rest && so.x0.size() == 0;
  const IdData d = [&] {
    try {
      return columns_of(a.data, f.result.model).load(reads_output);
    } catch (const ColumnSelectionError& e) {
      if (!reads_output) throw;
      throw ColumnSelectionError(std::string(e.what()) + "; --initial " + to_string(so.initial) +
                                 " reads the record's measured output to find the initial state: name its column "
                                 "with --output");
    }
  }();
  Eigen::MatrixXd y = simulate_result(f.result, d, SimulationPurpose::FreeRun, a.initial, a.initial_samples);
  std::vector<std::string> ynames;
  for (Eigen::Index j = 0; j < y.cols(); ++j) ynames.push_back(y.cols() == 1 ? "y" : "y" + std::to_string(j + 1));
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

void setup_simulate(CLI::App& app, Command& command) {
  auto a = std::make_shared<SimArgs>();
  app.add_option("MODEL", a->model, "Model JSON (a result file or a bare model)")->required();
  app.add_option("DATA", a->data.path, "Table with the input column(s) and a time axis")->required();
  a->data.add_to(app, true);  // --output: the record's output, read for --initial measured|estimated
  app.add_option("--out", a->out, "Write t, inputs and simulated outputs to this CSV (default: stdout)");
  app.add_option("--snr", a->snr, "Add white Gaussian noise at this signal-to-noise ratio (dB)")
      ->check(CLI::Validator(
          [](std::string& v) {
            double x = 0;
            try { x = std::stod(v); } catch (const std::exception&) {}  // not a number: the conversion says so
            return std::isfinite(x) ? std::string() : "--snr must be a finite number of dB (got " + v + ")";
          },
          "DB"));
  add_initial_option(app, a->initial, &a->initial_samples, "rest; a grey-box result: its fitted initial state");
  app.add_option("--seed", a->seed, "Seed of the noise")->capture_default_str();
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a, &command] {
    command = [a](Provenance& prov) {
      a->data.provenance = &prov;
      return run(*a);
    };
  });
}

}  // namespace ctid::cli
