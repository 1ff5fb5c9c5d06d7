// ctid — goodness-of-fit metrics (definitions in ctid::FitReport, core/types.hpp).
#pragma once

#include <string>

#include <Eigen/Dense>

#include "ctid/core/types.hpp"

namespace ctid {

/// 100 (1 - ||y - yhat|| / ||y - mean(y)||). Throws InvalidArgument for size mismatch,
/// fewer than 2 samples or a constant y.
double fit_percent(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat);

/// A fit in percent as text for people: two decimals ("87.25"), three significant digits when its magnitude is
/// 10 000 or more ("-1.23e+138": the simulation of an unusable model that diverges), "nan", "inf" or "-inf".
std::string fit_percent_text(double fit_percent);
/// ||y - yhat|| / ||y - mean(y)||.
double nrmse(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat);
/// mean((y - yhat)^2).
double mse(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat);
/// Akaike's final prediction error V (1 + d/N) / (1 - d/N); +Inf when d >= N.
double fpe(double mse, int n_samples, int n_parameters);
/// N ln V + 2 d.
double aic(double mse, int n_samples, int n_parameters);
/// AIC + 2 d (d + 1) / (N - d - 1); +Inf when N - d - 1 <= 0.
double aicc(double mse, int n_samples, int n_parameters);
/// N ln V + d ln N.
double bic(double mse, int n_samples, int n_parameters);
/// All of the above for measured y and model output yhat with d free parameters.
/// Throws InvalidArgument for size mismatch, fewer than 2 samples or a constant y.
FitReport fit_report(const Eigen::Ref<const Eigen::VectorXd>& y, const Eigen::Ref<const Eigen::VectorXd>& yhat,
                     int n_parameters);
/// The same, but a non-finite model output (an unstable simulation) or a constant y gives
/// fit_percent = -Inf and +Inf errors instead of an exception. Used for estimators' reports.
FitReport fit_report_or_inf(const Eigen::Ref<const Eigen::VectorXd>& y, const Eigen::Ref<const Eigen::VectorXd>& yhat,
                            int n_parameters);
/// fit_report_or_inf from sums accumulated elsewhere (a fit streamed block by block): sse = sum (y - yhat)^2 and
/// sst = sum (y - mean(y))^2 over n_samples.
FitReport fit_report_from_sums(double sse, double sst, int n_samples, int n_parameters);

}  // namespace ctid
