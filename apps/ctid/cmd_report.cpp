// ctid report RESULT.json DATA --out REPORT.html: the HTML report of a result file (ctid fit --json) on a
// record — transfer-function results with their covariance, NARX and NDE model files (the fit statistics
// are recomputed on DATA).
#include <cstdio>
#include <functional>

#include <nlohmann/json.hpp>

#include "common.hpp"

namespace ctid::cli {
extern std::function<int()> g_run;

namespace {
struct ReportArgs {
  std::string result, out, title;
  DataArgs data;
  bool force = false;
};

// Parameters and fit of a model read without its result envelope.
template <class M>
Result<M> bare_result(const M& model, const IdData& d, const Eigen::VectorXd& yhat) {
  Result<M> r;
  r.model = model;
  r.parameters.values = model.coefficients();
  for (const auto& t : model.terms()) r.parameters.names.push_back(t.name());
  r.parameters.std = Eigen::VectorXd::Constant(r.parameters.values.size(), NAN);
  r.parameters.fixed.assign(model.terms().size(), false);
  r.fit = fit_report_or_inf(d.y().col(0), yhat, static_cast<int>(model.terms().size()));
  return r;
}

// A linear result file is reported as strictly as `ctid validate` scores it: its parameters and covariance must be
// sound (finite, of the right size, positive semi-definite, no zero standard deviation unless the fit was exact),
// else exit 3; a model that diverges on the record is not drawn (exit 1).
template <class R>
void check_linear_result(const R& r, const MisoModel& m, const IdData& d, const std::string& path) {
  FitReport f;  // only the rules about parameters and covariance (the record may be another one)
  if (r.fit.nrmse < 1e-6) {
    f.n_samples = 1;
    f.nrmse = r.fit.nrmse;
    f.fit_percent = 100;
  }
  if (const std::string why = usability_problem(Summary{}, r.parameters, f); !why.empty())
    throw InputError(path + ": " + why + " (its uncertainty bands would be meaningless)");
  if (d.nu() != m.nu())
    throw UsageError(detail::format("the model has {} inputs; {} inputs were selected", m.nu(), d.nu()));
  require_finite_simulation(lsim(m, d), d, unstable_poles(m));
}

int run(const ReportArgs& a) {
  if (a.out.empty()) throw UsageError("give the report file with --out REPORT.html");
  check_outputs({a.out}, {a.data.path, a.result}, a.force);
  std::string text;
  try {
    text = read_text_file(a.result);
  } catch (const FileError& e) {
    throw InputError(e.what());
  }
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(a.result + ": not JSON (" + e.what() + ")");
  }
  const nlohmann::json& model = j.contains("model") ? j["model"] : j;
  const std::string type = model.is_object() && model.contains("type") && model["type"].is_string()
                               ? model["type"].get<std::string>()
                               : "";
  const IdData d = a.data.load(true);
  if (d.ny() != 1 || (d.nu() != 1 && type != "miso"))
    throw UsageError("report needs one --input (one per model input for a miso result) and one --output");
  ReportOptions o;
  o.method = j.contains("method") && j["method"].is_string() ? j["method"].get<std::string>() : type;
  o.title = a.title.empty() ? "ctid report: " + a.result : a.title;
  o.data_source = a.data.path;
  std::string html;
  try {
    if (type == "transfer_function") {
      const Result<TransferFunction> r = parse_result_json(text, a.result);
      check_linear_result(r, MisoModel{{r.model}}, d, a.result);
      html = html_report(d, r, o);
    } else if (type == "miso") {
      const Result<MisoModel> r = parse_miso_result_json(text, a.result);
      check_linear_result(r, r.model, d, a.result);
      html = html_report(d, r, o);
    } else if (type == "narx") {
      const NarxModel m = parse_narx_json(text, a.result);
      const NarxModel p = m.process();
      const int L = std::min(p.max_lag(), d.size());
      html = html_report(d, bare_result(m, d, p.simulate(d.u().col(0), d.y().col(0).head(L))), o);
    } else if (type == "nde") {
      const NdeModel m = parse_nde_json(text, a.result);
      Eigen::VectorXd t(d.size());
      for (int i = 0; i < d.size(); ++i) t(i) = d.time(i) - d.t0();
      html = html_report(d, bare_result(m, d, m.simulate(d.u().col(0), t, d.intersample(0)).y), o);
    } else {
      throw UsageError(a.result + ": model type '" + type +
                       "' has no report here (transfer_function, miso, narx, nde; for FSF results use ctid fit --report)");
    }
  } catch (const FileError& e) {
    throw InputError(e.what());
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  try {
    write_text_file(a.out, html);
  } catch (const FileError& e) {
    throw InputError(e.what());
  }
  std::printf("wrote %s\n", a.out.c_str());
  return kOk;
}
}  // namespace

void setup_report(CLI::App& app) {
  auto a = std::make_shared<ReportArgs>();
  app.add_option("RESULT", a->result, "Result or model JSON (ctid fit --json)")->required();
  app.add_option("DATA", a->data.path, "The record to report on (CSV/.dat or .mat)")->required();
  a->data.add_to(app, true);
  app.add_option("--out", a->out, "The HTML file to write")->required();
  app.add_option("--title", a->title, "Report title");
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a] { g_run = [a] { return run(*a); }; });
}

}  // namespace ctid::cli
