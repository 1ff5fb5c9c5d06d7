// ctid demo — identify the bundled DaISy hair-dryer record (examples/data/dryer.dat).
#include <cstdio>
#include <filesystem>
#include <functional>

#include "common.hpp"

namespace ctid::cli {
extern std::function<int()> g_run;

namespace {
struct DemoArgs {
  std::string json;
  std::string data;
  bool force = false;
};

std::string find_dryer(const std::string& given) {
  namespace fs = std::filesystem;
  if (!given.empty()) return given;
  std::vector<fs::path> candidates = {fs::path(CTID_SOURCE_DATA_DIR) / "dryer.dat", fs::path(CTID_INSTALL_DATA_DIR) / "dryer.dat"};
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path().parent_path() / "share" / "ctid" / "dryer.dat");
  for (const auto& c : candidates)
    if (fs::exists(c)) return c.string();
  throw InputError("the bundled data file dryer.dat was not found (looked in " + candidates[0].parent_path().string() +
                   " and " + candidates[1].parent_path().string() + "); pass --data PATH");
}

int run(const DemoArgs& a) {
  check_outputs({a.json}, {a.data}, a.force);
  DataArgs da;
  da.path = find_dryer(a.data);
  da.inputs = {"1"};
  da.outputs = {"2"};
  da.ts = 0.08;  // DaISy gives no Ts; 0.08 s is MATLAB's documented value for this experiment
  da.detrend = "mean";
  const IdData d = da.load(true);
  IdData named = d;
  named.set_input_names({"heater_voltage"});
  named.set_output_names({"outlet_temperature"});
  const auto [est, val] = named.split(500);
  std::printf("ctid %s demo: laboratory hair dryer (DaISy; Ljung 1987), %d samples at Ts = 0.08 s\n", version(), d.size());
  std::printf("heater voltage -> outlet air temperature; means removed; first 500 samples to estimate, last 500 to validate\n\n");
  // Second order, one numerator coefficient, 2 samples (0.16 s) of transport delay; IV removes the
  // equation-error bias of plain LSSVF; the filter time constant is chosen automatically.
  const TfOrders orders{1, 2, 2};
  const Result<TransferFunction> r = ivsvf(est, orders);
  print_result(r, "ivsvf", est);
  const Eigen::VectorXd yv = lsim(r.model, val, 0);
  const double fv = fit_percent(val.y().col(0), yv);
  std::printf("\nvalidation on the last 500 samples: fit %s %%\n", fit_percent_text(fv).c_str());
  const auto p = r.model.poles();
  std::printf("poles:");
  for (auto z : p) std::printf("  %.4g%+.4gj", z.real(), z.imag());
  std::printf("   DC gain %.4g   delay %.3g s\n", r.model.dc_gain(), r.model.io_delay());
  if (!a.json.empty()) {
    write_result_json(a.json, r, "ivsvf");
    std::printf("wrote %s\n", a.json.c_str());
  }
  return r.usable() ? kOk : kNotUsable;
}
}  // namespace

void setup_demo(CLI::App& app) {
  auto a = std::make_shared<DemoArgs>();
  app.add_option("--json", a->json, "Also write the result to this JSON file");
  app.add_option("--data", a->data, "Path of dryer.dat (default: the bundled copy)");
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a] { g_run = [a] { return run(*a); }; });
}

}  // namespace ctid::cli
