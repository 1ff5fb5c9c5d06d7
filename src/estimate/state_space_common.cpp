// State-space estimators' shared scales and fits — see estimate/state_space_common.hpp.
#include "estimate/state_space_common.hpp"

#include <cmath>

#include "ctid/validate/metrics.hpp"

namespace ctid::ss_detail {

Eigen::VectorXd channel_scales(std::span<const IdData> records, bool outputs) {
  const Eigen::Index n = outputs ? records.front().ny() : records.front().nu();
  Eigen::VectorXd s(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    double sum = 0.0, count = 0.0, squares = 0.0;
    for (const IdData& d : records) {
      sum += (outputs ? d.y() : d.u()).col(j).sum();
      count += static_cast<double>(d.size());
    }
    const double mean = sum / count;
    for (const IdData& d : records) squares += ((outputs ? d.y() : d.u()).col(j).array() - mean).square().sum();
    const double v = std::sqrt(squares / count);
    s(j) = v > 0 && std::isfinite(v) ? v : 1.0;
  }
  return s;
}

Fits fits_of(std::span<const IdData> records, std::span<const Eigen::MatrixXd> yhat, const Eigen::VectorXd& sy,
             int n_parameters) {
  const Eigen::Index ny = records.front().ny();
  Eigen::Index n = 0;
  for (const IdData& d : records) n += d.size();
  Eigen::VectorXd y(n * ny), h(n * ny), yj(n), hj(n);
  Fits f;
  f.per_output.resize(ny);
  for (Eigen::Index j = 0; j < ny; ++j) {
    Eigen::Index at = 0;
    for (size_t e = 0; e < records.size(); ++e) {
      const Eigen::Index m = records[e].size();
      yj.segment(at, m) = records[e].y().col(j);
      hj.segment(at, m) = yhat[e].col(j);
      at += m;
    }
    f.per_output(j) = fit_report_or_inf(yj, hj, n_parameters).fit_percent;
    // Each output about its own mean and scale, so that every output counts alike in the overall fit.
    const double mean = yj.mean();
    y.segment(j * n, n) = (yj.array() - mean) / sy(j);
    h.segment(j * n, n) = (hj.array() - mean) / sy(j);
  }
  f.all = fit_report_or_inf(y, h, n_parameters);
  return f;
}

}  // namespace ctid::ss_detail
