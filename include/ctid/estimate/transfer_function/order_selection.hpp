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
#include "ctid/estimate/transfer_function/srivc.hpp"

namespace ctid {

enum class OrderCriterion { Yic, Rt2, Aic, Bic };
/// "yic", "rt2", "aic", "bic"; throws InvalidArgument otherwise.
OrderCriterion order_criterion_from_string(const std::string& s);
/// The name order_criterion_from_string reads ("yic", "rt2", "aic", "bic").
const char* to_string(OrderCriterion c);

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

/// The most structures one select_order call fits (each is an SRIVC fit).
inline constexpr int kMaxOrderCandidates = 2000;

/// Fit every structure with nb in [nb.min, nb.max], nf in [nf.min, nf.max], nk in
/// [nk.min, nk.max] (nb <= nf + 1) and return them ranked: usable candidates first, by
/// the chosen criterion; a candidate is usable when its SRIVC result is (Result::usable()) and its YIC is
/// finite. Throws InvalidOptions for empty or invalid ranges and for more than kMaxOrderCandidates
/// structures. Reports progress once per structure ("select_order"); when asked to stop it returns the
/// structures fitted so far (interrupt_requested() is then true).
std::vector<OrderCandidate> select_order(const IdData& data, OrderRange nb, OrderRange nf, OrderRange nk,
                                         const OrderSelectionOptions& options = {});

}  // namespace ctid
