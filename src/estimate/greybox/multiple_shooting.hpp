// ctid — multiple shooting of the grey-box problem (Bock & Plitt 1984, "A multiple shooting algorithm for direct
// solution of optimal control problems"; Bock 1983 for parameter estimation): each record is cut into segments,
// segment k > 0 starts from free states s_k, and continuity x_end(k-1) = s_k is imposed by penalty residuals
// rho_i (x_end,i - s_k,i), rho_i = mu / scale_i, with mu raised over three searches (1, 1e2, 1e4 times the RMS
// weighted output) so that the last leaves defects at rounding level. An unstable or integrating plant then never
// runs free over the whole record while the search is far from the optimum. The search vector is
// [v (problem.p) | the segment states]; its Jacobian is block sparse (a segment's rows depend on the parameters and
// its own start only) and the normal equations are solved sparse (internal/levenberg_marquardt.hpp).
#pragma once

#include <string>
#include <vector>

#include "estimate/greybox/problem.hpp"

namespace ctid::greybox_detail {

/// Multiple shooting when the options ask for it (segments > 1) or, automatically (segments = 0), when the free
/// run from the problem's start escapes or fits below -900 %.
bool wants_multiple_shooting(Problem& problem);

// A segment of a record: samples first .. first + rows (its inputs and times, one sample beyond the rows whose outputs
// it owns: the next segment's start, where continuity is imposed; the last owns its end).
struct Segment {
  Eigen::MatrixXd u;
  Eigen::VectorXd t;
  int first = 0, rows = 0;
};

class MultipleShooting {
 public:
  /// Cuts every record into `segments` segments (> 1), or automatically (0) into segments of 100 samples, halved
  /// (down to 4) until every segment simulates from the problem's start.
  MultipleShooting(Problem& problem, int segments);

  /// One multiple-shooting search from v (length problem.p) through the three penalty stages; its x is the whole
  /// vector (the segment states after the problem's v), its iterations those of all stages.
  internal::LmResult search(const Eigen::VectorXd& v);

  /// The end of a multiple-shooting fit whose best search is `best`: the single-shooting search from its estimate
  /// where the fitted model runs free, taken when its cost is within 5 % of the segments' output cost (a stable or
  /// integrating plant: it ends at the output-error optimum itself). Otherwise (an unstable plant: the free run
  /// escapes or drifts) the multiple-shooting estimate stands, its information the Schur complement of the segment
  /// states' block, `segment_fit` the segments' weighted outputs, and a warning says so.
  void settle(internal::LmResult& best, Eigen::VectorXd& segment_fit, std::vector<std::string>& warnings);

  int segments() const;         ///< segments of all records
  double defect() const { return defect_; }  ///< the largest continuity defect relative to the state's scale

 private:
  bool evaluate(const Eigen::VectorXd& vm, Eigen::VectorXd& r, Eigen::SparseMatrix<double>* J);
  Eigen::VectorXd segment_guess(const Eigen::VectorXd& v, bool& ok);
  void cut(int S_given, int length);

  Problem& P_;
  std::vector<std::vector<Segment>> seg_;
  std::vector<int> offset_;  // each record's first segment state in the vector
  int ns_ = 0;               // segment states in all
  Eigen::VectorXd scale_, rho_;
  double mu_base_ = 1.0;
  std::vector<int> all_states_;
  std::vector<Eigen::Triplet<double>> nz_;
  double defect_ = NAN;
};

}  // namespace ctid::greybox_detail
