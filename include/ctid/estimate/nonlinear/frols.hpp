// ctid — forward regression orthogonal least squares (FROLS) with the error reduction ratio (ERR) for
// polynomial NARX structure detection (Billings & Li 1999, BL-D1 and BL 28-32; the
// algorithm of Billings, Chen & Korenberg 1989).
//
// Memory: FROLS on one record stores nothing of the record's length N besides the record (several records are
// concatenated once; NARMAX keeps its residual signal). Candidate columns are generated in row blocks;
// each step needs only the inner products of every candidate with the newest orthogonal vector, which is
// regenerated block by block from the selected terms' columns with the Gram-Schmidt coefficients already
// found, and the fit's free run is simulated a block at a time. Workspace O(block x (variables + terms) +
// M x terms); time per sample and term O(variables^2 + terms) (measured in docs/benchmarks.md). When fewer
// products per row suffice (FrolsOptions::route), the candidates' Gram matrix is formed instead in one pass as
// sums of monomials of the lagged signals and the selection runs in it (Korenberg 1988, fast orthogonal
// search): the record is read once, workspace O(128 x moments + M^2).
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "ctid/core/types.hpp"
#include "ctid/estimate/options.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/model/narx.hpp"

namespace ctid {

enum class InformationCriterion { None, Aic, Aicc, Bic, Fpe };

/// How FROLS forms the products of the candidates with the orthogonalised terms.
enum class FrolsRoute {
  Auto,    ///< Gram when it needs fewer products per row than the passes
  Passes,  ///< one pass over the signals per selected term, the candidate columns regenerated block by block
  Gram,    ///< the candidates' Gram matrix from one pass, then Korenberg's fast orthogonal search in it
};

struct FrolsOptions {
  int max_terms = 20;           ///< upper bound on the number of selected terms
  double err_tolerance = 0.0;   ///< stop when 1 - sum(ERR) <= err_tolerance (0: only max_terms / criterion)
  /// Model size: the k <= max_terms minimising the criterion along the single greedy pass (None: all
  /// selected terms). Criteria as validate/metrics.hpp with N = rows used, d = k.
  InformationCriterion criterion = InformationCriterion::None;
  int block_rows = 4096;        ///< rows of candidate columns generated at a time
  /// Passes: exact Gram-Schmidt on regenerated columns, K + 2 passes over the record. Gram: one pass (the monomials
  /// of degree up to twice the candidates', at most 50 000), the signals read once — at long records the passes wait
  /// on main memory — at the price of the candidates' squared conditioning (ERR and coefficients agree with Passes to
  /// about 1e-9 on collinear lag sets; a near tie may select another term).
  FrolsRoute route = FrolsRoute::Auto;
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
/// Several records of one system (same Ts): one regression stacking each record's rows k = L .. N_r-1 (no row
/// reaches across records), one term selection; the fit pools each record's free run from its own first L
/// outputs. Throws InvalidArgument for records at different sampling periods or not longer than L.
Result<NarxModel> frols(const std::vector<IdData>& data, const std::vector<NarxTerm>& candidates,
                        const FrolsOptions& options = {});

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
/// Several records (as frols): the residuals of each record start from zero at its own first L samples.
Result<NarxModel> narmax(const std::vector<IdData>& data, const std::vector<NarxTerm>& process_candidates,
                         const NarmaxOptions& options = {});

/// The NARX workflow (`ctid fit --method narx`, Python ctid.narx, C++ narx()): the polynomial candidates of
/// narx_candidates(degree, ylag, ulag, constant, umin), then FROLS — model size by an information criterion,
/// AIC by default — or, with noise_terms > 0, NARMAX with the noise candidates narx_noise_candidates(noise_terms,
/// 2, 2).
struct NarxOptions {
  int degree = 2;         ///< polynomial degree of the candidates
  int ylag = 2;           ///< output lags y(k-1) .. y(k-ylag), >= 1
  int ulag = 2;           ///< input lags u(k-umin) .. u(k-ulag)
  int umin = 1;           ///< smallest input lag (0: a direct feed-through term)
  bool constant = true;   ///< include the constant term
  int noise_terms = 0;    ///< NARMAX residual lags e(k-1..noise_terms); 0: NARX by FROLS
  NarmaxOptions narmax = [] {
    NarmaxOptions o;
    o.frols.criterion = InformationCriterion::Aic;
    return o;
  }();                    ///< selection (narmax.frols, also for NARX) and NARMAX iterations; noise candidates from noise_terms
  void validate() const;
};

/// Fits the NARX (or NARMAX) workflow on one SISO record. Throws InvalidArgument / InvalidOptions as frols/narmax.
Result<NarxModel> narx(const IdData& data, const NarxOptions& options = {});
/// The workflow on several records of one system (frols/narmax on records).
Result<NarxModel> narx(const std::vector<IdData>& data, const NarxOptions& options = {});

/// The settings tables (estimate/options.hpp).
template <>
const OptionTable<FrolsOptions>& option_table<FrolsOptions>();
template <>
const OptionTable<NarmaxOptions>& option_table<NarmaxOptions>();
template <>
const OptionTable<NarxOptions>& option_table<NarxOptions>();

}  // namespace ctid
