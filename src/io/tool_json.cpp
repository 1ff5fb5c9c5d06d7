// ctid — the JSON files of the tools (io/tool_text.hpp): ctid compare --json and ctid validate --json.
#include <cmath>

#include <nlohmann/json.hpp>

#include "ctid/core/check.hpp"
#include "ctid/io/load.hpp"
#include "ctid/io/tool_text.hpp"

namespace ctid {

namespace {
using json = nlohmann::ordered_json;

json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
}  // namespace

std::string comparison_to_json(const std::string& data_name, const IdData& d, const std::vector<ModelComparison>& cs,
                               int indent) {
  json j;
  j["ctid_version"] = version();
  j["data"] = data_name;
  j["n_samples"] = d.size();
  j["best"] = cs.empty() ? json(nullptr) : json(cs[best_comparison(cs)].name);
  j["models"] = json::array();
  for (const ModelComparison& c : cs) {
    json m = {{"name", c.name}, {"type", model_type_name(c.model)}, {"initial", to_string(c.initial)}};
    m["outputs"] = json::array();
    for (std::size_t o = 0; o < c.fits.size(); ++o) {
      const FitReport& f = c.fits[o];
      json jo = {{"output", channel_name(d.output_names(), static_cast<int>(o))},
                 {"fit_percent", num(f.fit_percent)}, {"nrmse", num(f.nrmse)}, {"mse", num(f.mse)}, {"aic", num(f.aic)}};
      if (c.whiteness[o].lags.size() > 0) {
        jo["whiteness_lags_outside"] = c.whiteness[o].n_outside;
        jo["independence_lags_outside"] = json::array();
        for (const auto& x : c.independence[o]) jo["independence_lags_outside"].push_back(x.n_outside);
      }
      m["outputs"].push_back(jo);
    }
    m["problem"] = c.simulation.problem;
    j["models"].push_back(m);
  }
  return j.dump(indent) + "\n";
}

namespace {
json correlation_json(const CorrelationTest& c) {
  return {{"lags", std::vector<int>(c.lags.begin(), c.lags.end())},
          {"values", std::vector<double>(c.values.begin(), c.values.end())},
          {"bound_99", c.bound},
          {"n_outside", c.n_outside},
          {"passed", c.passed()}};
}

void add_scores(json& j, const OutputScore& s) {
  const FitReport& f = s.fit;
  j["fit"] = {{"fit_percent", f.fit_percent}, {"nrmse", f.nrmse}, {"mse", f.mse}, {"n_samples", f.n_samples}};
  j["residual_autocorrelation"] = correlation_json(s.whiteness);
  j["input_residual_crosscorrelation"] = json::array();
  for (const auto& x : s.independence) j["input_residual_crosscorrelation"].push_back(correlation_json(x));
}
}  // namespace

std::string validation_to_json(const ResultFile& file, InitialCondition initial,
                               const std::vector<std::pair<std::string, std::vector<OutputScore>>>& records,
                               int indent) {
  CTID_REQUIRE(!records.empty(), "validation_to_json: no record");
  json all = json::array();
  for (const auto& [name, scores] : records) {
    json r;
    r["data"] = name;
    if (scores.size() == 1) {
      add_scores(r, scores.front());
    } else {
      r["outputs"] = json::array();
      for (const OutputScore& s : scores) {
        json o = {{"output", s.output}};
        add_scores(o, s);
        r["outputs"].push_back(o);
      }
    }
    all.push_back(r);
  }
  json j = all.front();
  j.erase("data");
  j["ctid_version"] = version();
  j["model"] = json::parse(result_to_json(file.result, file.method))["model"];
  j["initial"] = to_string(initial);
  j["experiments"] = all;
  return j.dump(indent) + "\n";
}

}  // namespace ctid
