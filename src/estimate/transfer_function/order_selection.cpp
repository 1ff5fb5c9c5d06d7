// Structure selection by YIC / RT2 / AIC / BIC (Young 1989; CONTSID srivcstruc).
#include "ctid/estimate/transfer_function/order_selection.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "ctid/core/check.hpp"
#include "ctid/core/progress.hpp"
#include "estimate/transfer_function/tf_common.hpp"

namespace ctid {

OrderCriterion order_criterion_from_string(const std::string& s) {
  std::string l = s;
  std::transform(l.begin(), l.end(), l.begin(), [](unsigned char c) { return std::tolower(c); });
  if (l == "yic") return OrderCriterion::Yic;
  if (l == "rt2") return OrderCriterion::Rt2;
  if (l == "aic") return OrderCriterion::Aic;
  if (l == "bic") return OrderCriterion::Bic;
  throw InvalidArgument(detail::format("unknown order criterion '{}' (use yic, rt2, aic or bic)", s));
}

const char* to_string(OrderCriterion c) {
  switch (c) {
    case OrderCriterion::Yic: return "yic";
    case OrderCriterion::Rt2: return "rt2";
    case OrderCriterion::Aic: return "aic";
    case OrderCriterion::Bic: return "bic";
  }
  return "yic";
}

std::vector<OrderCandidate> select_order(const IdData& data, OrderRange nb, OrderRange nf, OrderRange nk,
                                         const OrderSelectionOptions& options) {
  auto check = [](OrderRange r, int lo, const char* name) {
    CTID_REQUIRE_OPTION(r.min >= lo && r.max >= r.min, "select_order: the range of {} must be {} <= min <= max (got {}:{})",
                        name, lo, r.min, r.max);
  };
  check(nb, 1, "nb");
  check(nf, 1, "nf");
  check(nk, 0, "nk");
  CTID_REQUIRE(data.ny() == 1, "select_order: needs one output (data has {})", data.ny());
  const Eigen::VectorXd y = data.y().col(0);
  const double sy2 = (y.array() - y.mean()).square().mean();
  CTID_REQUIRE(sy2 > 0, "select_order: the output is constant");
  long long count = 0;
  for (int f = nf.min; f <= nf.max; ++f)
    count += static_cast<long long>(std::max(0, std::min(nb.max, f + 1) - nb.min + 1)) * (nk.max - nk.min + 1);
  CTID_REQUIRE_OPTION(count <= kMaxOrderCandidates,
                      "select_order: the ranges give {} structures, more than the limit of {}; narrow --nb/--nf/--nk",
                      count, kMaxOrderCandidates);
  std::vector<OrderCandidate> out;
  int done = 0;
  for (int f = nf.min; f <= nf.max; ++f)
    for (int b = nb.min; b <= std::min(nb.max, f + 1); ++b)
      for (int k = nk.min; k <= nk.max; ++k) {
        if (!report_progress("select_order", ++done, NAN)) goto ranked;  // interrupted: rank what was fitted
        OrderCandidate c;
        c.orders = TfOrders{b, f, k};
        const Result<TransferFunction> r = srivc(data, c.orders, options.srivc);
        c.termination = to_string(r.summary.termination);
        c.usable = r.usable();
        const double s2 = r.fit.mse;
        c.rt2 = 1.0 - s2 / sy2;
        double nevn = 0;
        const int np = r.parameters.size();
        for (int i = 0; i < np; ++i) {
          const double th = r.parameters.values(i);
          nevn += (r.parameters.std(i) * r.parameters.std(i)) / std::max(th * th, 1e-300);
        }
        nevn /= np;
        c.yic = std::log(s2 / sy2) + std::log(nevn);
        c.aic = r.fit.aic;
        c.bic = r.fit.bic;
        c.fit_percent = r.fit.fit_percent;
        if (!std::isfinite(c.yic)) c.usable = false;
        // A pole the data cannot resolve: the lower order describes them as well, so this one ranks after it.
        if (c.usable && tf_detail::pole_beyond_bandwidth(r.model, data)) {
          c.usable = false;
          c.termination = "pole beyond the bandwidth";
        }
        out.push_back(c);
      }
ranked:
  auto key = [&](const OrderCandidate& c) {
    switch (options.rank_by) {
      case OrderCriterion::Yic: return c.yic;
      case OrderCriterion::Rt2: return -c.rt2;
      case OrderCriterion::Aic: return c.aic;
      case OrderCriterion::Bic: return c.bic;
    }
    return c.yic;
  };
  // Usable structures first, then by the criterion; a criterion that is not a number (a fit that failed) ranks last
  // in its group (compared as a number it would make the order undefined and land anywhere).
  std::stable_sort(out.begin(), out.end(), [&](const OrderCandidate& a, const OrderCandidate& b) {
    if (a.usable != b.usable) return a.usable;
    const double ka = key(a), kb = key(b);
    if (std::isnan(ka) || std::isnan(kb)) return !std::isnan(ka) && std::isnan(kb);
    return ka < kb;
  });
  return out;
}

}  // namespace ctid
