#include "ctid/validate/uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "ctid/core/check.hpp"

namespace ctid {

std::vector<TfCoefficient> tf_coefficients(const TransferFunction& g, const ParameterSet& p) {
  const Eigen::VectorXd& den = g.den().coefficients();
  const Eigen::VectorXd& num = g.num().coefficients();
  if (den.size() == 0 || den(0) != 1.0) return {};
  std::vector<TfCoefficient> map(static_cast<size_t>(p.size()));
  for (int i = 0; i < p.size(); ++i) {
    const std::string& n = p.names[static_cast<size_t>(i)];
    if (n.size() < 2 || n.size() > 7 || (n[0] != 'a' && n[0] != 'b') ||
        n.find_first_not_of("0123456789", 1) != std::string::npos)
      continue;  // e.g. "delay"
    const int k = std::stoi(n.substr(1));
    const Eigen::VectorXd& c = n[0] == 'a' ? den : num;
    if (k < (n[0] == 'a' ? 1 : 0) || k >= c.size() ||
        std::abs(c(k) - p.values(i)) > 1e-9 * std::max(1.0, std::abs(c(k))))
      return {};
    map[static_cast<size_t>(i)] = {n[0], k};
  }
  return map;
}

TransferFunction with_coefficients(const TransferFunction& g, const std::vector<TfCoefficient>& map, const Eigen::VectorXd& v) {
  Eigen::VectorXd num = g.num().coefficients(), den = g.den().coefficients();
  for (size_t i = 0; i < map.size(); ++i)
    if (map[i].poly) (map[i].poly == 'a' ? den : num)(map[i].index) = v(static_cast<Eigen::Index>(i));
  return TransferFunction(num, den, g.io_delay());
}

Eigen::VectorXd model_frequency_grid(const AnyModel& model, double w_max, int n) {
  if (const auto* f = std::get_if<FsfModel>(&model)) {
    CTID_REQUIRE(n >= 2, "model_frequency_grid: need at least 2 points (got {})", n);
    const double lo = std::log10(0.5 * 2 * std::numbers::pi / f->T()), hi = std::log10(std::numbers::pi / f->delta() * 0.95);
    Eigen::VectorXd w(n);
    for (int i = 0; i < n; ++i) w(i) = std::pow(10.0, lo + (hi - lo) * i / (n - 1));
    return w;
  }
  CTID_REQUIRE(is_linear(model), "model_frequency_grid: a {} model has no frequency response (its GFRFs describe it)",
               model_type_name(model));
  return frequency_grid(model_poles(model), w_max, n);
}

Eigen::VectorXd frequency_grid(const Eigen::VectorXcd& poles, double w_max, int n) {
  CTID_REQUIRE(n >= 2, "frequency_grid: need at least 2 points (got {})", n);
  double lo = INFINITY, hi = 0;
  for (const auto& p : poles)
    if (std::abs(p) > 0 && std::isfinite(std::abs(p))) {
      lo = std::min(lo, std::abs(p));
      hi = std::max(hi, std::abs(p));
    }
  if (!(hi > 0)) lo = hi = 1.0;
  double a = std::log10(lo) - 2, b = std::log10(hi) + 2;
  if (w_max > 0 && std::isfinite(w_max)) b = std::min(b, std::log10(w_max));
  if (b <= a) a = b - 3;
  Eigen::VectorXd w(n);
  for (int i = 0; i < n; ++i) w(i) = std::pow(10.0, a + (b - a) * i / (n - 1));
  return w;
}

double poles_response_horizon(const Eigen::VectorXcd& poles, double fallback) {
  double slow = INFINITY;
  for (const auto& p : poles)
    if (p.real() < 0) slow = std::min(slow, -p.real());
  return std::isfinite(slow) ? 8.0 / slow : fallback;
}

double response_horizon(const std::vector<TransferFunction>& models, double fallback) {
  std::vector<std::complex<double>> poles;
  double delay = 0;
  for (const auto& g : models) {
    for (const auto& p : g.poles()) poles.push_back(p);
    delay = std::max(delay, g.io_delay());
  }
  const double h = poles_response_horizon(Eigen::Map<const Eigen::VectorXcd>(poles.data(), static_cast<Eigen::Index>(poles.size())), -1.0);
  return h > 0 ? h + delay : fallback;
}

MagnitudeBand magnitude_band(const Result<TransferFunction>& r, const Eigen::VectorXd& w, double level, int draws,
                             unsigned seed) {
  CTID_REQUIRE(level > 0 && level < 1, "magnitude_band: level must be in (0, 1) (got {})", level);
  CTID_REQUIRE(draws >= 10, "magnitude_band: need at least 10 draws (got {})", draws);
  return response_band(r, [&](const TransferFunction& g) { return Eigen::VectorXd(g.frequency_response(w).cwiseAbs()); },
                       level, draws, seed);
}

std::vector<TransferFunction> drawn_models(const Result<TransferFunction>& r, int draws, unsigned seed) {
  CTID_REQUIRE(draws >= 10, "drawn_models: need at least 10 draws (got {})", draws);
  const ParameterSet& p = r.parameters;
  const int P = p.size();
  std::vector<TransferFunction> out;
  if (P == 0 || p.covariance.rows() != P || p.covariance.cols() != P || !p.covariance.allFinite()) return out;
  const std::vector<TfCoefficient> map = tf_coefficients(r.model, p);
  if (std::none_of(map.begin(), map.end(), [](const TfCoefficient& c) { return c.poly != 0; })) return out;
  // Draws theta + L z with L L^T = covariance (eigen-decomposition: semi-definite covariances of fixed parameters
  // are fine).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (p.covariance + p.covariance.transpose()));
  const Eigen::MatrixXd L = es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  Eigen::VectorXd z(P);
  out.reserve(static_cast<size_t>(draws));
  for (int k = 0; k < draws; ++k) {
    for (auto& v : z) v = n01(rng);
    out.push_back(with_coefficients(r.model, map, p.values + L * z));
  }
  return out;
}

MagnitudeBand response_band(const Result<TransferFunction>& r,
                            const std::function<Eigen::VectorXd(const TransferFunction&)>& response, double level,
                            int draws, unsigned seed) {
  CTID_REQUIRE(level > 0 && level < 1, "response_band: level must be in (0, 1) (got {})", level);
  CTID_REQUIRE(draws >= 10, "response_band: need at least 10 draws (got {})", draws);
  MagnitudeBand band;
  const std::vector<TransferFunction> models = drawn_models(r, draws, seed);
  if (models.empty()) return band;
  const Eigen::Index n = response(r.model).size();
  Eigen::MatrixXd mags(draws, n);
  for (int k = 0; k < draws; ++k) {
    const Eigen::VectorXd v = response(models[static_cast<size_t>(k)]);
    CTID_REQUIRE(v.size() == n, "response_band: the response has {} points for a drawn model, {} for the estimate",
                 v.size(), n);
    mags.row(k) = v.transpose();
  }
  const double tail = 0.5 * (1.0 - level);
  const auto lo_i = static_cast<size_t>(std::floor(tail * draws));
  const auto hi_i = std::min(static_cast<size_t>(draws) - 1, static_cast<size_t>(std::ceil((1.0 - tail) * draws)) - 1);
  band.lower.resize(n);
  band.upper.resize(n);
  std::vector<double> c(static_cast<size_t>(draws));
  for (Eigen::Index j = 0; j < n; ++j) {
    for (int k = 0; k < draws; ++k) c[static_cast<size_t>(k)] = mags(k, j);
    std::sort(c.begin(), c.end());
    band.lower(j) = c[lo_i];
    band.upper(j) = c[hi_i];
  }
  return band;
}

namespace {
// "X<i>_<j>" -> (i-1, j-1); "pole<a>" etc. -> (a-1, -1); false when the name is not of that form.
bool parse_indexed(const std::string& name, const std::string& prefix, int& i, int& j) {
  if (name.rfind(prefix, 0) != 0) return false;
  const std::string rest = name.substr(prefix.size());
  const auto us = rest.find('_');
  auto number = [](const std::string& t, int& v) {
    if (t.empty() || t.find_first_not_of("0123456789") != std::string::npos || t.size() > 6) return false;
    v = std::stoi(t) - 1;
    return v >= 0;
  };
  if (us == std::string::npos) {
    j = -1;
    return number(rest, i);
  }
  return number(rest.substr(0, us), i) && number(rest.substr(us + 1), j);
}
}  // namespace

std::vector<StateSpaceDirection> state_space_directions(const StateSpace& m, const ParameterSet& p) {
  const int nx = m.nx(), nu = m.nu(), ny = m.ny();
  std::vector<StateSpaceDirection> out;
  for (const std::string& name : p.names) {
    StateSpaceDirection d{Eigen::MatrixXd::Zero(nx, nx), Eigen::MatrixXd::Zero(nx, nu), Eigen::MatrixXd::Zero(ny, nx),
                          Eigen::MatrixXd::Zero(ny, nu), Eigen::MatrixXd::Zero(nx, m.has_innovation_gain() ? ny : 0)};
    int i = -1, j = -1;
    auto entry = [&](Eigen::MatrixXd& M) {
      CTID_REQUIRE(j >= 0 && i < M.rows() && j < M.cols(), "state_space_directions: parameter '{}' is outside the {}x{} "
                   "matrix", name, M.rows(), M.cols());
      M(i, j) = 1.0;
    };
    auto mode = [&](bool pair) {
      CTID_REQUIRE(j < 0 && i + (pair ? 1 : 0) < nx, "state_space_directions: parameter '{}' is outside the {} states",
                   name, nx);
    };
    if (parse_indexed(name, "A", i, j)) entry(d.dA);
    else if (parse_indexed(name, "B", i, j)) entry(d.dB);
    else if (parse_indexed(name, "C", i, j)) entry(d.dC);
    else if (parse_indexed(name, "D", i, j)) entry(d.dD);
    else if (parse_indexed(name, "K", i, j)) entry(d.dK);
    else if (parse_indexed(name, "pole", i, j)) { mode(false); d.dA(i, i) = 1.0; }
    else if (parse_indexed(name, "sigma", i, j)) { mode(true); d.dA(i, i) = d.dA(i + 1, i + 1) = 1.0; }
    else if (parse_indexed(name, "omega", i, j)) { mode(true); d.dA(i, i + 1) = 1.0; d.dA(i + 1, i) = -1.0; }
    else CTID_REQUIRE(false, "state_space_directions: '{}' is not a parameter of a state-space model", name);
    out.push_back(std::move(d));
  }
  return out;
}

namespace {
// The covariance over the parameters, or an empty matrix when it is missing or not finite.
Eigen::MatrixXd finite_covariance(const ParameterSet& p) {
  const Eigen::MatrixXd& c = p.covariance;
  if (c.rows() != p.size() || c.cols() != p.size() || !c.allFinite()) return {};
  return c;
}
}  // namespace

std::vector<ModeUncertainty> mode_uncertainty(const Result<StateSpace>& r) {
  const std::vector<Mode> modes = r.model.modes();
  const Eigen::MatrixXd cov = finite_covariance(r.parameters);
  std::vector<ModeUncertainty> out(modes.size(), {NAN, NAN});
  if (cov.size() == 0 || modes.empty()) return out;
  const std::vector<StateSpaceDirection> dirs = state_space_directions(r.model, r.parameters);
  Eigen::EigenSolver<Eigen::MatrixXd> es(r.model.A());
  const Eigen::MatrixXcd V = es.eigenvectors(), Vi = V.inverse();
  const Eigen::VectorXcd lam = es.eigenvalues();
  for (size_t m = 0; m < modes.size(); ++m) {
    Eigen::Index i = 0;
    (lam.array() - modes[m].pole).abs().minCoeff(&i);
    // Gradients of wn = |lambda| and zeta = -Re(lambda)/|lambda| along each parameter.
    const std::complex<double> l = lam(i);
    const double wn = std::abs(l);
    Eigen::VectorXd gw(r.parameters.size()), gz(r.parameters.size());
    for (size_t k = 0; k < dirs.size(); ++k) {
      const std::complex<double> dl = (Vi.row(i) * dirs[k].dA.cast<std::complex<double>>() * V.col(i))(0, 0);
      const double dwn = wn > 0 ? (std::conj(l) * dl).real() / wn : std::abs(dl);
      gw(static_cast<Eigen::Index>(k)) = dwn;
      gz(static_cast<Eigen::Index>(k)) = wn > 0 ? -(dl.real() * wn - l.real() * dwn) / (wn * wn) : 0.0;
    }
    out[m] = {std::sqrt(std::max(0.0, gw.dot(cov * gw))), std::sqrt(std::max(0.0, gz.dot(cov * gz)))};
  }
  return out;
}

ResponseStd frequency_response_std(const Result<StateSpace>& r, const Eigen::VectorXd& w, int out, int in) {
  const StateSpace& m = r.model;
  CTID_REQUIRE(out >= 0 && out < m.ny() && in >= 0 && in < m.nu(),
               "frequency_response_std: output {} / input {} outside the model's {} outputs and {} inputs", out, in,
               m.ny(), m.nu());
  ResponseStd s{Eigen::VectorXd::Constant(w.size(), NAN), Eigen::VectorXd::Constant(w.size(), NAN)};
  const Eigen::MatrixXd cov = finite_covariance(r.parameters);
  if (cov.size() == 0) return s;
  const std::vector<StateSpaceDirection> dirs = state_space_directions(m, r.parameters);
  using C = std::complex<double>;
  const int nx = m.nx();
  const Eigen::MatrixXcd A = m.A().cast<C>();
  const Eigen::VectorXcd b = m.B().col(in).cast<C>();
  const Eigen::RowVectorXcd c = m.C().row(out).cast<C>();
  for (Eigen::Index k = 0; k < w.size(); ++k) {
    const Eigen::MatrixXcd R = (C(0, w(k)) * Eigen::MatrixXcd::Identity(nx, nx) - A).partialPivLu().inverse();
    const Eigen::VectorXcd Rb = R * b;          // R B e_in
    const Eigen::RowVectorXcd cR = c * R;       // e_out^T C R
    const C G = (c * Rb)(0, 0) + m.D()(out, in);
    if (!(std::abs(G) > 0)) continue;
    // d|G| = Re(conj(G) dG)/|G|, d arg G = Im(dG / G).
    Eigen::VectorXd gm(r.parameters.size()), gp(r.parameters.size());
    for (size_t j = 0; j < dirs.size(); ++j) {
      const StateSpaceDirection& d = dirs[j];
      const C dG = (d.dC.row(out).cast<C>() * Rb)(0, 0) + (cR * d.dA.cast<C>() * Rb)(0, 0) +
                   (cR * d.dB.col(in).cast<C>())(0, 0) + d.dD(out, in);
      gm(static_cast<Eigen::Index>(j)) = (std::conj(G) * dG).real() / std::abs(G);
      gp(static_cast<Eigen::Index>(j)) = (dG / G).imag();
    }
    s.magnitude(k) = std::sqrt(std::max(0.0, gm.dot(cov * gm)));
    s.phase(k) = std::sqrt(std::max(0.0, gp.dot(cov * gp)));
  }
  return s;
}

}  // namespace ctid
