// ctid — the text side of the options tables (estimate/options.hpp): parsing, formatting, range text and the
// errors that name the setting, its value and the closest valid name.
#include "ctid/estimate/options.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "ctid/core/check.hpp"
#include "ctid/core/error.hpp"

namespace ctid {

const char* to_string(OptionKind k) {
  switch (k) {
    case OptionKind::Real: return "real";
    case OptionKind::Integer: return "integer";
    case OptionKind::Flag: return "flag";
    case OptionKind::Choice: return "choice";
    case OptionKind::Reals: return "list of reals";
    case OptionKind::NamedReals: return "values by name";
    case OptionKind::NamedBounds: return "bounds by name";
    case OptionKind::Model: return "transfer function";
    case OptionKind::Names: return "list of names";
  }
  return "?";
}

bool OptionRange::contains(double v) const {
  if (special && (v == *special)) return true;
  if (std::isnan(v)) return false;
  const bool lo_ok = lo_open ? v > lo : v >= lo;
  const bool hi_ok = hi_open ? v < hi : v <= hi;
  return lo_ok && hi_ok;
}

std::string OptionRange::text() const {
  using options_detail::format_real;
  std::string s;
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi) s = std::string(lo_open ? "(" : "[") + format_real(lo) + ", " + format_real(hi) + (hi_open ? ")" : "]");
  else if (has_lo) s = std::string(lo_open ? "> " : ">= ") + format_real(lo);
  else if (has_hi) s = std::string(hi_open ? "< " : "<= ") + format_real(hi);
  else s = "finite";
  if (special) s += ", or " + format_real(*special) + (special_doc.empty() ? "" : " (" + special_doc + ")");
  return s;
}

OptionRange at_least(double lo) { return {lo, std::numeric_limits<double>::infinity(), false, true, {}, {}}; }
OptionRange above(double lo) { return {lo, std::numeric_limits<double>::infinity(), true, true, {}, {}}; }
OptionRange between(double lo, double hi) { return {lo, hi, false, false, {}, {}}; }
OptionRange above_at_most(double lo, double hi) { return {lo, hi, true, false, {}, {}}; }
OptionRange or_special(OptionRange r, double v, std::string doc) {
  r.special = v;
  r.special_doc = std::move(doc);
  return r;
}

std::vector<int> ParameterConstraints::free() const {
  std::vector<int> f;
  for (std::size_t i = 0; i < held.size(); ++i)
    if (!held[i]) f.push_back(static_cast<int>(i));
  return f;
}

void overlay_constraints(FixedValues& fixed, ParameterBounds& bounds, const FixedValues& option_fixed,
                         const ParameterBounds& option_bounds) {
  for (const auto& [name, value] : option_fixed) {
    fixed[name] = value;
    bounds.erase(name);  // the option holds what the declaration bounded
  }
  for (const auto& [name, b] : option_bounds) bounds[name] = b;
}

ParameterConstraints resolve_constraints(const FixedValues& fixed, const ParameterBounds& bounds,
                                         const std::vector<std::string>& names, const std::string& method,
                                         const std::string& of, std::vector<bool> held) {
  const auto n = static_cast<Eigen::Index>(names.size());
  ParameterConstraints c;
  c.held = held.empty() ? std::vector<bool>(names.size(), false) : std::move(held);
  CTID_ASSERT(c.held.size() == names.size());
  c.value = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
  c.lower = Eigen::VectorXd::Constant(n, -std::numeric_limits<double>::infinity());
  c.upper = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  auto index = [&](const std::string& name, const char* key) {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) {
      const std::string near = closest_name(name, names);
      throw InvalidOptions(detail::format("{}: {}.{}: '{}' is not {}{}", method, key, name, name, of,
                                          near.empty() ? std::string() : "; did you mean '" + near + "'?"));
    }
    return it - names.begin();
  };
  for (const auto& [name, v] : fixed) {
    const auto i = index(name, "fixed");
    c.held[static_cast<std::size_t>(i)] = true;
    c.value(i) = v;
  }
  for (const auto& [name, b] : bounds) {
    const auto i = index(name, "bounds");
    CTID_REQUIRE_OPTION(!c.held[static_cast<std::size_t>(i)], "{}: bounds.{}: '{}' is held ({}), so it cannot be bounded",
                        method, name, name, fixed.count(name) ? "fixed" : "by the method");
    c.lower(i) = b.first;
    c.upper(i) = b.second;
  }
  return c;
}

namespace options_detail {

namespace {
std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  const auto e = s.find_last_not_of(" \t");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}
}  // namespace

double parse_real(const std::string& method, const std::string& key, const std::string& text) {
  const std::string t = trim(text);
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || end != t.c_str() + t.size() || errno == ERANGE)
    throw InvalidOptions(detail::format("{}: {} must be a number (got '{}')", method, key, text));
  return v;
}

int parse_int(const std::string& method, const std::string& key, const std::string& text) {
  const std::string t = trim(text);
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);  // 1e3 is a whole number too
  if (t.empty() || end != t.c_str() + t.size() || !std::isfinite(v) || v != std::floor(v))
    throw InvalidOptions(detail::format("{}: {} must be a whole number (got '{}')", method, key, text));
  if (std::abs(v) > std::numeric_limits<int>::max())
    throw InvalidOptions(detail::format("{}: {} = {} is out of range (|value| <= {})", method, key, text,
                                        std::numeric_limits<int>::max()));
  return static_cast<int>(v);
}

bool parse_flag(const std::string& method, const std::string& key, const std::string& text) {
  const std::string t = trim(text);
  if (t == "1" || t == "true" || t == "yes" || t == "on") return true;
  if (t == "0" || t == "false" || t == "no" || t == "off") return false;
  throw InvalidOptions(detail::format("{}: {} must be 0 or 1 (got '{}')", method, key, text));
}

std::vector<double> parse_reals(const std::string& method, const std::string& key, const std::string& text) {
  std::vector<double> v;
  if (trim(text).empty() || trim(text) == "none") return v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) v.push_back(parse_real(method, key, item));
  return v;
}

std::pair<double, double> parse_bounds(const std::string& method, const std::string& key, const std::string& text) {
  const std::vector<double> v = parse_reals(method, key, text);
  if (v.size() != 2)
    throw InvalidOptions(detail::format("{}: {} must be LOWER,UPPER (got '{}')", method, key, text));
  return {v[0], v[1]};
}

TransferFunction parse_tf(const std::string& method, const std::string& key, const std::string& text) {
  const auto slash = text.find('/');
  if (slash == std::string::npos)
    throw InvalidOptions(detail::format(
        "{}: {} must be NUM/DEN, coefficients in descending powers of s (e.g. '1/0.1,1'; got '{}')", method, key, text));
  auto coefficients = [&](const std::string& part) {
    const std::vector<double> c = parse_reals(method, key, part);
    if (c.empty()) throw InvalidOptions(detail::format("{}: {} has an empty numerator or denominator (got '{}')", method, key, text));
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(c.data(), static_cast<Eigen::Index>(c.size())));
  };
  try {
    return TransferFunction(coefficients(text.substr(0, slash)), coefficients(text.substr(slash + 1)));
  } catch (const InvalidOptions&) {
    throw;
  } catch (const InvalidArgument& e) {
    throw InvalidOptions(detail::format("{}: {}: {}", method, key, e.what()));
  }
}

std::vector<std::string> parse_names(const std::string& text) {
  std::vector<std::string> v;
  if (trim(text).empty() || trim(text) == "none") return v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) v.push_back(trim(item));
  return v;
}

std::string format_names(const std::vector<std::string>& v) {
  if (v.empty()) return "none";
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
  return s;
}

std::string format_real(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

std::string format_reals(const std::vector<double>& v) {
  if (v.empty()) return "none";
  std::string s;
  for (double x : v) s += (s.empty() ? "" : ",") + format_real(x);
  return s;
}

std::string format_tf(const TransferFunction& g) {
  auto descending = [](const Polynomial& p) {
    const Eigen::VectorXd& c = p.coefficients();
    return format_reals(std::vector<double>(c.data(), c.data() + c.size()));
  };
  return descending(g.num()) + "/" + descending(g.den());
}

void out_of_range(const std::string& method, const std::string& name, const std::string& range, const std::string& got,
                  const std::string& unit) {
  const bool interval = !range.empty() && (range[0] == '[' || range[0] == '(');
  throw InvalidOptions(detail::format("{}: {} must be {}{} (got {}{})", method, name, interval ? "in " : "", range, got,
                                      unit.empty() ? "" : " " + unit));
}

void unknown_key(const std::string& method, const std::string& key, const std::vector<std::string>& names) {
  const std::string near = closest_name(key, names);
  std::string all;
  for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
  throw InvalidOptions(detail::format("{}: '{}' is not a setting{} (settings: {})", method, key,
                                      near.empty() ? std::string() : "; did you mean '" + near + "'?", all));
}

}  // namespace options_detail
}  // namespace ctid
