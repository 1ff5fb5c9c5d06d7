// ctid example-data — write one of the simulated example records the README and docs/ use (example_data()).
#include <cstdio>
#include <functional>

#include "common.hpp"
#include "ctid/io/csv.hpp"
#include "ctid/simulate/example_data.hpp"

namespace ctid::cli {

namespace {
struct ExampleArgs {
  std::string name, out;
  bool list = false, force = false;
};

int run(const ExampleArgs& a) {
  if (a.list || a.name.empty()) {
    for (const auto& n : example_data_names()) std::printf("%-8s %s\n", n.c_str(), example_data(n).description.c_str());
    return 0;
  }
  if (a.out.empty()) throw UsageError("give the output file: ctid example-data " + a.name + " OUT.csv");
  ExampleData e;
  try {
    e = example_data(a.name);
  } catch (const InvalidArgument& err) {
    throw UsageError(err.what());
  }
  check_output_files({a.out}, {}, a.force);
  write_csv(a.out, e.columns, e.values);
  std::printf("wrote %s: %s (%lld rows; columns", a.out.c_str(), e.description.c_str(),
              static_cast<long long>(e.values.rows()));
  for (const auto& c : e.columns) std::printf(" %s", c.c_str());
  std::printf(")\n");
  return 0;
}
}  // namespace

void setup_example_data(CLI::App& app, Command& command) {
  auto a = std::make_shared<ExampleArgs>();
  app.add_option("NAME", a->name, "Example record (--list names them all)");
  app.add_option("OUT", a->out, "CSV file to write (header row of column names)");
  app.add_flag("--list", a->list, "List the example records with what each one is");
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a, &command] { command = [a](Provenance&) { return run(*a); }; });
}

}  // namespace ctid::cli
