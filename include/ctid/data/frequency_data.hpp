// ctid — frequency-response data: G(j w_k) at angular frequencies w_k (rad/s), one channel or an ny x nu matrix per
// frequency, from a measured response, from input/output spectra (G = Y / U), or from periodic records averaged over
// their periods (frf_from_periodic).
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "ctid/data/iddata.hpp"

namespace ctid {

class FrequencyData {
 public:
  FrequencyData() = default;
  /// One input, one output: w strictly increasing and > 0 (rad/s), G finite, same length >= 1. Throws
  /// InvalidArgument naming the first offending index and values.
  FrequencyData(Eigen::VectorXd w, Eigen::VectorXcd G);
  /// Several inputs and outputs: G[k] is the ny x nu response at w[k] (all the same size). `variance`, when not
  /// empty, holds one ny x nu matrix per frequency: the variance E|G_hat - G|^2 of each complex entry (positive and
  /// finite), e.g. from the spread over periods; estimators weight by its inverse. Throws InvalidArgument as above.
  FrequencyData(Eigen::VectorXd w, std::vector<Eigen::MatrixXcd> G, std::vector<Eigen::MatrixXd> variance = {});
  /// From input and output spectra at w: G = Y / U (U must be non-zero).
  static FrequencyData from_spectra(const Eigen::VectorXd& w, const Eigen::VectorXcd& U, const Eigen::VectorXcd& Y);
  int size() const { return static_cast<int>(w_.size()); }
  int outputs() const { return g_.empty() ? 0 : static_cast<int>(g_.front().rows()); }
  int inputs() const { return g_.empty() ? 0 : static_cast<int>(g_.front().cols()); }
  const Eigen::VectorXd& w() const { return w_; }
  /// The response of a one-input one-output data set; throws InvalidArgument for several channels (see channel).
  const Eigen::VectorXcd& response() const;
  /// G_out,in(j w_k) over the frequencies (0-based indices).
  Eigen::VectorXcd channel(int out, int in) const;
  /// The ny x nu response matrices, one per frequency.
  const std::vector<Eigen::MatrixXcd>& matrices() const { return g_; }
  /// The variances of the entries (empty when not known).
  const std::vector<Eigen::MatrixXd>& variance() const { return var_; }
  /// Channel names (from the records of frf_from_periodic; empty otherwise).
  std::vector<std::string> input_names, output_names;

 private:
  Eigen::VectorXd w_;
  std::vector<Eigen::MatrixXcd> g_;
  std::vector<Eigen::MatrixXd> var_;
  Eigen::VectorXcd siso_;
};

/// The mean period of a periodic record: the record (uniformly sampled) cut into periods of `period` samples, the
/// first `skip` periods dropped (their transient), the rest averaged sample by sample — noise variance divided by
/// the number of periods averaged, the steady-state response kept. The result has `period` samples, the record's
/// sample period, start time and channel names. Throws InvalidArgument for irregular sampling, period < 2, skip < 0,
/// or a record shorter than skip + 1 periods.
IdData average_periods(const IdData& data, int period, int skip = 1);

/// The FRF matrix of periodic records (Pintelon & Schoukens 2012, "System Identification: A Frequency Domain
/// Approach", 2nd ed., §2.4 and §7.2: the nonparametric estimate from periodic excitations). Each record holds
/// whole periods of `period` samples (uniform sampling, all with the same sample period), the first `skip` periods
/// dropped; the spectra of each period at DFT bins k = 1 .. period/2 - 1 (w_k = 2 pi k / (period Ts)). A bin is
/// kept where the inputs are excited: the largest input amplitude at k (mean over periods) is at least `excited`
/// times the largest over all bins. G = Ybar Ubar^-1 with Ubar the nu x records matrix of the records' mean input
/// spectra (records = nu experiments with linearly independent inputs; one record for one input), and the variance
/// of each entry the sample variance of the per-period estimates G_p = Y_p U_p^-1 over the P periods divided by P
/// (it includes the input's noise to first order; not the systematic nonlinear distortion of one realisation).
/// Throws InvalidArgument naming the problem when the records differ in channels or sample period, fewer than
/// skip + 2 periods remain (two are needed for a variance), the number of records is not nu, or Ubar is singular
/// at an excited bin.
FrequencyData frf_from_periodic(const std::vector<IdData>& records, int period, int skip = 1, double excited = 0.1);

}  // namespace ctid
