// ctid — El-Shafey's modal-function tools: shared --set parsing, `ctid poles` (free-response data
// matrix, Theorem 4.3, against Prony) and `ctid response --method modal` (step, impulse, frequency).
#include <cmath>
#include <cstdio>
#include <functional>

#include "common.hpp"

namespace ctid::cli {

namespace {
// --set pairs through the library's tables of `method`; shift_samples (the shifts in whole samples) become `shifts`
// in seconds (shifts_from_samples).
template <class... O>
void modal_sets(const std::string& method, const std::vector<std::string>& sets, double ts, Eigen::VectorXd& shifts,
                O&... o) {
  try {
    for (const auto& [name, value] : apply_settings(method, setting_list(sets), {"shift_samples"}, o...))
      shifts = shifts_from_samples(method, setting_reals(method, name, value), ts, shifts);
  } catch (const UnknownSetting& e) {
    throw unknown_setting("--set " + e.key, e, method);
  }
}


struct PolesArgs {
  DataArgs data;
  int order = 0;
  std::vector<double> generator;
  std::vector<std::string> sets;
  std::string json;
  bool force = false;
};

int run_poles(PolesArgs a) {
  check_output_files({a.json}, {a.data.path}, a.force);
  if (a.order < 1) throw UsageError("--order must be >= 1");
  if (a.data.outputs.empty()) {
    const CsvTable tab = read_csv(a.data.path);
    std::vector<std::string> rest;
    for (const auto& n : tab.names)
      if (n != a.data.time) rest.push_back(n);
    if (rest.size() != 1) throw UsageError(a.data.path + ": choose the free-response column with --output");
    a.data.outputs = rest;
  }
  a.data.inputs = a.data.outputs;  // the response only, loaded as the one column; no input is used
  const IdData d = a.data.load(false);
  const double Ts = d.ts();
  const Eigen::VectorXd y = d.u().col(0);
  PolesOptions o;
  modal_sets("poles", a.sets, Ts, o.shifts, o);
  if (!a.generator.empty()) {
    if (o.generator.size() > 0) throw UsageError("give either --generator or --set generator, not both");
    o.generator = Eigen::Map<const Eigen::VectorXd>(a.generator.data(), static_cast<Eigen::Index>(a.generator.size()));
  }
  const PolesComparison c = compare_poles(y, Ts, a.order, o);
  std::printf("free response: %d samples, Ts = %.6g s, order %d\n%s", d.size(), Ts, a.order, poles_text(c).c_str());
  if (!a.json.empty()) {
    write_text_file(a.json, poles_to_json(c, a.order, Ts));
    std::printf("wrote %s\n", a.json.c_str());
  }
  return kOk;
}

struct ResponseArgs {
  DataArgs data;
  std::string method = "modal", kind = "step", out, json;
  int order = 0;
  std::vector<std::string> sets;
  bool force = false;
};

int run_response(const ResponseArgs& a) {
  check_output_files({a.out, a.json}, {a.data.path}, a.force);
  if (a.order < 1) throw UsageError("--order must be >= 1");
  const IdData d = a.data.load(true);
  if (d.nu() != 1 || d.ny() != 1) throw UsageError("response needs one --input and one --output");
  ModalResponseOptions ro;
  ModalOptions mo;
  modal_sets("modal_response", a.sets, d.ts(), mo.shifts, ro, mo);
  const ResponseKind kind = a.kind == "frequency" ? ResponseKind::Frequency
                            : a.kind == "impulse" ? ResponseKind::Impulse
                                                  : ResponseKind::Step;
  const ModalResponse m = modal_response(d, a.order, kind, ro, mo);
  std::fputs(modal_response_text(m).c_str(), stdout);
  const auto [names, table] = modal_response_table(m);
  if (!a.out.empty()) write_csv(a.out, names, table);
  if (!a.json.empty())
    write_text_file(a.json, table_to_json("response", {{"method", a.method}, {"kind", a.kind},
                                                       {"order", std::to_string(a.order)}},
                                          names, table));
  for (const std::string* f : {&a.out, &a.json})
    if (!f->empty()) std::printf("wrote %s\n", f->c_str());
  return kOk;
}

}  // namespace

void setup_poles(CLI::App& app, Command& command) {
  auto a = std::make_shared<PolesArgs>();
  app.add_option("DATA", a->data.path, "CSV/.dat table or .mat file holding a free (or generated-input) response")
      ->required();
  a->data.add_to(app, true);
  app.add_option("--order", a->order, "Number of system poles n")->required();
  app.add_option("--generator", a->generator,
                 "A response forced by a known generated input: its frequencies w1,.. (rad/s; 0 = constant); the "
                 "augmented estimate is deflated by them")
      ->delimiter(',');
  app.add_option("--set", a->sets,
                 "KEY=VALUE; " + settings_help(method_info("poles")) +
                     "  shift_samples  the shifts counted in samples (instead of shifts)");
  app.add_option("--json", a->json, "Write both estimates (poles, characteristic polynomials, conditions) to this JSON file");
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a, &command] {
    command = [a](Provenance& prov) {
      a->data.provenance = &prov;
      return run_poles(*a);
    };
  });
}

void setup_response(CLI::App& app, Command& command) {
  auto a = std::make_shared<ResponseArgs>();
  app.add_option("DATA", a->data.path, "CSV/.dat table or .mat file")->required();
  app.add_option("--method", a->method, "Estimator of the response: modal (El-Shafey)")
      ->check(CLI::IsMember({"modal"}))
      ->capture_default_str();
  app.add_option("--kind", a->kind, "step, impulse or frequency")
      ->check(CLI::IsMember({"step", "impulse", "frequency"}))
      ->capture_default_str();
  a->data.add_to(app, true);
  app.add_option("--order", a->order, "System order n")->required();
  app.add_option("--set", a->sets,
                 "KEY=VALUE; " + settings_help(method_info("modal_response")) +
                     "  shift_samples  the shifts counted in samples (instead of shifts)");
  app.add_option("--out", a->out, "Write the response to this CSV file");
  app.add_option("--json", a->json, "Write the response to this JSON file (the --out columns, with kind and order)");
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a, &command] {
    command = [a](Provenance& prov) {
      a->data.provenance = &prov;
      return run_response(*a);
    };
  });
}

}  // namespace ctid::cli
