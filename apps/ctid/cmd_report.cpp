// ctid report RESULT.json DATA --out REPORT.html [--initial ...]: the HTML report of any result or model file ctid
// writes (read_result_file) on a record; a bare model's fit statistics are computed on DATA.
#include <cstdio>
#include <functional>

#include "common.hpp"

namespace ctid::cli {

namespace {
struct ReportArgs {
  std::string result, out, title;
  std::vector<std::string> paths;  // several: experiments of one system, a section each
  DataArgs data;
  std::string initial;  // "": the initial condition of the result's own fit
  bool force = false;
};

// A result file with a parameter table is reported as strictly as `ctid validate` scores it: its parameters and
// covariance must be sound (finite, of the right size, positive semi-definite, no zero standard deviation unless
// the fit was exact), else exit 3; a model that diverges on the record is not drawn (exit 1). Returns the simulated
// output on d.
Eigen::MatrixXd check_result(const ResultFile& file, const IdData& d, const std::string& initial, const std::string& path) {
  if (!file.bare) {
    FitReport f;  // only the rules about parameters and covariance (the record may be another one)
    if (file.result.fit.nrmse < 1e-6) {
      f.n_samples = 1;
      f.nrmse = file.result.fit.nrmse;
      f.fit_percent = 100;
    }
    if (const std::string why = usability_problem(Summary{}, file.result.parameters, f); !why.empty())
      throw InputError(path + ": " + why + " (its uncertainty bands would be meaningless)");
  }
  return simulate_result(file.result, d, SimulationPurpose::OwnFit, initial);
}

int run(const ReportArgs& a) {
  if (a.out.empty()) throw UsageError("give the report file with --out REPORT.html");
  std::vector<std::string> inputs = a.paths;
  inputs.push_back(a.result);
  check_output_files({a.out}, inputs, a.force);
  ResultFile file = read_result_file(a.result);
  const std::vector<IdData> ds = columns_of(a.data, file.result.model).load_each(a.paths, true);
  const IdData& d = ds.front();
  const int nu = model_inputs(file.result.model), ny = model_outputs(file.result.model);
  if (d.ny() != ny || d.nu() != nu)
    throw UsageError(detail::format("report needs one --input per model input and one --output per model output (the {} "
                                    "model has {} input(s) and {} output(s); selected {} and {})",
                                    model_type_name(file.result.model), nu, ny, d.nu(), d.ny()));
  const Eigen::MatrixXd yhat = check_result(file, d, a.initial, a.result);
  // A bare model's fit is the one on this record (several outputs: each output's fit is in its section).
  if (file.bare && ny == 1)
    file.result.fit = fit_report_or_inf(d.y().col(0), yhat.col(0), model_coefficient_count(file.result.model));
  ReportOptions o;
  o.method = file.method.empty() ? model_type_name(file.result.model) : file.method;
  o.title = a.title.empty() ? "ctid report: " + a.result : a.title;
  o.data_source = a.paths.front();
  if (a.data.provenance) o.provenance = *a.data.provenance;
  for (std::size_t e = 1; e < ds.size(); ++e) {
    // Further records start as the fit starts a record (a fitted x0 belongs to the first record).
    simulate_result(file.result, ds[e], SimulationPurpose::OtherRecord, a.initial);
    o.more_records.emplace_back(a.paths[e], ds[e]);
  }
  if (!a.initial.empty()) o.initial = initial_condition_from_string(a.initial);
  const std::string html = html_report(d, file.result, o);
  write_text_file(a.out, html);
  std::printf("wrote %s\n", a.out.c_str());
  return kOk;
}
}  // namespace

void setup_report(CLI::App& app, Command& command) {
  auto a = std::make_shared<ReportArgs>();
  app.add_option("RESULT", a->result, "Result or model JSON (ctid fit --json)")->required();
  app.add_option("DATA", a->paths, "The record(s) to report on (CSV/.dat or .mat; several: a section each)")->required();
  a->data.add_to(app, true);
  app.add_option("--out", a->out, "The HTML file to write")->required();
  app.add_option("--title", a->title, "Report title");
  add_initial_option(app, a->initial);
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a, &command] {
    command = [a](Provenance& prov) {
      a->data.provenance = &prov;
      return run(*a);
    };
  });
}

}  // namespace ctid::cli
