// ctid — forward regression orthogonal least squares (FROLS) with the error reduction ratio (ERR) for
// polynomial NARX structure detection (Billings & Li 1999, BL-D1 and BL 28-32 / SEEDS-SPEC BL-D6; the
// algorithm of Billings, Chen & Korenberg 1989).
//
// Memory: the candidate matrix (N x M) is never stored. Candidate columns are generated in row blocks;
// each step needs only the inner products of every candidate with the newest orthogonal vector, so the
// workspace is O(block x M + N x terms + M x terms).
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/model/narx.hpp"

namespace ctid {

enum class InformationCriterion { None, Aic, Aicc, Bic, Fpe };

struct FrolsOptions {
  int max_terms = 20;           ///< upper bound on the number of selected terms
  double err_tolerance = 0.0;   ///< stop when 1 - sum(ERR) <= err_tolerance (0: only max_terms / criterion)
  /// Model size: the k <= max_terms minimising the criterion along the single greedy pass (None: all
  /// selected terms). Criteria as validate/metrics.hpp with N = rows used, d = k.
  InformationCriterion criterion = InformationCriterion::None;
  int block_rows = 4096;        ///< rows of candidate columns generated at a time
  /// Throws InvalidOptions naming the field.
  void validate() const;
};

/// FROLS on one SISO record with the given candidate terms (no noise terms; see narx_candidates).
/// Rows k = L .. N-1 with L the largest candidate lag. Parameters are named by term; their covariance is
/// sigma^2 (P^T P)^{-1} of the selected columns. diagnostics.vectors: "err" (ERR in % of each selected term,
/// in order of selection), "criterion" (the criterion after 1..K terms when one is chosen); scalars: "esr"
/// (1 - sum ERR of the returned terms), "candidates". fit: free-run simulation from the measured first L
/// outputs (an escaping simulation gives an infinite error and a warning).
/// Throws InvalidArgument for a multi-channel record, noise terms, or as many candidates as rows.
Result<NarxModel> frols(const IdData& data, const std::vector<NarxTerm>& candidates, const FrolsOptions& options = {});

struct NarmaxOptions {
  FrolsOptions frols;                      ///< process-term selection (max_terms counts process terms)
  /// e(k-1..5), e(k-i)e(k-j), e(k-i)y(k-j) and e(k-i)u(k-j) (i <= 5, j <= 2) by default.
  std::vector<NarxTerm> noise_candidates = narx_noise_candidates(5, 2, 2);
  int max_noise_terms = 5;                 ///< noise terms allowed on top of frols.max_terms
  int iterations = 20;                     ///< extended least-squares iterations
  double tolerance = 1e-3;                 ///< stop when the process terms repeat and their coefficients change less (relative)
  void validate() const;
};

/// NARMAX (BL-D1): NARX selection by FROLS, then iterations in which the residuals e(k) = y(k) - phi(k)^T theta
/// of the current model (noise regressors from the previous residuals: pseudo-linear regression) feed the
/// noise candidates and FROLS selects process and noise terms together (extended least squares), until the
/// terms repeat and the coefficients settle. The noise terms absorb coloured
/// equation errors (e.g. output measurement noise) so that the process coefficients are not biased;
/// model.process() drops them for simulation. diagnostics.scalars: "narmax_iterations", "relative_change".
Result<NarxModel> narmax(const IdData& data, const std::vector<NarxTerm>& process_candidates,
                         const NarmaxOptions& options = {});

}  // namespace ctid
