// ctid — progress reporting and cancellation (docs/architecture.md, "Errors": the library never prints; progress and
// cancellation go through a callback). A callback installed for the current thread by ProgressScope is
// called by the iterative estimators once per iteration (SRIVC and its delay search; every
// Levenberg-Marquardt fit: output error, physical parameters, NDE refinement; FROLS term selection; NARMAX
// extended least squares) and once per point by every grid or search (the delay grid, the tau grid, the
// structures of order selection). Returning false asks the estimator to stop: it returns its best iterate so
// far with Termination::Interrupted. The request is sticky within the scope: once the callback has said
// stop, every later report_progress says stop without calling it again, so that a routine running several
// fits stops at the first request (interrupt_requested() tells it).
#pragma once

#include <functional>

namespace ctid {

struct ProgressEvent {
  const char* stage = "";  ///< "srivc", "levenberg_marquardt", "frols", "narmax", "delay_grid", "tau_grid", "select_order"
  int iteration = 0;       ///< 1-based iteration (or selected-term count for FROLS)
  double cost = 0.0;       ///< the stage's current cost where it has one (NaN otherwise)
};

/// true: go on; false: stop and return the best result so far as Interrupted.
using ProgressCallback = std::function<bool(const ProgressEvent&)>;

/// Installs a callback for the current thread for the lifetime of the scope (scopes nest: the previous
/// callback is restored on exit).
class ProgressScope {
 public:
  explicit ProgressScope(ProgressCallback callback);
  ~ProgressScope();
  ProgressScope(const ProgressScope&) = delete;
  ProgressScope& operator=(const ProgressScope&) = delete;

 private:
  ProgressCallback previous_;
  bool previous_stop_ = false;
};

/// Called by estimators: false when the installed callback asks to stop, or asked before in this scope
/// (true when none is installed).
bool report_progress(const char* stage, int iteration, double cost);
/// True once the current scope's callback has asked to stop.
bool interrupt_requested();

}  // namespace ctid
