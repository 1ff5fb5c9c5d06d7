// ctid — frequency-response data (data/frequency_data.hpp); period averaging and the FRF of periodic records
// (Pintelon & Schoukens 2012, §2.4, §7.2).
#include "ctid/data/frequency_data.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include <unsupported/Eigen/FFT>

#include "ctid/core/check.hpp"

namespace ctid {

namespace {

void check_frequencies(const Eigen::VectorXd& w) {
  CTID_REQUIRE(w.size() >= 1, "FrequencyData: at least one frequency is needed");
  for (Eigen::Index k = 0; k < w.size(); ++k) {
    CTID_REQUIRE(std::isfinite(w(k)) && w(k) > 0, "FrequencyData: frequency {} must be positive and finite (got {} rad/s)",
                 k, w(k));
    CTID_REQUIRE(k == 0 || w(k) > w(k - 1),
                 "FrequencyData: frequencies must be strictly increasing (w[{}] = {} after w[{}] = {})", k, w(k), k - 1,
                 w(k - 1));
  }
}

}  // namespace

FrequencyData::FrequencyData(Eigen::VectorXd w, Eigen::VectorXcd G) : w_(std::move(w)), siso_(std::move(G)) {
  check_frequencies(w_);
  CTID_REQUIRE(w_.size() == siso_.size(), "FrequencyData: {} frequencies but {} response values", w_.size(),
               siso_.size());
  for (Eigen::Index k = 0; k < w_.size(); ++k) {
    CTID_REQUIRE(std::isfinite(siso_(k).real()) && std::isfinite(siso_(k).imag()),
                 "FrequencyData: response value {} is not finite", k);
    g_.push_back(Eigen::MatrixXcd::Constant(1, 1, siso_(k)));
  }
}

FrequencyData::FrequencyData(Eigen::VectorXd w, std::vector<Eigen::MatrixXcd> G, std::vector<Eigen::MatrixXd> variance)
    : w_(std::move(w)), g_(std::move(G)), var_(std::move(variance)) {
  check_frequencies(w_);
  CTID_REQUIRE(static_cast<size_t>(w_.size()) == g_.size(), "FrequencyData: {} frequencies but {} response matrices",
               w_.size(), g_.size());
  CTID_REQUIRE(var_.empty() || var_.size() == g_.size(), "FrequencyData: {} response matrices but {} variance matrices",
               g_.size(), var_.size());
  const Eigen::Index ny = g_.front().rows(), nu = g_.front().cols();
  CTID_REQUIRE(ny >= 1 && nu >= 1, "FrequencyData: the response matrices are empty ({} x {})", ny, nu);
  for (size_t k = 0; k < g_.size(); ++k) {
    CTID_REQUIRE(g_[k].rows() == ny && g_[k].cols() == nu, "FrequencyData: response matrix {} is {} x {}, matrix 0 is {} x {}",
                 k, g_[k].rows(), g_[k].cols(), ny, nu);
    CTID_REQUIRE(g_[k].allFinite(), "FrequencyData: response matrix {} (w = {} rad/s) has a non-finite entry", k, w_(k));
    if (var_.empty()) continue;
    CTID_REQUIRE(var_[k].rows() == ny && var_[k].cols() == nu, "FrequencyData: variance matrix {} is {} x {}, not {} x {}",
                 k, var_[k].rows(), var_[k].cols(), ny, nu);
    CTID_REQUIRE(var_[k].allFinite() && (var_[k].array() > 0).all(),
                 "FrequencyData: variance matrix {} (w = {} rad/s) has an entry that is not positive and finite "
                 "(smallest {})", k, w_(k), var_[k].minCoeff());
  }
  if (ny == 1 && nu == 1) siso_ = channel(0, 0);
}

const Eigen::VectorXcd& FrequencyData::response() const {
  CTID_REQUIRE(outputs() == 1 && inputs() == 1,
               "FrequencyData: the data have {} outputs and {} inputs; response() is for one of each (use channel(out, "
               "in))", outputs(), inputs());
  return siso_;
}

Eigen::VectorXcd FrequencyData::channel(int out, int in) const {
  CTID_REQUIRE(out >= 0 && out < outputs() && in >= 0 && in < inputs(),
               "FrequencyData: channel ({}, {}) does not exist ({} outputs, {} inputs)", out, in, outputs(), inputs());
  Eigen::VectorXcd c(size());
  for (int k = 0; k < size(); ++k) c(k) = g_[static_cast<size_t>(k)](out, in);
  return c;
}

FrequencyData FrequencyData::from_spectra(const Eigen::VectorXd& w, const Eigen::VectorXcd& U, const Eigen::VectorXcd& Y) {
  CTID_REQUIRE(U.size() == w.size() && Y.size() == w.size(), "FrequencyData: {} frequencies, {} input and {} output values",
               w.size(), U.size(), Y.size());
  Eigen::VectorXcd G(w.size());
  for (Eigen::Index k = 0; k < w.size(); ++k) {
    CTID_REQUIRE(std::abs(U(k)) > 0, "FrequencyData: the input spectrum is zero at w[{}] = {} rad/s", k, w(k));
    G(k) = Y(k) / U(k);
  }
  return FrequencyData(w, G);
}

namespace {

// Whole periods after the transient: throws unless at least `need` remain.
int periods_of(const IdData& d, int period, int skip, int need, const char* who, size_t record) {
  CTID_REQUIRE(period >= 2, "{}: the period must be at least 2 samples (got {})", who, period);
  CTID_REQUIRE(skip >= 0, "{}: skip must be >= 0 periods (got {})", who, skip);
  CTID_REQUIRE(d.is_uniform(), "{}: record {} is not uniformly sampled (periods are counted in samples)", who, record);
  const int whole = d.size() / period;
  CTID_REQUIRE(whole - skip >= need,
               "{}: record {} has {} samples = {} whole period(s) of {} samples; skipping {} leaves {}, {} needed", who,
               record, d.size(), whole, period, skip, std::max(whole - skip, 0), need);
  return whole - skip;
}

}  // namespace

IdData average_periods(const IdData& data, int period, int skip) {
  const int P = periods_of(data, period, skip, 1, "average_periods", 1);
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(period, data.nu()), y = Eigen::MatrixXd::Zero(period, data.ny());
  for (int p = skip; p < skip + P; ++p) {
    u += data.u().middleRows(static_cast<Eigen::Index>(p) * period, period);
    y += data.y().middleRows(static_cast<Eigen::Index>(p) * period, period);
  }
  IdData out(u / P, y / P, data.ts(), data.t0());
  out.set_input_names(data.input_names());
  out.set_output_names(data.output_names());
  out.set_input_units(data.input_units());
  out.set_output_units(data.output_units());
  for (int j = 0; j < data.nu(); ++j) out.set_intersample(j, data.intersample(j));
  return out;
}

FrequencyData frf_from_periodic(const std::vector<IdData>& records, int period, int skip, double excited) {
  CTID_REQUIRE(!records.empty(), "frf_from_periodic: no records were given");
  CTID_REQUIRE(std::isfinite(excited) && excited > 0 && excited < 1,
               "frf_from_periodic: excited must be in (0, 1) (a fraction of the largest input amplitude; got {})", excited);
  const IdData& first = records.front();
  const int nu = first.nu(), ny = first.ny(), E = static_cast<int>(records.size());
  CTID_REQUIRE(nu >= 1 && ny >= 1, "frf_from_periodic: the records need inputs and outputs (got {} and {})", nu, ny);
  CTID_REQUIRE(E == nu,
               "frf_from_periodic: {} input(s) need {} record(s) with linearly independent excitations (got {})", nu, nu,
               E);
  int P = 1 << 30;
  for (size_t e = 0; e < records.size(); ++e) {
    const IdData& d = records[e];
    CTID_REQUIRE(d.nu() == nu && d.ny() == ny, "frf_from_periodic: record {} has {} inputs and {} outputs, record 1 {} and {}",
                 e + 1, d.nu(), d.ny(), nu, ny);
    CTID_REQUIRE(d.u().allFinite() && d.y().allFinite(), "frf_from_periodic: record {} contains non-finite values", e + 1);
    P = std::min(P, periods_of(d, period, skip, 2, "frf_from_periodic", e + 1));
    CTID_REQUIRE(std::abs(d.ts() - first.ts()) <= 1e-9 * first.ts(),
                 "frf_from_periodic: record {} is sampled every {} s, record 1 every {} s", e + 1, d.ts(), first.ts());
  }
  const int K = period / 2;  // bins 1 .. K-1 (0 and Nyquist carry no phase information of a continuous response)
  // Spectra of every period: S[e][p] is period x (nu + ny).
  Eigen::FFT<double> fft;
  std::vector<std::vector<Eigen::MatrixXcd>> S(static_cast<size_t>(E));
  std::vector<double> in(static_cast<size_t>(period));
  std::vector<std::complex<double>> spectrum;
  for (int e = 0; e < E; ++e) {
    const IdData& d = records[static_cast<size_t>(e)];
    for (int p = skip; p < skip + P; ++p) {
      Eigen::MatrixXcd X(K, nu + ny);
      for (int c = 0; c < nu + ny; ++c) {
        const Eigen::MatrixXd& src = c < nu ? d.u() : d.y();
        const int col = c < nu ? c : c - nu;
        for (int i = 0; i < period; ++i)
          in[static_cast<size_t>(i)] = src(static_cast<Eigen::Index>(p) * period + i, col);
        fft.fwd(spectrum, in);
        for (int k = 0; k < K; ++k) X(k, c) = spectrum[static_cast<size_t>(k)];
      }
      S[static_cast<size_t>(e)].push_back(std::move(X));
    }
  }
  // Excited bins: the largest mean input amplitude at the bin against the largest of all bins.
  Eigen::VectorXd amp = Eigen::VectorXd::Zero(K);
  for (int e = 0; e < E; ++e)
    for (int k = 1; k < K; ++k) {
      Eigen::VectorXcd m = Eigen::VectorXcd::Zero(nu);
      for (int p = 0; p < P; ++p) m += S[static_cast<size_t>(e)][static_cast<size_t>(p)].row(k).head(nu).transpose();
      amp(k) = std::max(amp(k), m.cwiseAbs().maxCoeff() / P);
    }
  const double top = amp.maxCoeff();
  CTID_REQUIRE(top > 0, "frf_from_periodic: the inputs are constant over the periods (no excited frequency)");
  const double h = first.ts();
  std::vector<double> ws;
  std::vector<Eigen::MatrixXcd> Gs;
  std::vector<Eigen::MatrixXd> Vs;
  for (int k = 1; k < K; ++k) {
    if (amp(k) < excited * top) continue;
    Eigen::MatrixXcd Ub = Eigen::MatrixXcd::Zero(nu, E), Yb = Eigen::MatrixXcd::Zero(ny, E);
    std::vector<Eigen::MatrixXcd> Gp;
    for (int p = 0; p < P; ++p) {
      Eigen::MatrixXcd Up(nu, E), Yp(ny, E);
      for (int e = 0; e < E; ++e) {
        const Eigen::MatrixXcd& X = S[static_cast<size_t>(e)][static_cast<size_t>(p)];
        Up.col(e) = X.row(k).head(nu).transpose();
        Yp.col(e) = X.row(k).tail(ny).transpose();
      }
      Ub += Up / P;
      Yb += Yp / P;
      const Eigen::FullPivLU<Eigen::MatrixXcd> lu(Up);
      CTID_REQUIRE(lu.isInvertible(),
                   "frf_from_periodic: the records' inputs are linearly dependent at {} rad/s in period {} (give one "
                   "record per input with independent excitations)", 2 * std::numbers::pi * k / (period * h), p + skip + 1);
      Gp.push_back((lu.solve(Yp.transpose())).transpose());  // Yp Up^-1
    }
    const Eigen::FullPivLU<Eigen::MatrixXcd> lub(Ub);
    CTID_REQUIRE(lub.isInvertible(), "frf_from_periodic: the mean input spectra are linearly dependent at {} rad/s",
                 2 * std::numbers::pi * k / (period * h));
    const Eigen::MatrixXcd G = lub.solve(Yb.transpose()).transpose();
    Eigen::MatrixXcd mean = Eigen::MatrixXcd::Zero(ny, nu);
    for (const auto& g : Gp) mean += g / P;
    Eigen::MatrixXd var = Eigen::MatrixXd::Zero(ny, nu);
    for (const auto& g : Gp) var += (g - mean).cwiseAbs2() / (P - 1);
    var /= P;
    // A bin whose periods agree to rounding: the variance floor of double precision (weights stay finite).
    var = var.cwiseMax(1e-30 * std::max(G.cwiseAbs2().maxCoeff(), 1e-300));
    ws.push_back(2 * std::numbers::pi * k / (period * h));
    Gs.push_back(G);
    Vs.push_back(var);
  }
  FrequencyData out(Eigen::Map<const Eigen::VectorXd>(ws.data(), static_cast<Eigen::Index>(ws.size())), std::move(Gs),
                    std::move(Vs));
  out.input_names = first.input_names();
  out.output_names = first.output_names();
  return out;
}

}  // namespace ctid
