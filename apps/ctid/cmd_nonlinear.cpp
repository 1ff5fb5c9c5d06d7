// ctid — Billings & Li: `ctid gfrf`, the generalised frequency response functions of a NARX or NDE model
// (`ctid fit --method narx|kia` fits them, through the library's registry).
#include <cmath>
#include <cstdio>
#include <algorithm>
#include <functional>
#include <limits>
#include <sstream>

#include "common.hpp"

namespace ctid::cli {

namespace {
struct GfrfArgs {
  std::string model, out, points, json;
  int order = 1;
  std::vector<double> w;
  bool real = false, no_zoh = false, force = false;
};

int run_gfrf(const GfrfArgs& a) {
  check_output_files({a.out, a.json}, {a.model, a.points}, a.force);
  if (a.order < 1 || a.order > 3) throw UsageError(detail::format("--order must be 1, 2 or 3 (got {})", a.order));
  if (a.w.empty() == a.points.empty())
    throw UsageError("give either the frequencies with --w w1,w2,.. (rad/s) or the points with --points FILE");
  std::function<Complex(const std::vector<Complex>&)> kernel;
  std::string kind;
  const AnyModel model = read_result_file(a.model).result.model;
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
    const CsvTable in = read_csv(a.points);
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

void setup_gfrf(CLI::App& app, Command& command) {
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
  app.callback([a, &command] { command = [a](Provenance&) { return run_gfrf(*a); }; });
}

}  // namespace ctid::cli
