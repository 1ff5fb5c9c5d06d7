// The registry runs every fit (estimate/methods.hpp, estimate/fit.hpp): each method that fits records runs through
// fit() on a small record of its kind and returns a result of one of its declared model types under its registry
// name; the variants its data call for are named as such; a request the method cannot take is refused naming it;
// and fit() gives bit for bit what the estimator called directly gives.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "ctid/ctid.hpp"
#include "test_util.hpp"

namespace {
using namespace ctid;

// A record of `ctid example-data NAME`: the columns after an optional time column t are the inputs, then the
// outputs (the last `outputs` columns).
IdData example(const std::string& name, int outputs = 1) {
  const ExampleData e = example_data(name);
  const bool timed = e.columns.front() == "t";
  const int first = timed ? 1 : 0, n = static_cast<int>(e.values.cols()) - first;
  const Eigen::MatrixXd u = e.values.middleCols(first, n - outputs), y = e.values.rightCols(outputs);
  const double ts = timed ? e.values(1, 0) - e.values(0, 0) : (name == "bl" ? 0.0025 : 0.05);
  IdData d(u, y, ts);
  std::vector<std::string> in(e.columns.begin() + first, e.columns.end() - outputs), out(e.columns.end() - outputs, e.columns.end());
  d.set_input_names(in);
  d.set_output_names(out);
  return d;
}

GreyboxModel spring_model() {
  std::ifstream f(std::string(CTID_EXAMPLES_DATA_DIR) + "/spring_greybox.json");
  std::stringstream s;
  s << f.rdbuf();
  return parse_greybox_json(s.str(), "spring_greybox.json");
}

// A request each fit can take: the record of its kind and the structure it needs.
FitRequest request_for(const MethodInfo& m) {
  const MethodCapabilities& c = m.capabilities;
  FitRequest r;
  if (c.greybox_model) {
    r.records = {example("spring")};
    r.structure.greybox = spring_model();
    return r;
  }
  r.records = {c.narx_model || m.name == "narx" ? example("bl") : example("second")};
  if (c.needs_orders) r.structure.orders = {{1, 2, 0}};
  if (c.physical_model) r.structure.physical = PhysicalStructure{"k*(s + z)/(s^2 + a*s + b)", {{"k", 0.8}, {"z", 2.5}, {"a", 1.0}, {"b", 3.5}}, "raw"};
  if (c.nx) r.settings = {{"nx", std::string("2")}};
  if (m.name == "narx" || c.narx_model) r.settings = {{"degree", std::string("2")}, {"ylag", std::string("2")}, {"ulag", std::string("2")}};
  return r;
}

TEST(Registry, EveryFitRunsUnderItsNameAndGivesItsModelType) {
  const std::vector<std::string> fits = fit_method_names();
  ASSERT_GE(fits.size(), 15u);
  for (const auto& name : fits) {
    const MethodInfo& m = method_info(name);
    ASSERT_TRUE(m.run) << name;
    const FitOutcome out = fit(name, request_for(m));
    EXPECT_EQ(out.method, name);
    const auto& types = m.capabilities.model_types;
    EXPECT_NE(std::find(types.begin(), types.end(), model_type_name(out.result.model)), types.end())
        << name << " gave a " << model_type_name(out.result.model);
    EXPECT_FALSE(out.settings.empty()) << name;
    // Every fit reaches a model that explains the record better than its mean (fit_percent > 0); most are usable.
    EXPECT_GT(out.result.fit.fit_percent, 0.0) << name << ": " << out.result.why_not_usable();
  }
}

TEST(Registry, FitEqualsTheEstimatorCalledDirectly) {
  const IdData d = example("second");
  FitRequest r;
  r.records = {d};
  r.structure.orders = {{1, 2, 0}};
  r.settings = {{"max_iterations", std::string("30")}};
  SrivcOptions o;
  o.max_iterations = 30;
  const Result<TransferFunction> direct = srivc(d, {1, 2, 0}, o);
  const FitOutcome viafit = fit("srivc", r);
  ASSERT_EQ(viafit.result.parameters.size(), direct.parameters.size());
  for (int i = 0; i < direct.parameters.size(); ++i) {
    EXPECT_EQ(viafit.result.parameters.values(i), direct.parameters.values(i));  // bit for bit
    EXPECT_EQ(viafit.result.parameters.std(i), direct.parameters.std(i));
  }
  // The settings text is every setting of the options used, the given one with its value.
  const auto it = std::find_if(viafit.settings.begin(), viafit.settings.end(), [](const auto& s) { return s.first == "max_iterations"; });
  ASSERT_NE(it, viafit.settings.end());
  EXPECT_EQ(it->second, "30");
  EXPECT_EQ(viafit.settings.size(), method_info("srivc").settings.size());
}

TEST(Registry, TheDataChooseTheVariantAndItsName) {
  // Two inputs: srivc runs as srivc_miso.
  FitRequest miso;
  miso.records = {example("miso")};
  miso.structure.orders = {{1, 2, 0}, {1, 1, 0}};
  const FitOutcome m = fit("srivc", miso);
  EXPECT_EQ(m.method, "srivc_miso");
  EXPECT_TRUE(std::holds_alternative<MisoModel>(m.result.model));
  // Frequency data: tfest runs as tf_from_frequency, and is the default method there.
  const ExampleData f = example_data("freq");
  FitRequest fr;
  fr.frequency = FrequencyData(f.values.col(0), f.values.col(1).cast<std::complex<double>>() +
                                                    std::complex<double>(0, 1) * f.values.col(2));
  fr.structure.orders = {{2, 4, 0}};
  EXPECT_EQ(default_method(fr.structure, true), "tfest");
  EXPECT_EQ(fit("tfest", fr).method, "tf_from_frequency");
  // An alias runs the method and records its registry name.
  FitRequest a;
  a.records = {example("second")};
  EXPECT_EQ(fit("srivc-auto", a).method, "srivc_auto");
  EXPECT_EQ(default_method(FitStructure{}), "srivc_auto");
  EXPECT_EQ(default_method(a.structure), "srivc_auto");
}

TEST(Registry, RefusesWhatAMethodDoesNotTake) {
  auto message = [](const std::string& method, const FitRequest& r) {
    try {
      fit(method, r);
    } catch (const InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  FitRequest two;
  two.records = {example("second"), example("second")};
  EXPECT_NE(message("fsf", two).find("fsf: fits one record (got 2); several records are fitted jointly by lssvf"),
            std::string::npos)
      << message("fsf", two);
  FitRequest grey;
  grey.records = {example("second")};
  grey.structure.orders = {{1, 2, 0}};
  grey.structure.greybox = spring_model();
  EXPECT_EQ(message("srivc", grey), "srivc: takes no grey-box model");
  FitRequest none;
  none.records = {example("second")};
  EXPECT_EQ(message("oe", none), "oe: needs transfer-function orders (nb, nf, nk)");
  EXPECT_EQ(message("srivc_miso", none), "srivc_miso: runs as srivc on records with several inputs");
  EXPECT_NE(message("srivcc", none).find("'srivcc' is not a method; did you mean 'srivc'?"), std::string::npos);
  FitRequest two_outputs;
  two_outputs.records = {example("mimo", 2)};
  two_outputs.structure.orders = {{1, 2, 0}};
  EXPECT_NE(message("srivc", two_outputs).find("srivc estimates single-output models (the record has 2 outputs; "
                                               "greybox, subspace or ssest take several)"),
            std::string::npos)
      << message("srivc", two_outputs);
  // An unknown setting: typed, with the method, the name and the closest setting.
  FitRequest typo = none;
  typo.structure.orders = {{1, 2, 0}};
  typo.settings = {{"max_iteration", std::string("5")}};
  try {
    fit("srivc", typo);
    ADD_FAILURE() << "no error";
  } catch (const UnknownSetting& e) {
    EXPECT_EQ(e.method, "srivc");
    EXPECT_EQ(e.key, "max_iteration");
    EXPECT_EQ(e.closest, "max_iterations");
  }
}

}  // namespace
