// ctid — IdData: one input/output experiment (docs/architecture.md).
//
// u is N x nu (nu >= 0; nu = 0 is a free response / time series), y is N x ny (ny >= 1).
// Sample times are either uniform (t_k = t0 + k Ts) or explicit and strictly
// increasing. Each input carries its intersample behaviour: Zoh (held constant from
// t_k to t_{k+1}), Foh (linear between samples) or BandLimited (no assumption; methods
// that need one treat it as Foh and say so). Channel names default to u1.., y1..
// Errors: InvalidArgument naming the sizes / index / value that is wrong.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

namespace ctid {

enum class Intersample { Zoh, Foh, BandLimited };
const char* to_string(Intersample i);
/// "zoh", "foh", "bl"/"bandlimited" (case-insensitive); throws InvalidArgument otherwise.
Intersample intersample_from_string(const std::string& s);

enum class Detrend { Mean, Linear };

/// What detrend() removed, per channel: value(t) = offset + slope * (t - t_ref).
struct TrendInfo {
  Eigen::VectorXd u_offset, u_slope, y_offset, y_slope;
  double t_ref = 0.0;
};

class IdData {
 public:
  IdData() = default;
  /// Uniform sampling: t_k = t0 + k*ts. Throws InvalidArgument for ts <= 0, size
  /// mismatch, fewer than 1 sample, or a NaN/Inf sample (naming channel and row).
  IdData(Eigen::MatrixXd u, Eigen::MatrixXd y, double ts, double t0 = 0.0);
  /// Explicit, strictly increasing sample times t (length N).
  IdData(Eigen::MatrixXd u, Eigen::MatrixXd y, Eigen::VectorXd t);
  /// Samples at the strictly increasing times t, kept as uniform data (Ts = mean step, t0 = t[0]) when every
  /// sample lies within kUniformTimeTolerance * Ts of that grid (a time column written with rounding, or a data
  /// logger's clock jitter), else irregular; the largest distance is uniform_time_deviation(). Used by the file
  /// readers and Python's from_arrays; errors as the constructors.
  static IdData from_times(Eigen::MatrixXd u, Eigen::MatrixXd y, Eigen::VectorXd t);
  /// Largest distance, in units of Ts, of a time given to from_times from the uniform grid the data were read as
  /// (0 for data built uniform or kept irregular). The CLI notes a value above 1e-9.
  double uniform_time_deviation() const { return uniform_deviation_; }
  /// Restores uniform_time_deviation() on a record rebuilt from its ts() and t0() (Python's pickle). Throws
  /// InvalidArgument for irregular data or a value outside [0, kUniformTimeTolerance].
  void set_uniform_time_deviation(double deviation);
  /// from_times's threshold: times within 1e-3 Ts of a uniform grid are uniform samples (e.g. a dSPACE log's
  /// relative clock jitter of 2.4e-5 Ts); the model error of that time shift is of order 1e-3 of one sample's change.
  static constexpr double kUniformTimeTolerance = 1e-3;

  int size() const { return static_cast<int>(y_.rows()); }
  int nu() const { return static_cast<int>(u_.cols()); }
  int ny() const { return static_cast<int>(y_.cols()); }
  bool is_uniform() const { return uniform_; }
  /// Sampling period; for irregular data throws InvalidArgument.
  double ts() const;
  double t0() const { return time(0); }
  double time(int k) const { return uniform_ ? t0_ + k * ts_ : t_(k); }
  Eigen::VectorXd times() const;
  /// Total duration t_{N-1} - t_0.
  double duration() const { return time(size() - 1) - time(0); }

  const Eigen::MatrixXd& u() const { return u_; }
  const Eigen::MatrixXd& y() const { return y_; }

  Intersample intersample(int input) const { return intersample_.at(input); }
  void set_intersample(Intersample i);              ///< all inputs
  void set_intersample(int input, Intersample i);

  const std::vector<std::string>& input_names() const { return input_names_; }
  const std::vector<std::string>& output_names() const { return output_names_; }
  const std::vector<std::string>& input_units() const { return input_units_; }
  const std::vector<std::string>& output_units() const { return output_units_; }
  void set_input_names(std::vector<std::string> names);
  void set_output_names(std::vector<std::string> names);
  void set_input_units(std::vector<std::string> units);
  void set_output_units(std::vector<std::string> units);
  /// Index of a channel by name; throws InvalidArgument listing the known names.
  int input_index(const std::string& name) const;
  int output_index(const std::string& name) const;

  /// Samples [begin, end) as a new experiment (times preserved).
  IdData slice(int begin, int end) const;
  /// Keep only the given input and output channels (in that order).
  IdData select(const std::vector<int>& inputs, const std::vector<int>& outputs) const;
  /// The first n samples and the rest (0 < n < size()).
  std::pair<IdData, IdData> split(int n_first) const;
  /// Split by fraction in (0, 1): first round(fraction*N) samples for estimation.
  std::pair<IdData, IdData> split(double fraction) const;
  /// Remove the mean or a least-squares line (in time) from every channel.
  IdData detrend(Detrend kind, TrendInfo* removed = nullptr) const;
  /// Subtract a trend found on another record (detrend's `removed`): offset + slope * (t - t_ref) per channel, at
  /// this record's times. A validation record is treated so, with the estimation record's trend, so that no
  /// statistic of the validation record enters the model. Throws InvalidArgument when the channel counts differ.
  IdData remove_trend(const TrendInfo& trend) const;

 private:
  void check_and_init();
  Eigen::MatrixXd u_, y_;
  Eigen::VectorXd t_;  // only for irregular data
  double ts_ = 0.0, t0_ = 0.0;
  bool uniform_ = true;
  double uniform_deviation_ = 0.0;  // uniform_time_deviation()
  std::vector<Intersample> intersample_;
  std::vector<std::string> input_names_, output_names_, input_units_, output_units_;
};

/// The checks every estimator makes on its record (one place, so that C++, Python and the CLI refuse alike):
/// `nu` inputs and `ny` outputs (-1: any number), and no constant channel — a constant input excites nothing (a
/// step response needs samples before the step) and a constant output leaves nothing to fit. Throws
/// InvalidArgument naming `who`, the channel and its value.
void require_io_data(const IdData& data, const char* who, int nu = 1, int ny = 1);

}  // namespace ctid
