// ctid order DATA --nb 1:2 --nf 3:5 [--nk 0:0] [--rank yic|rt2|aic|bic] [--json OUT.json [--force]]
#include <cstdio>
#include <functional>

#include "common.hpp"

namespace ctid::cli {

namespace {
struct OrderArgs {
  DataArgs data;
  std::string nb = "1:2", nf = "1:3", nk = "0:0", rank = "yic", json;
  bool force = false;
};

OrderRange parse_range(const std::string& flag, const std::string& s) {
  const auto colon = s.find(':');
  try {
    std::size_t used = 0;
    if (colon == std::string::npos) {
      const int v = std::stoi(s, &used);
      if (used != s.size()) throw std::invalid_argument(s);
      return {v, v};
    }
    const int a = std::stoi(s.substr(0, colon), &used);
    if (used != colon) throw std::invalid_argument(s);
    const std::string rest = s.substr(colon + 1);
    const int b = std::stoi(rest, &used);
    if (used != rest.size()) throw std::invalid_argument(s);
    return {a, b};
  } catch (const std::exception&) {
    throw UsageError(flag + " takes N or MIN:MAX (got '" + s + "')");
  }
}

int run(const OrderArgs& a) {
  OrderSelectionOptions o;
  o.rank_by = order_criterion_from_string(a.rank);
  const OrderRange nb = parse_range("--nb", a.nb), nf = parse_range("--nf", a.nf), nk = parse_range("--nk", a.nk);
  check_output_files({a.json}, {a.data.path}, a.force);
  const IdData d = a.data.load(true);
  if (d.nu() != 1 || d.ny() != 1) throw UsageError("order selection needs one --input and one --output");
  const std::vector<OrderCandidate> c = select_order(d, nb, nf, nk, o);
  std::printf("rank  nb nf nk        YIC       RT2         AIC         BIC    fit %%  SRIVC\n");
  int i = 0;
  for (const auto& k : c)
    // Significant digits, not fixed decimals: a diverged structure's RT2 of -1e135 stays one column wide.
    std::printf("%4d  %2d %2d %2d %10.4g %9.4g %11.6g %11.6g %8s  %s\n", ++i, k.orders.nb, k.orders.nf, k.orders.nk, k.yic,
                k.rt2, k.aic, k.bic, fit_percent_text(k.fit_percent).c_str(), k.termination.c_str());
  if (!a.json.empty()) {
    write_text_file(a.json, order_selection_to_json(c, o.rank_by, interrupt_requested()));
    std::printf("wrote %s\n", a.json.c_str());
  }
  if (interrupt_requested()) {
    std::fprintf(stderr, "ctid: interrupted after %zu of the structures; the table ranks those fitted\n", c.size());
    return kNotUsable;
  }
  return c.empty() || !c.front().usable ? kNotUsable : kOk;
}
}  // namespace

void setup_order(CLI::App& app, Command& command) {
  auto a = std::make_shared<OrderArgs>();
  app.add_option("DATA", a->data.path, "CSV/.dat table or .mat file")->required();
  a->data.add_to(app, true);
  app.add_option("--nb", a->nb, "Numerator coefficients: N or MIN:MAX")->capture_default_str();
  app.add_option("--nf", a->nf, "Model orders: N or MIN:MAX")->capture_default_str();
  app.add_option("--nk", a->nk, "Input delays in samples: N or MIN:MAX")->capture_default_str();
  app.add_option("--rank", a->rank, "Ranking criterion: yic, rt2, aic or bic")->capture_default_str();
  app.add_option("--json", a->json, "Write the ranked candidates to this JSON file");
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a, &command] {
    command = [a](Provenance& prov) {
      a->data.provenance = &prov;
      return run(*a);
    };
  });
}

}  // namespace ctid::cli
