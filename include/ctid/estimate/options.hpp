// ctid — one table of settings per method.
//
// Each options struct declares its fields once, in an OptionTable: name (the C++ member's name, the Python
// keyword and the CLI key of `--set NAME=VALUE`), unit, admissible range, default and one line of doc. The
// table drives the struct's validate() (range checks), the CLI's `--set` parsing and per-method help, the Python
// keyword arguments, properties and docstrings, and the "settings" section of a report. Times are in seconds
// everywhere; nothing is counted in samples unless its name says so.
//
// Text forms (CLI and reports): numbers as C++ reads them ("1e-3", "inf"); flags 0/1/true/false/yes/no; lists
// comma-separated ("0.1,0.2"); named values as NAME.KEY=V (e.g. fixed.a2=4, bounds.a1=0,inf); a transfer
// function as "NUM/DEN" with comma-separated coefficients in descending powers of s ("1/0.1,1" = 1/(0.1 s + 1)).
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "ctid/core/error.hpp"
#include "ctid/core/names.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

/// The kind of value a setting holds (its C++ type, Python type and text form).
enum class OptionKind {
  Real,         ///< double
  Integer,      ///< int
  Flag,         ///< bool
  Choice,       ///< an enumeration, written by name
  Reals,        ///< std::vector<double>
  NamedReals,   ///< std::map<std::string, double>: NAME.KEY=V
  NamedBounds,  ///< std::map<std::string, std::pair<double, double>>: NAME.KEY=LO,HI
  Model,        ///< std::optional<TransferFunction> or TransferFunction: "NUM/DEN"
  Names,        ///< std::vector<std::string> (e.g. model terms "y^2,y*Dy"): comma-separated
};
const char* to_string(OptionKind k);

/// An admissible interval with an optional special value (e.g. tau: "> 0, or 0 = automatic").
struct OptionRange {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = true, hi_open = true;  ///< the default range: every finite value
  std::optional<double> special;  ///< also admissible, with the meaning in special_doc
  std::string special_doc;
  bool contains(double v) const;
  std::string text() const;  ///< e.g. "> 0, or 0 (automatic)"
};
/// Shorthands: [lo, inf), (lo, inf), [lo, hi], (lo, hi].
OptionRange at_least(double lo);
OptionRange above(double lo);
OptionRange between(double lo, double hi);
OptionRange above_at_most(double lo, double hi);
/// r, also admitting the value v with the meaning `doc`.
OptionRange or_special(OptionRange r, double v, std::string doc);

/// What a user sees of one setting.
struct OptionInfo {
  std::string name;
  OptionKind kind = OptionKind::Real;
  std::string unit;           ///< "s", "1/s", "rad/s", "%", "samples" or ""
  std::string range;          ///< admissible values as text ("" = any)
  std::string doc;            ///< one line
  std::string default_value;  ///< the default, as text
  std::vector<std::string> choices;  ///< Choice: the names
};

/// A setting's value, typed (Python reads and writes these).
using OptionValue = std::variant<double, int, bool, std::string, std::vector<double>, std::map<std::string, double>,
                                 std::map<std::string, std::pair<double, double>>, std::optional<TransferFunction>,
                                 std::vector<std::string>>;


/// Parameters held at a value, by name: the `fixed` setting of every estimator with constraints (fixed.NAME=VALUE;
/// Python fixed={"a2": 4}), in the unit and scale of the returned model's parameter of that name.
using FixedValues = std::map<std::string, double>;
/// Ranges by parameter name: the `bounds` setting (bounds.NAME=LOWER,UPPER; Python bounds={"a1": (0, 10)}).
using ParameterBounds = std::map<std::string, std::pair<double, double>>;

/// fixed and bounds resolved against an estimator's parameter names (one entry per name, in their order).
struct ParameterConstraints {
  std::vector<bool> held;  ///< held at `value` (fixed by the user, or held by the method, e.g. a reference term)
  Eigen::VectorXd value;   ///< the held values (NaN where not given by `fixed`)
  Eigen::VectorXd lower, upper;  ///< the bounds (-inf/+inf where none is given)
  std::vector<int> free() const;  ///< indices of the parameters not held, in order
};
/// The one resolution of the constraint vocabulary. `held`: parameters the method holds already (empty: none).
/// Throws InvalidOptions "METHOD: fixed.NAME: 'NAME' is not OF; did you mean 'X'?" for a name outside `names`
/// (`of` e.g. "a parameter of \"k/(s + c)\"") and "METHOD: bounds.NAME: ... is held" for a bound on a held
/// parameter.
ParameterConstraints resolve_constraints(const FixedValues& fixed, const ParameterBounds& bounds,
                                         const std::vector<std::string>& names, const std::string& method,
                                         const std::string& of, std::vector<bool> held = {});

/// A model's own declarations (its parameters' fixed values and bounds, in `fixed` and `bounds`) with the options on
/// top: an option's fixed value holds the parameter (dropping its declared bound), an option's bound replaces the
/// declared one. Used by the estimators whose models declare constraints (physical, greybox).
void overlay_constraints(FixedValues& fixed, ParameterBounds& bounds, const FixedValues& option_fixed,
                         const ParameterBounds& option_bounds);

namespace options_detail {
double parse_real(const std::string& method, const std::string& key, const std::string& text);
int parse_int(const std::string& method, const std::string& key, const std::string& text);
bool parse_flag(const std::string& method, const std::string& key, const std::string& text);
std::vector<double> parse_reals(const std::string& method, const std::string& key, const std::string& text);
std::pair<double, double> parse_bounds(const std::string& method, const std::string& key, const std::string& text);
TransferFunction parse_tf(const std::string& method, const std::string& key, const std::string& text);
std::vector<std::string> parse_names(const std::string& text);
std::string format_names(const std::vector<std::string>& v);
std::string format_real(double v);
std::string format_reals(const std::vector<double>& v);
std::string format_tf(const TransferFunction& g);
[[noreturn]] void out_of_range(const std::string& method, const std::string& name, const std::string& range,
                               const std::string& got, const std::string& unit);
[[noreturn]] void unknown_key(const std::string& method, const std::string& key, const std::vector<std::string>& names);
}  // namespace options_detail

/// The settings of one options struct O. Built once (see option_table<O>()) and immutable afterwards.
template <class O>
class OptionTable {
 public:
  struct Field {
    OptionInfo info;
    /// From text; key: NAME or NAME.KEY; method: the name used in messages.
    std::function<void(O&, const std::string& method, const std::string& key, const std::string& text)> parse;
    std::function<std::string(const O&)> format;
    std::function<OptionValue(const O&)> get;
    std::function<void(O&, const std::string& method, const OptionValue&)> set;
    std::function<void(const O&, const std::string& method)> check;  ///< throws InvalidOptions
  };

  explicit OptionTable(std::string method) : method_(std::move(method)) {}
  const std::string& method() const { return method_; }
  const std::vector<Field>& fields() const { return fields_; }

  OptionTable& real(const char* name, double O::*m, const char* unit, OptionRange r, const char* doc) {
    const std::string n = name, u = unit;
    return add({n, OptionKind::Real, u, r.text(), doc, {}, {}},
               [m, n](O& o, const std::string& method, const std::string& t) { o.*m = options_detail::parse_real(method, n, t); },
               [m](const O& o) { return options_detail::format_real(o.*m); },
               [m](const O& o) { return OptionValue(o.*m); },
               [m](O& o, const std::string&, const OptionValue& v) { o.*m = std::holds_alternative<int>(v) ? std::get<int>(v) : std::get<double>(v); },
               [m, n, r, u](const O& o, const std::string& method) {
                 if (!r.contains(o.*m)) options_detail::out_of_range(method, n, r.text(), options_detail::format_real(o.*m), u);
               });
  }
  /// A whole number (int or unsigned member; held as int in OptionValue).
  template <class I>
  OptionTable& integer(const char* name, I O::*m, const char* unit, OptionRange r, const char* doc) {
    static_assert(std::is_integral_v<I>);
    if constexpr (std::is_unsigned_v<I>) r.lo = std::max(r.lo, 0.0);
    const std::string n = name, u = unit;
    return add({n, OptionKind::Integer, u, r.text(), doc, {}, {}},
               [m, n, r, u](O& o, const std::string& method, const std::string& t) {
                 const int v = options_detail::parse_int(method, n, t);
                 if (std::is_unsigned_v<I> && v < 0) options_detail::out_of_range(method, n, r.text(), t, u);
                 o.*m = static_cast<I>(v);
               },
               [m](const O& o) { return std::to_string(o.*m); },
               [m](const O& o) { return OptionValue(static_cast<int>(o.*m)); },
               [m, n, r, u](O& o, const std::string& method, const OptionValue& v) {
                 const int x = std::get<int>(v);
                 if (std::is_unsigned_v<I> && x < 0) options_detail::out_of_range(method, n, r.text(), std::to_string(x), u);
                 o.*m = static_cast<I>(x);
               },
               [m, n, r, u](const O& o, const std::string& method) {
                 if (!r.contains(o.*m)) options_detail::out_of_range(method, n, r.text(), std::to_string(o.*m), u);
               });
  }
  OptionTable& flag(const char* name, bool O::*m, const char* doc) {
    const std::string n = name;
    return add({n, OptionKind::Flag, "", "0 or 1", doc, {}, {}},
               [m, n](O& o, const std::string& method, const std::string& t) { o.*m = options_detail::parse_flag(method, n, t); },
               [m](const O& o) { return std::string(o.*m ? "1" : "0"); }, [m](const O& o) { return OptionValue(o.*m); },
               [m](O& o, const std::string&, const OptionValue& v) { o.*m = std::get<bool>(v); }, nullptr);
  }
  /// An enumeration (or a bool shown by name) written by the names in `values`.
  template <class E>
  OptionTable& choice(const char* name, E O::*m, std::vector<std::pair<std::string, E>> values, const char* doc) {
    const std::string n = name;
    std::vector<std::string> names;
    std::string range;
    for (const auto& [k, e] : values) {
      names.push_back(k);
      range += (range.empty() ? "" : "|") + k;
    }
    auto from = [values, names, n](const std::string& method, const std::string& t) {
      for (const auto& [k, e] : values)
        if (k == t) return e;
      options_detail::out_of_range(method, n, [&] {
        std::string s;
        for (const auto& k : names) s += (s.empty() ? "" : ", ") + k;
        return "one of " + s;
      }(), "'" + t + "'", "");
    };
    auto to = [values, m](const O& o) {
      for (const auto& [k, e] : values)
        if (e == o.*m) return k;
      return std::string("?");
    };
    return add({n, OptionKind::Choice, "", range, doc, {}, names},
               [m, from](O& o, const std::string& method, const std::string& t) { o.*m = from(method, t); }, to,
               [to](const O& o) { return OptionValue(to(o)); },
               [m, from](O& o, const std::string& method, const OptionValue& v) { o.*m = from(method, std::get<std::string>(v)); }, nullptr);
  }
  OptionTable& reals(const char* name, std::vector<double> O::*m, const char* unit, OptionRange r, const char* doc) {
    const std::string n = name, u = unit;
    return add({n, OptionKind::Reals, u, r.text() + (r.text().empty() ? "" : " each"), doc, {}, {}},
               [m, n](O& o, const std::string& method, const std::string& t) { o.*m = options_detail::parse_reals(method, n, t); },
               [m](const O& o) { return options_detail::format_reals(o.*m); }, [m](const O& o) { return OptionValue(o.*m); },
               [m](O& o, const std::string&, const OptionValue& v) { o.*m = std::get<std::vector<double>>(v); },
               [m, n, r, u](const O& o, const std::string& method) {
                 for (double x : o.*m)
                   if (!r.contains(x)) options_detail::out_of_range(method, n, r.text(), options_detail::format_real(x), u);
               });
  }
  /// A vector held as Eigen::VectorXd (e.g. per-sample weights, initial parameters); same text form.
  OptionTable& reals(const char* name, Eigen::VectorXd O::*m, const char* unit, OptionRange r, const char* doc) {
    const std::string n = name, u = unit;
    auto to_std = [m](const O& o) { return std::vector<double>((o.*m).data(), (o.*m).data() + (o.*m).size()); };
    auto from_std = [](const std::vector<double>& v) {
      return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())));
    };
    return add({n, OptionKind::Reals, u, r.text() + " each", doc, {}, {}},
               [m, n, from_std](O& o, const std::string& method, const std::string& t) {
                 o.*m = from_std(options_detail::parse_reals(method, n, t));
               },
               [to_std](const O& o) { return options_detail::format_reals(to_std(o)); },
               [to_std](const O& o) { return OptionValue(to_std(o)); },
               [m, from_std](O& o, const std::string&, const OptionValue& v) { o.*m = from_std(std::get<std::vector<double>>(v)); },
               [m, n, r, u](const O& o, const std::string& method) {
                 for (Eigen::Index i = 0; i < (o.*m).size(); ++i)
                   if (!r.contains((o.*m)(i)))
                     options_detail::out_of_range(method, n + "[" + std::to_string(i) + "]", r.text(),
                                                  options_detail::format_real((o.*m)(i)), u);
               });
  }
  /// A member of another type written as a list of reals through two conversions (e.g. windows as pairs).
  template <class To, class From>
  OptionTable& reals_via(const char* name, const char* unit, OptionRange r, const char* doc, To to, From from) {
    const std::string n = name, u = unit;
    return add({n, OptionKind::Reals, u, r.text() + " each", doc, {}, {}},
               [n, from](O& o, const std::string& method, const std::string& t) {
                 from(o, method, options_detail::parse_reals(method, n, t));
               },
               [to](const O& o) { return options_detail::format_reals(to(o)); }, [to](const O& o) { return OptionValue(to(o)); },
               [from](O& o, const std::string& method, const OptionValue& v) {
                 from(o, method, std::get<std::vector<double>>(v));
               },
               [to, n, r, u](const O& o, const std::string& method) {
                 for (double x : to(o))
                   if (!r.contains(x)) options_detail::out_of_range(method, n, r.text(), options_detail::format_real(x), u);
               });
  }
  /// Values by name (e.g. fixed coefficients); CLI: NAME.KEY=V, one per key. Values must be finite.
  OptionTable& named_reals(const char* name, FixedValues O::*m, const char* doc) {
    const std::string n = name;
    return add({n, OptionKind::NamedReals, "", "finite", doc, {}, {}},
               [m, n](O& o, const std::string& method, const std::string& key, const std::string& t) {
                 (o.*m)[sub_key(method, n, key)] = options_detail::parse_real(method, key, t);
               },
               [m](const O& o) {
                 std::string s;
                 for (const auto& [k, v] : o.*m) s += (s.empty() ? "" : " ") + k + "=" + options_detail::format_real(v);
                 return s;
               },
               [m](const O& o) { return OptionValue(o.*m); },
               [m](O& o, const std::string&, const OptionValue& v) { o.*m = std::get<std::map<std::string, double>>(v); },
               [m, n](const O& o, const std::string& method) {
                 for (const auto& [k, v] : o.*m)
                   if (!std::isfinite(v))
                     options_detail::out_of_range(method, n + "." + k, "finite", options_detail::format_real(v), "");
               });
  }
  /// Intervals by name; CLI: NAME.KEY=LO,HI. Each needs lo <= hi (not NaN).
  OptionTable& named_bounds(const char* name, ParameterBounds O::*m, const char* doc) {
    const std::string n = name;
    return add({n, OptionKind::NamedBounds, "", "lower <= upper", doc, {}, {}},
               [m, n](O& o, const std::string& method, const std::string& key, const std::string& t) {
                 (o.*m)[sub_key(method, n, key)] = options_detail::parse_bounds(method, key, t);
               },
               [m](const O& o) {
                 std::string s;
                 for (const auto& [k, b] : o.*m)
                   s += (s.empty() ? "" : " ") + k + "=" + options_detail::format_real(b.first) + "," +
                        options_detail::format_real(b.second);
                 return s;
               },
               [m](const O& o) { return OptionValue(o.*m); },
               [m](O& o, const std::string&, const OptionValue& v) { o.*m = std::get<std::map<std::string, std::pair<double, double>>>(v); },
               [m, n](const O& o, const std::string& method) {
                 for (const auto& [k, b] : o.*m)
                   if (!(b.first <= b.second))
                     options_detail::out_of_range(method, n + "." + k, "lower <= upper",
                                                  options_detail::format_real(b.first) + "," +
                                                      options_detail::format_real(b.second),
                                                  "");
               });
  }
  /// An optional transfer function (a starting model, a filter); CLI: "NUM/DEN".
  OptionTable& model(const char* name, std::optional<TransferFunction> O::*m, const char* doc) {
    const std::string n = name;
    return add({n, OptionKind::Model, "", "", doc, {}, {}},
               [m, n](O& o, const std::string& method, const std::string& t) { o.*m = options_detail::parse_tf(method, n, t); },
               [m](const O& o) { return o.*m ? options_detail::format_tf(*(o.*m)) : std::string("none"); },
               [m](const O& o) { return OptionValue(o.*m); },
               [m](O& o, const std::string&, const OptionValue& v) { o.*m = std::get<std::optional<TransferFunction>>(v); }, nullptr);
  }
  /// A required transfer function (e.g. a known controller).
  OptionTable& model(const char* name, TransferFunction O::*m, const char* doc) {
    const std::string n = name;
    return add({n, OptionKind::Model, "", "", doc, {}, {}},
               [m, n](O& o, const std::string& method, const std::string& t) { o.*m = options_detail::parse_tf(method, n, t); },
               [m](const O& o) { return options_detail::format_tf(o.*m); },
               [m](const O& o) { return OptionValue(std::optional<TransferFunction>(o.*m)); },
               [m, n](O& o, const std::string& method, const OptionValue& v) {
                 const auto& g = std::get<std::optional<TransferFunction>>(v);
                 if (!g) options_detail::out_of_range(method, n, "a transfer function", "none", "");
                 o.*m = *g;
               },
               nullptr);
  }
  /// A list of names (comma-separated in text).
  OptionTable& names(const char* name, std::vector<std::string> O::*m, const char* doc) {
    const std::string n = name;
    return add({n, OptionKind::Names, "", "", doc, {}, {}},
               [m](O& o, const std::string&, const std::string& t) { o.*m = options_detail::parse_names(t); },
               [m](const O& o) { return options_detail::format_names(o.*m); }, [m](const O& o) { return OptionValue(o.*m); },
               [m](O& o, const std::string&, const OptionValue& v) { o.*m = std::get<std::vector<std::string>>(v); }, nullptr);
  }
  /// A list of model terms T (T::parse(text), t.name()), e.g. NDE terms "y^2,y*Dy"; a bad term is an InvalidOptions.
  template <class T>
  OptionTable& terms(const char* name, std::vector<T> O::*m, const char* doc) {
    const std::string n = name;
    auto from = [n](const std::string& method, const std::vector<std::string>& names) {
      std::vector<T> out;
      for (const auto& s : names) {
        try {
          out.push_back(T::parse(s));
        } catch (const InvalidArgument& e) {
          throw InvalidOptions(method + ": " + n + ": " + e.what());
        }
      }
      return out;
    };
    auto to = [m](const O& o) {
      std::vector<std::string> out;
      for (const auto& t : o.*m) out.push_back(t.name());
      return out;
    };
    return add({n, OptionKind::Names, "", "", doc, {}, {}},
               [m, from](O& o, const std::string& method, const std::string& t) {
                 o.*m = from(method, options_detail::parse_names(t));
               },
               [to](const O& o) { return options_detail::format_names(to(o)); }, [to](const O& o) { return OptionValue(to(o)); },
               [m, from](O& o, const std::string& method, const OptionValue& v) {
                 o.*m = from(method, std::get<std::vector<std::string>>(v));
               },
               nullptr);
  }
  /// The fields of a nested options struct, reached under their own names (or `rename` old -> new);
  /// `only` (if not empty) limits which fields are included.
  /// `prefix` is put before every name that `rename` does not give.
  template <class N>
  OptionTable& include(N O::*m, const OptionTable<N>& nested, std::vector<std::string> only = {},
                       std::map<std::string, std::string> rename = {}, const std::string& prefix = "") {
    for (const auto& f : nested.fields()) {
      if (!only.empty() && std::find(only.begin(), only.end(), f.info.name) == only.end()) continue;
      OptionInfo info = f.info;
      if (auto it = rename.find(info.name); it != rename.end()) info.name = it->second;
      else info.name = prefix + info.name;
      const std::string inner = f.info.name, outer = info.name;
      Field g;
      g.info = info;
      g.parse = [m, f, inner, outer](O& o, const std::string& method, const std::string& key, const std::string& t) {
        f.parse(o.*m, method, inner + key.substr(outer.size()), t);
      };
      g.format = [m, f](const O& o) { return f.format(o.*m); };
      g.get = [m, f](const O& o) { return f.get(o.*m); };
      g.set = [m, f](O& o, const std::string& method, const OptionValue& v) { f.set(o.*m, method, v); };
      if (f.check) g.check = [m, f](const O& o, const std::string& method) { f.check(o.*m, method); };
      fields_.push_back(std::move(g));
    }
    return *this;
  }

  /// The settings with their defaults (those of a default-constructed O).
  std::vector<OptionInfo> info() const {
    const O d{};
    std::vector<OptionInfo> out;
    for (const auto& f : fields_) {
      OptionInfo i = f.info;
      i.default_value = f.format(d);
      out.push_back(std::move(i));
    }
    return out;
  }
  std::vector<std::string> names() const {
    std::vector<std::string> n;
    for (const auto& f : fields_) n.push_back(f.info.name);
    return n;
  }
  /// The field named `name` (NAME, or NAME.KEY for named values); throws InvalidOptions naming the closest valid
  /// name when there is none.
  const Field& field(const std::string& key) const {
    if (const Field* f = find(key)) return *f;
    options_detail::unknown_key(method_, key, names());
  }
  /// The field for `key` (NAME, or NAME.KEY for named values), or nullptr.
  const Field* find(const std::string& key) const {
    for (const auto& f : fields_) {
      const auto& n = f.info.name;
      const bool named = f.info.kind == OptionKind::NamedReals || f.info.kind == OptionKind::NamedBounds;
      if (key == n || (named && key.compare(0, n.size() + 1, n + ".") == 0)) return &f;
    }
    return nullptr;
  }
  /// Sets `key` (NAME or NAME.KEY) from its text form. Throws InvalidOptions for an unknown key (naming the
  /// closest valid one) or a value that does not parse; ranges are checked by check().
  void set(O& o, const std::string& key, const std::string& text) const {
    const Field& f = field(key);
    const bool named = f.info.kind == OptionKind::NamedReals || f.info.kind == OptionKind::NamedBounds;
    if (named && key == f.info.name)
      options_detail::out_of_range(method_, key, "given per name as " + key + ".NAME=VALUE", text, "");
    f.parse(o, method_, key, text);
  }
  /// Sets the field `name` from a typed value (Python); throws InvalidOptions for an unknown name.
  void set_value(O& o, const std::string& name, const OptionValue& v) const { field(name).set(o, method_, v); }
  /// Every setting as text, in table order (for reports and result files).
  std::vector<std::pair<std::string, std::string>> settings(const O& o) const {
    std::vector<std::pair<std::string, std::string>> s;
    for (const auto& f : fields_) s.emplace_back(f.info.name, f.format(o));
    return s;
  }
  /// Range checks of every field; throws InvalidOptions "METHOD: NAME must be RANGE (got V UNIT)".
  void check(const O& o) const {
    for (const auto& f : fields_)
      if (f.check) f.check(o, method_);
  }

 private:
  static std::string sub_key(const std::string& method, const std::string& name, const std::string& key) {
    if (key.size() <= name.size() + 1) options_detail::out_of_range(method, key, "given as " + name + ".NAME=VALUE", key, "");
    return key.substr(name.size() + 1);
  }
  template <class P, class F, class G, class S, class C>
  OptionTable& add(OptionInfo info, P parse, F format, G get, S set, C check) {
    Field f;
    f.info = std::move(info);
    if constexpr (std::is_invocable_v<P, O&, const std::string&, const std::string&, const std::string&>)
      f.parse = parse;
    else
      f.parse = [parse](O& o, const std::string& method, const std::string&, const std::string& t) { parse(o, method, t); };
    f.format = format;
    f.get = get;
    f.set = set;
    if constexpr (!std::is_same_v<C, std::nullptr_t>) f.check = check;
    fields_.push_back(std::move(f));
    return *this;
  }

  std::string method_;
  std::vector<Field> fields_;
};

/// The table of options struct O; specialised (declared beside each options struct, defined in its estimator's
/// .cpp). Tables are built on first use and live for the program's lifetime.
template <class O>
const OptionTable<O>& option_table();

}  // namespace ctid
