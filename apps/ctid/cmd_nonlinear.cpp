// ctid — Billings & Li: `ctid fit --method narx|kia` and `ctid gfrf` (NARX/NARMAX by FROLS, the Kernel
// Invariance Algorithm, generalised frequency response functions).
#include <cmath>
#include <cstdio>
#include <algorithm>
#include <functional>
#include <sstream>

#include "common.hpp"

namespace ctid::cli {
extern std::function<int()> g_run;

namespace {
void print_narx(const Result<NarxModel>& r) {
  if (batch_outcome()) return;
  std::printf("selected terms (in order of selection) with their error reduction ratio:\n");
  const Eigen::VectorXd& err = r.diagnostics.get(diagnostic::err);
  for (int i = 0; i < r.parameters.size(); ++i)
    std::printf("  %-22s %14.6g +- %-11.3g ERR %8.4f %%\n", r.parameters.names[i].c_str(), r.parameters.values(i),
                r.parameters.std(i), i < err.size() ? err(i) : NAN);
  std::printf("1 - sum(ERR) = %.3g   free-run fit %s %%\n", r.diagnostics.get(diagnostic::esr),
              fit_percent_text(r.fit.fit_percent).c_str());
}
}  // namespace

// The library's NARX workflow (narx()) with the settings of its table, on one record or several.
Result<NarxModel> run_narx(const std::vector<IdData>& ds, const NarxOptions& o) {
  try {
    o.validate();
    if (!batch_outcome())
      std::printf("candidates: %zu (degree %d, ylag %d, ulag %d)\n",
                narx_candidates(o.degree, o.ylag, o.ulag, o.constant, o.umin).size(), o.degree, o.ylag, o.ulag);
    return narx(ds, o);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
}

int run_narx_or_kia(const std::string& method, const std::vector<IdData>& ds, const std::vector<std::string>& set_list,
                    const std::string& narx_file, const std::string& json, const std::string& report,
                    const std::vector<std::pair<std::string, IdData>>& more_records) {
  const IdData& d = ds.front();
  if (d.nu() != 1 || d.ny() != 1) throw UsageError(method + " needs one --input and one --output");
  NarxOptions no;
  if (method == "narx") {
    apply_sets("narx", set_list, no);
    const Result<NarxModel> r = run_narx(ds, no);
    if (BatchOutcome* b = batch_outcome()) {
      b->result = to_any(r);
      b->method = "narx";
      return r.usable() ? kOk : kNotUsable;
    }
    print_narx(r);
    if (!json.empty()) {
      write_result_json(json, r, "narx");
      std::printf("wrote %s\n", json.c_str());
    }
    write_report(report, d, r, "narx", settings_of(no), "", more_records);
    return r.usable() ? kOk : kNotUsable;
  }
  // kia: the NARX model from --narx, or identified here with the narx settings; then the library's workflow (kia()).
  KiaOptions ko;
  ko.linear.zoh = ko.quadratic.zoh = ko.cubic.zoh = d.intersample(0) == Intersample::Zoh;
  if (narx_file.empty()) apply_sets("kia", set_list, ko, no);
  else apply_sets("kia", set_list, ko);
  NarxModel narx;
  if (!narx_file.empty()) {
    const AnyModel m = read_result(narx_file).result.model;
    if (!std::holds_alternative<NarxModel>(m))
      throw InputError(narx_file + ": --narx needs a NARX model; this is a " + model_type_name(m) + " model");
    narx = std::get<NarxModel>(m).process();
  } else {
    const Result<NarxModel> r = run_narx(ds, no);
    print_narx(r);
    narx = r.model.process();
  }
  KiaRun run;
  try {
    run = kia(ds, narx, ko);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  if (BatchOutcome* b = batch_outcome()) {
    b->result = to_any(run.result());
    b->method = ko.refine ? "kia+oe" : "kia";
    return run.result().usable() ? kOk : kNotUsable;
  }
  const Result<NdeModel>& k = run.reconstructed;
  for (const auto& c : k.diagnostics.choices) std::printf("chosen: %s\n", c.c_str());
  std::printf("NDE: %s\n", k.model.to_string(5).c_str());
  const Eigen::VectorXd& err = k.diagnostics.get(diagnostic::err);
  for (int i = 0; i < k.parameters.size(); ++i)
    std::printf("  %-10s %14.6g   ERR %8.4f %%\n", k.parameters.names[i].c_str(), k.parameters.values(i), err(i));
  std::printf("simulated output fit: %s %%   (hold factor %s)\n", fit_percent_text(k.fit.fit_percent).c_str(), ko.linear.zoh ? "on" : "off");
  std::printf("NARX model's free-run fit on the same record%s: %s %%\n", ds.size() > 1 ? "s" : "",
              fit_percent_text(run.narx_fit_percent).c_str());
  if (run.refined && run.refined->usable()) {
    const Result<NdeModel>& oe = *run.refined;
    std::printf("refined by output error (%d iterations): %s\n", oe.summary.iterations, oe.model.to_string(5).c_str());
    for (int i = 0; i < oe.parameters.size(); ++i)
      std::printf("  %-10s %14.6g +- %.3g%s\n", oe.parameters.names[i].c_str(), oe.parameters.values(i),
                  oe.parameters.std(i), oe.parameters.fixed[static_cast<size_t>(i)] ? "  (reference)" : "");
    for (const auto& w : oe.diagnostics.warnings) std::printf("  note: %s\n", w.c_str());
    std::printf("simulated output fit: %s %%\n", fit_percent_text(oe.fit.fit_percent).c_str());
  } else if (run.refined) {
    std::fprintf(stderr, "ctid: warning: the output-error refinement failed (%s); keeping the KIA model\n",
                 run.refined->why_not_usable().c_str());
  }
  const Result<NdeModel>& r = run.result();
  if (!json.empty()) {
    write_result_json(json, r, "kia");
    std::printf("wrote %s\n", json.c_str());
  }
  Settings settings = settings_of(ko);
  if (narx_file.empty())
    for (auto& x : settings_of(no)) settings.push_back(x);
  write_report(report, d, r, ko.refine ? "kia+oe" : "kia", settings, narx_file, more_records);
  if (!r.usable()) {
    std::fprintf(stderr, "ctid: the estimate is not usable: %s\n", r.why_not_usable().c_str());
    return kNotUsable;
  }
  return kOk;
}

namespace {
struct GfrfArgs {
  std::string model, out, points, json;
  int order = 1;
  std::vector<double> w;
  bool real = false, no_zoh = false, force = false;
};

int run_gfrf(const GfrfArgs& a) {
  check_outputs({a.out, a.json}, {a.model, a.points}, a.force);
  if (a.order < 1 || a.order > 3) throw UsageError(detail::format("--order must be 1, 2 or 3 (got {})", a.order));
  if (a.w.empty() == a.points.empty())
    throw UsageError("give either the frequencies with --w w1,w2,.. (rad/s) or the points with --points FILE");
  std::function<Complex(const std::vector<Complex>&)> kernel;
  std::string kind;
  const AnyModel model = read_result(a.model).result.model;
  if (const auto* narx = std::get_if<NarxModel>(&model)) {
    kernel = [m = narx->process(), zoh = !a.no_zoh](const std::vector<Complex>& s) { return narx_gfrf_ct(m, s, zoh); };
    kind = "narx";
  } else if (const auto* nde = std::get_if<NdeModel>(&model)) {
    kernel = [m = *nde](const std::vector<Complex>& s) {
      return s.size() == 1 ? m.h1(s[0]) : s.size() == 2 ? m.h2(s[0], s[1]) : m.h3(s[0], s[1], s[2]);
    };
    kind = "nde";
  } else {
    throw InputError(a.model + ": GFRFs are computed for NARX and NDE models; this is a " + model_type_name(model) +
                     " model");
  }
  std::vector<std::string> names;
  for (int i = 1; i <= a.order; ++i) {
    names.push_back("s" + std::to_string(i) + "_re");
    names.push_back("s" + std::to_string(i) + "_im");
  }
  // The evaluation points: one n-tuple per row.
  std::vector<std::vector<Complex>> tuples;
  if (!a.points.empty()) {
    CsvTable in;
    try {
      in = read_csv(a.points);
    } catch (const FileError& e) {
      throw InputError(e.what());
    }
    std::vector<int> col;
    for (const auto& n : names) {
      const auto it = std::find(in.names.begin(), in.names.end(), n);
      if (it == in.names.end())
        throw InputError(detail::format("{}: no column '{}' (H_{} needs the columns s1_re, s1_im .. s{}_im)", a.points,
                                        n, a.order, a.order));
      col.push_back(static_cast<int>(it - in.names.begin()));
    }
    for (Eigen::Index r = 0; r < in.values.rows(); ++r) {
      std::vector<Complex> s;
      for (int i = 0; i < a.order; ++i) s.emplace_back(in.values(r, col[2 * i]), in.values(r, col[2 * i + 1]));
      tuples.push_back(s);
    }
    if (tuples.empty()) throw InputError(a.points + ": no points");
  } else {  // every n-tuple of the frequencies
    std::vector<Complex> pts;
    for (double w : a.w) pts.push_back(a.real ? Complex(w, 0) : Complex(0, w));
    const int P = static_cast<int>(pts.size());
    int rows = 1;
    for (int i = 0; i < a.order; ++i) rows *= P;
    std::vector<int> idx(a.order, 0);
    for (int r = 0; r < rows; ++r) {
      std::vector<Complex> s;
      for (int i = 0; i < a.order; ++i) s.push_back(pts[idx[i]]);
      tuples.push_back(s);
      for (int i = a.order - 1; i >= 0 && ++idx[i] == P; --i) idx[i] = 0;
    }
  }
  const int rows = static_cast<int>(tuples.size());
  Eigen::MatrixXd tab(rows, 2 * a.order + 3);
  names.insert(names.end(), {"re", "im", "mag"});
  for (int r = 0; r < rows; ++r) {
    for (int i = 0; i < a.order; ++i) {
      tab(r, 2 * i) = tuples[r][i].real();
      tab(r, 2 * i + 1) = tuples[r][i].imag();
    }
    const Complex h = kernel(tuples[r]);
    tab(r, 2 * a.order) = h.real();
    tab(r, 2 * a.order + 1) = h.imag();
    tab(r, 2 * a.order + 2) = std::abs(h);
  }
  std::printf("%s model, H_%d at %d point%s%s\n", kind.c_str(), a.order, rows, rows == 1 ? "" : "s",
              kind == "narx" && !a.no_zoh ? " (divided by the hold factor Z(s))" : "");
  for (int r = 0; r < std::min(rows, 10); ++r)
    std::printf("  H = %.6g %+.6gj\n", tab(r, 2 * a.order), tab(r, 2 * a.order + 1));
  if (!a.out.empty()) {
    write_csv(a.out, names, tab);
    std::printf("wrote %s\n", a.out.c_str());
  }
  if (!a.json.empty()) {
    write_text_file(a.json, table_to_json("gfrf", {{"model", kind}, {"order", std::to_string(a.order)},
                                                   {"hold_factor", kind == "narx" && !a.no_zoh ? "divided" : "none"}},
                                          names, tab));
    std::printf("wrote %s\n", a.json.c_str());
  }
  return kOk;
}
}  // namespace

void setup_gfrf(CLI::App& app) {
  auto a = std::make_shared<GfrfArgs>();
  app.add_option("MODEL", a->model, "NARX or NDE model JSON (result of fit --method narx or kia)")->required();
  app.add_option("--order", a->order, "Kernel order n (1..3)")->capture_default_str();
  app.add_option("--w", a->w, "Frequencies (rad/s); order n evaluates every n-tuple")->delimiter(',');
  app.add_option("--points", a->points, "CSV of complex points, one n-tuple per row: columns s1_re, s1_im, .., sn_im "
                 "(the layout of --out)");
  app.add_flag("--real", a->real, "Use s = w on the real axis instead of s = j w");
  app.add_flag("--no-zoh", a->no_zoh, "NARX: do not divide by the hold factor Z(s) (data not sampled with a held input)");
  app.add_option("--out", a->out, "Write the kernel values to this CSV file");
  app.add_option("--json", a->json, "Write the kernel values to this JSON file (the --out columns, with model and order)");
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a] { g_run = [a] { return run_gfrf(*a); }; });
}

}  // namespace ctid::cli
