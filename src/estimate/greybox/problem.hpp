// ctid — the grey-box output-error problem over a record set (include/ctid/estimate/greybox/greybox.hpp): the constraints
// resolved, the records stacked, the output weights, the search vector
//     v = [free parameters (pf) | estimated initial states of record 1 (nx0) | of record 2 (nx0) | ..]
// with its bounds and start, and the weighted residuals w_j (y_j - yhat_j) of a simulation from the start of every
// record with their Jacobian from the model's exact forward sensitivities (Ljung 1999 §7.3; Bohlin 2006).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "ctid/estimate/greybox/greybox.hpp"
#include "data/record_refs.hpp"
#include "internal/levenberg_marquardt.hpp"

namespace ctid::greybox_detail {

// One record as the search sees it.
struct Record {
  Eigen::MatrixXd u;
  Eigen::VectorXd t, y;  // y: the outputs stacked column by column (N ny)
  Intersample hold = Intersample::Zoh;
  Eigen::Index start = 0;  // first row in the stacked residual
  int n = 0;
};

class Problem {
 public:
  /// Throws InvalidArgument for records that do not match the model, too few samples, unknown names in the options.
  Problem(const internal::RecordRefs& records, const GreyboxModel& model, const GreyboxOptions& options);

  const GreyboxModel& model;
  const GreyboxOptions& opt;
  int E = 0, ny = 0, np = 0, nx = 0;
  ParameterConstraints cons;
  Eigen::VectorXd theta0;        // the model's parameters with the held ones at their values
  std::vector<int> free;         // the free parameters' indices
  std::vector<int> free_x0;      // the estimated initial states' indices
  int pf = 0, nx0 = 0, p = 0;    // free parameters, estimated states per record, length of v
  std::vector<Record> rec;
  int N = 0;                     // samples of all records
  Eigen::VectorXd w;             // the output weights
  Eigen::VectorXd y, wy;         // the outputs of all records stacked (record by record, output by output), weighted
  Eigen::VectorXd lo, hi, v0;    // bounds and start of v
  std::string escape;            // the message of the last simulation that escaped

  /// The model at the search vector v (its first pf entries; the held parameters at their values).
  GreyboxModel model_at(const Eigen::VectorXd& v) const;
  /// Record e's initial state at v for the model m = model_at(v): initial-state expressions of parameters move with
  /// them, estimated states come from v, the others from the record's guess (model.initial_state_guess).
  Eigen::VectorXd x0_of(const GreyboxModel& m, const Eigen::VectorXd& v, int e) const;
  /// A simulation of record d's inputs u at times t from x0 with the fit's integrator; `auto` switches to BDF for the
  /// rest of the fit once a simulation found the model stiff. (`escape` is the callers' to set.)
  GreyboxSimulation simulate(const GreyboxModel& m, const Record& d, const Eigen::MatrixXd& u, const Eigen::VectorXd& t,
                             const Eigen::VectorXd& x0);
  /// The same with the sensitivities to the free parameters and to the initial states `states`.
  GreyboxSensitivities sensitivities(const GreyboxModel& m, const Record& d, const Eigen::MatrixXd& u,
                                     const Eigen::VectorXd& t, const Eigen::VectorXd& x0, const std::vector<int>& states,
                                     bool x0_from_parameters);
  /// Single shooting: the weighted residuals (and Jacobian) of every record simulated from its start; false (the
  /// message in `escape`) when a simulation escapes.
  bool evaluate(const Eigen::VectorXd& v, Eigen::VectorXd& r, Eigen::MatrixXd* J);
  /// A Levenberg-Marquardt search of the single-shooting problem from v.
  internal::LmResult search(const Eigen::VectorXd& v);
  internal::LmOptions lm_options() const;

 private:
  std::vector<Eigen::VectorXd> guess_;  // each record's initial-state guess
  GreyboxIntegrator integrator_;
};

}  // namespace ctid::greybox_detail
