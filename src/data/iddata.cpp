#include "ctid/data/iddata.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "ctid/core/check.hpp"

namespace ctid {

const char* to_string(Intersample i) {
  switch (i) {
    case Intersample::Zoh: return "zoh";
    case Intersample::Foh: return "foh";
    case Intersample::BandLimited: return "bl";
  }
  CTID_ASSERT(false);
}

Intersample intersample_from_string(const std::string& s) {
  std::string l = s;
  std::transform(l.begin(), l.end(), l.begin(), [](unsigned char c) { return std::tolower(c); });
  if (l == "zoh") return Intersample::Zoh;
  if (l == "foh") return Intersample::Foh;
  if (l == "bl" || l == "bandlimited") return Intersample::BandLimited;
  throw InvalidArgument(detail::format("unknown intersample behaviour '{}' (use zoh, foh or bl)", s));
}

IdData::IdData(Eigen::MatrixXd u, Eigen::MatrixXd y, double ts, double t0)
    : u_(std::move(u)), y_(std::move(y)), ts_(ts), t0_(t0), uniform_(true) {
  CTID_REQUIRE(std::isfinite(ts) && ts > 0, "IdData: the sampling period must be positive and finite (got Ts = {})", ts);
  CTID_REQUIRE(std::isfinite(t0), "IdData: the start time must be finite (got t0 = {})", t0);
  check_and_init();
}

IdData::IdData(Eigen::MatrixXd u, Eigen::MatrixXd y, Eigen::VectorXd t)
    : u_(std::move(u)), y_(std::move(y)), t_(std::move(t)), uniform_(false) {
  CTID_REQUIRE(t_.size() == y_.rows(), "IdData: the time vector and y need the same number of samples (t has {}, y has {})",
               t_.size(), y_.rows());
  for (Eigen::Index k = 0; k < t_.size(); ++k) {
    CTID_REQUIRE(std::isfinite(t_(k)), "IdData: sample time {} is not finite ({})", k, t_(k));
    if (k > 0)
      CTID_REQUIRE(t_(k) > t_(k - 1), "IdData: sample times must be strictly increasing (t[{}] = {} follows t[{}] = {})", k,
                   t_(k), k - 1, t_(k - 1));
  }
  check_and_init();
}

IdData IdData::from_times(Eigen::MatrixXd u, Eigen::MatrixXd y, Eigen::VectorXd t) {
  const Eigen::Index N = t.size();
  CTID_REQUIRE(N == y.rows() && (u.cols() == 0 || N == u.rows()),
               "IdData: the time vector has {} samples but y has {} (and u {}); give one time per sample", N, y.rows(),
               u.rows());
  if (N > 1 && t.allFinite()) {
    const double h = (t(N - 1) - t(0)) / double(N - 1);
    double deviation = 0.0;  // the largest |t_k - (t_0 + k h)| / h
    for (Eigen::Index k = 1; k < N && h > 0 && deviation <= kUniformTimeTolerance; ++k)
      deviation = std::max(deviation, std::abs(t(k) - (t(0) + double(k) * h)) / h);
    if (h > 0 && deviation <= kUniformTimeTolerance) {
      IdData d(std::move(u), std::move(y), h, t(0));
      d.uniform_deviation_ = deviation;
      return d;
    }
  }
  return IdData(std::move(u), std::move(y), std::move(t));
}

void IdData::set_uniform_time_deviation(double deviation) {
  CTID_REQUIRE(uniform_, "IdData: irregular data have no uniform time deviation");
  CTID_REQUIRE(deviation >= 0 && deviation <= kUniformTimeTolerance,
               "IdData: the uniform time deviation must be in [0, {}] sampling periods (got {})", kUniformTimeTolerance,
               deviation);
  uniform_deviation_ = deviation;
}

void IdData::check_and_init() {
  CTID_REQUIRE(y_.cols() >= 1, "IdData: at least one output channel is needed (y has {} columns)", y_.cols());
  CTID_REQUIRE(y_.rows() >= 1, "IdData: at least one sample is needed (y has {} rows)", y_.rows());
  CTID_REQUIRE(u_.rows() == y_.rows() || u_.cols() == 0,
               "IdData: u and y need the same number of samples (u has {}, y has {})", u_.rows(), y_.rows());
  if (u_.cols() == 0) u_.resize(y_.rows(), 0);
  for (Eigen::Index j = 0; j < u_.cols(); ++j)
    for (Eigen::Index k = 0; k < u_.rows(); ++k)
      CTID_REQUIRE(std::isfinite(u_(k, j)), "IdData: input {} has a non-finite value ({}) at sample {}", j + 1, u_(k, j), k);
  for (Eigen::Index j = 0; j < y_.cols(); ++j)
    for (Eigen::Index k = 0; k < y_.rows(); ++k)
      CTID_REQUIRE(std::isfinite(y_(k, j)), "IdData: output {} has a non-finite value ({}) at sample {}", j + 1, y_(k, j), k);
  intersample_.assign(nu(), Intersample::Zoh);
  input_names_.clear();
  output_names_.clear();
  auto channel = [](char prefix, int j) {  // "u1", "y2", ... (append: avoids a GCC 12 -Wrestrict false positive)
    std::string s(1, prefix);
    s += std::to_string(j + 1);
    return s;
  };
  for (int j = 0; j < nu(); ++j) input_names_.push_back(channel('u', j));
  for (int j = 0; j < ny(); ++j) output_names_.push_back(channel('y', j));
  input_units_.assign(nu(), "");
  output_units_.assign(ny(), "");
}

double IdData::ts() const {
  CTID_REQUIRE(uniform_, "IdData: the data are irregularly sampled ({} samples over {} s); no single Ts", size(), duration());
  return ts_;
}

Eigen::VectorXd IdData::times() const {
  if (!uniform_) return t_;
  Eigen::VectorXd t(size());
  for (int k = 0; k < size(); ++k) t(k) = time(k);
  return t;
}

void IdData::set_intersample(Intersample i) { intersample_.assign(nu(), i); }
void IdData::set_intersample(int input, Intersample i) {
  CTID_REQUIRE(input >= 0 && input < nu(), "IdData: input index {} out of range (data has {} inputs)", input, nu());
  intersample_[input] = i;
}

namespace {
void check_count(const std::vector<std::string>& v, int n, const char* what) {
  CTID_REQUIRE(static_cast<int>(v.size()) == n, "IdData: {} needs {} entries (got {})", what, n, v.size());
}
int find_name(const std::vector<std::string>& names, const std::string& name, const char* what) {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  std::string known;
  for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
  throw InvalidArgument(detail::format("IdData: no {} named '{}' (known: {})", what, name, known));
}
}  // namespace

void IdData::set_input_names(std::vector<std::string> names) { check_count(names, nu(), "input names"); input_names_ = std::move(names); }
void IdData::set_output_names(std::vector<std::string> names) { check_count(names, ny(), "output names"); output_names_ = std::move(names); }
void IdData::set_input_units(std::vector<std::string> units) { check_count(units, nu(), "input units"); input_units_ = std::move(units); }
void IdData::set_output_units(std::vector<std::string> units) { check_count(units, ny(), "output units"); output_units_ = std::move(units); }
int IdData::input_index(const std::string& name) const { return find_name(input_names_, name, "input"); }
int IdData::output_index(const std::string& name) const { return find_name(output_names_, name, "output"); }

IdData IdData::slice(int begin, int end) const {
  CTID_REQUIRE(begin >= 0 && end <= size() && begin < end, "IdData: slice [{}, {}) is not inside [0, {})", begin, end, size());
  IdData d = *this;
  d.u_ = u_.middleRows(begin, end - begin);
  d.y_ = y_.middleRows(begin, end - begin);
  if (uniform_) d.t0_ = time(begin);
  else d.t_ = t_.segment(begin, end - begin);
  return d;
}

IdData IdData::select(const std::vector<int>& inputs, const std::vector<int>& outputs) const {
  CTID_REQUIRE(!outputs.empty(), "IdData: select needs at least one output");
  Eigen::MatrixXd u(size(), inputs.size()), y(size(), outputs.size());
  IdData d = *this;
  d.input_names_.clear(); d.input_units_.clear(); d.intersample_.clear();
  d.output_names_.clear(); d.output_units_.clear();
  for (std::size_t j = 0; j < inputs.size(); ++j) {
    CTID_REQUIRE(inputs[j] >= 0 && inputs[j] < nu(), "IdData: input index {} out of range (data has {} inputs)", inputs[j], nu());
    u.col(j) = u_.col(inputs[j]);
    d.input_names_.push_back(input_names_[inputs[j]]);
    d.input_units_.push_back(input_units_[inputs[j]]);
    d.intersample_.push_back(intersample_[inputs[j]]);
  }
  for (std::size_t j = 0; j < outputs.size(); ++j) {
    CTID_REQUIRE(outputs[j] >= 0 && outputs[j] < ny(), "IdData: output index {} out of range (data has {} outputs)", outputs[j], ny());
    y.col(j) = y_.col(outputs[j]);
    d.output_names_.push_back(output_names_[outputs[j]]);
    d.output_units_.push_back(output_units_[outputs[j]]);
  }
  d.u_ = std::move(u);
  d.y_ = std::move(y);
  return d;
}

std::pair<IdData, IdData> IdData::split(int n_first) const {
  CTID_REQUIRE(n_first > 0 && n_first < size(), "IdData: split point {} must be inside (0, {})", n_first, size());
  return {slice(0, n_first), slice(n_first, size())};
}

std::pair<IdData, IdData> IdData::split(double fraction) const {
  CTID_REQUIRE(fraction > 0 && fraction < 1, "IdData: split fraction must be in (0, 1) (got {})", fraction);
  return split(static_cast<int>(std::lround(fraction * size())));
}

IdData IdData::detrend(Detrend kind, TrendInfo* removed) const {
  IdData d = *this;
  const Eigen::VectorXd t = times();
  const double tref = t(0);
  const Eigen::VectorXd tc = t.array() - tref;
  TrendInfo info;
  info.t_ref = tref;
  auto fit = [&](Eigen::MatrixXd& m, Eigen::VectorXd& off, Eigen::VectorXd& slope) {
    off.resize(m.cols());
    slope.setZero(m.cols());
    for (Eigen::Index j = 0; j < m.cols(); ++j) {
      if (kind == Detrend::Mean || m.rows() < 2) {
        off(j) = m.col(j).mean();
      } else {
        const double tm = tc.mean(), ym = m.col(j).mean();
        const double stt = (tc.array() - tm).square().sum();
        slope(j) = ((tc.array() - tm) * (m.col(j).array() - ym)).sum() / stt;
        off(j) = ym - slope(j) * tm;
      }
      m.col(j).array() -= off(j) + slope(j) * tc.array();
    }
  };
  fit(d.u_, info.u_offset, info.u_slope);
  fit(d.y_, info.y_offset, info.y_slope);
  if (removed) *removed = info;
  return d;
}

IdData IdData::remove_trend(const TrendInfo& trend) const {
  CTID_REQUIRE(trend.u_offset.size() == nu() && trend.y_offset.size() == ny() && trend.u_slope.size() == nu() &&
                   trend.y_slope.size() == ny(),
               "IdData: the trend is of {} input(s) and {} output(s); the record has {} and {}", trend.u_offset.size(),
               trend.y_offset.size(), nu(), ny());
  IdData d = *this;
  const Eigen::ArrayXd tc = times().array() - trend.t_ref;
  for (Eigen::Index j = 0; j < d.u_.cols(); ++j) d.u_.col(j).array() -= trend.u_offset(j) + trend.u_slope(j) * tc;
  for (Eigen::Index j = 0; j < d.y_.cols(); ++j) d.y_.col(j).array() -= trend.y_offset(j) + trend.y_slope(j) * tc;
  return d;
}

void require_io_data(const IdData& d, const char* who, int nu, int ny) {
  CTID_REQUIRE((nu < 0 || d.nu() == nu) && (ny < 0 || d.ny() == ny),
               "{}: needs {} input(s) and {} output(s) (the data have {} and {}); select channels first", who,
               nu < 0 ? std::string("any number of") : std::to_string(nu), ny < 0 ? std::string("any number of") : std::to_string(ny),
               d.nu(), d.ny());
  // (the column read in place)
  auto constant = [](const Eigen::Ref<const Eigen::VectorXd>& v) { return v.size() > 0 && v.maxCoeff() == v.minCoeff(); };
  for (int i = 0; i < d.nu(); ++i)
    CTID_REQUIRE(!constant(d.u().col(i)),
                 "{}: input '{}' is constant ({}) over the whole record: it excites nothing (a step response needs samples "
                 "before the step)",
                 who, d.input_names()[i], d.u()(0, i));
  for (int i = 0; i < d.ny(); ++i)
    CTID_REQUIRE(!constant(d.y().col(i)), "{}: output '{}' is constant ({}) over the whole record: there is nothing to fit",
                 who, d.output_names()[i], d.y()(0, i));
}

}  // namespace ctid
