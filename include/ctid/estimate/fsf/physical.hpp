// ctid — stage 2 of Gawthrop & Wang (2005): Levenberg-Marquardt estimation of the physical
// parameters Theta of a partially known model (GW 22-23, time domain; GW 30, frequency
// domain), with the exponential shift s -> s + a of the unstable case (GW §3.2); and the
// direct output-error route on raw data for comparison. Sensitivities are exact
// (PhysicalModel::sensitivities, simulated exactly). Gawthrop & Wang 2005, §§3-4.
#pragma once

#include <limits>
#include <map>
#include <string>
#include <vector>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/model/fsf.hpp"
#include "ctid/model/physical_model.hpp"
#include "ctid/estimate/options.hpp"

namespace ctid {

struct PhysicalParameter {
  std::string name;
  double initial = std::numeric_limits<double>::quiet_NaN();  ///< required
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  bool fixed = false;
};

struct PhysicalFitOptions {
  int max_iterations = 500;  ///< Levenberg-Marquardt iterations (a well-posed fit converges long before)
  double tolerance = 1e-12;
  int step_points = 1000;   ///< samples of the compressed step response on [0, T] (step route)
  /// Raw route: estimate each record's initial state instead of starting it from rest — the free response of the
  /// model's realisation, eliminated by variable projection so that the parameters' covariance accounts for it;
  /// diagnostics x0 per record (in the fitted transfer function's realisation, what simulate/validate start from).
  /// The FSF routes refuse it (they compress the record from rest).
  bool estimate_initial_state = false;
  /// Parameters held at a value, by name — the constraint vocabulary of every estimator (oe, lssvf, rls_svf):
  /// applied on top of the PhysicalParameter declarations (a parameter fixed here needs no declaration).
  FixedValues fixed;
  /// Bounds [lower, upper] by name, on top of the declarations' lower/upper.
  ParameterBounds bounds;
  void validate() const;
};
/// The settings of PhysicalFitOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<PhysicalFitOptions>& option_table<PhysicalFitOptions>();

/// Fit to the compressed step response of `compressed` (whose shift a is applied to the
/// model). `parameters` gives every parameter of `model` (same names, any order). Throws
/// InvalidArgument / InvalidOptions for a missing or unknown parameter, a missing initial
/// value, or empty bounds. The model returned is the unshifted G(s; Theta).
/// data: the record `compressed` was fitted to. When given, fit is the simulation fit on it (from rest; windowed by
/// e^{-at} for a > 0, as the raw route measures it); otherwise no fit is computed (fit.n_samples = 0). The model's
/// match to the compressed response itself is diagnostics "compressed_fit_percent".
Result<TransferFunction> fit_physical_step(const PhysicalModel& model, const std::vector<PhysicalParameter>& parameters,
                                           const FsfModel& compressed, const PhysicalFitOptions& options = {},
                                           const IdData* data = nullptr);
/// Fit to the compressed frequency response theta_k = G(jk Omega + a), k = 0..m (GW 30); data and fit as above.
Result<TransferFunction> fit_physical_frequency(const PhysicalModel& model, const std::vector<PhysicalParameter>& parameters,
                                                const FsfModel& compressed, const PhysicalFitOptions& options = {},
                                                const IdData* data = nullptr);
/// Output error on the raw record, windowed by e^{-at} when a > 0: the shifted model
/// G(s + a) is fitted to y_a = e^{-at} y, simulated exactly for the windowed held input
/// e^{-at} u_k (the window's generator is part of the simulated state). a > 0 needs uniform
/// sampling and a ZOH input.
Result<TransferFunction> fit_physical_raw(const PhysicalModel& model, const std::vector<PhysicalParameter>& parameters,
                                          const IdData& data, double a = 0.0, const PhysicalFitOptions& options = {});
/// Several experiments of one system: the records' output errors stacked (each simulated from rest and, for a > 0,
/// windowed from its own start), one parameter set; diagnostics "experiments".
Result<TransferFunction> fit_physical_raw(const PhysicalModel& model, const std::vector<PhysicalParameter>& parameters,
                                          const std::vector<IdData>& data, double a = 0.0,
                                          const PhysicalFitOptions& options = {});

}  // namespace ctid
