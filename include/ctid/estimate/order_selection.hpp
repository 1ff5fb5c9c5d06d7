// ctid — model structure selection for continuous-time transfer functions, as CONTSID's
// srivcstruc/selcstruc: every [nb nf nk] of the given ranges is fitted by SRIVC and the
// candidates are ranked by
//   YIC = ln(s2/sy2) + ln( (1/np) sum_i s2 p_ii / theta_i^2 )   (Young 1989; lower is better),
//   RT2 = 1 - s2/sy2   (coefficient of determination of the simulated output; higher is better),
//   AIC, BIC (FitReport definitions; lower is better),
// with s2 the output-error variance, sy2 the variance of y and s2 p_ii the parameter variances.
#pragma once

#include <string>
#include <vector>

#include "ctid/data/iddata.hpp"
#include "ctid/estimate/orders.hpp"
#include "ctid/estimate/srivc.hpp"

namespace ctid {

enum class OrderCriterion { Yic, Rt2, Aic, Bic };
/// "yic", "rt2", "aic", "bic"; throws InvalidArgument otherwise.
OrderCriterion order_criterion_from_string(const std::string& s);

struct OrderCandidate {
  TfOrders orders;
  double yic = 0, rt2 = 0, aic = 0, bic = 0, fit_percent = 0;
  bool usable = false;          ///< SRIVC converged to a stable model
  std::string termination;
};

struct OrderRange {
  int min = 1, max = 1;
};

struct OrderSelectionOptions {
  SrivcOptions srivc;
  OrderCriterion rank_by = OrderCriterion::Yic;
};

/// Fit every structure with nb in [nb.min, nb.max], nf in [nf.min, nf.max], nk in
/// [nk.min, nk.max] (nb <= nf + 1) and return them ranked: usable candidates first, by
/// the chosen criterion. Throws InvalidOptions for empty or invalid ranges.
std::vector<OrderCandidate> select_order(const IdData& data, OrderRange nb, OrderRange nf, OrderRange nk,
                                         const OrderSelectionOptions& options = {});

}  // namespace ctid
