// ctid — the closed set of model types (see include/ctid/model/any_model.hpp).
#include "ctid/model/any_model.hpp"

#include <cstdio>

namespace ctid {

namespace {
template <class... F>
struct Overloads : F... {
  using F::operator()...;
};
template <class... F>
Overloads(F...) -> Overloads<F...>;

std::string pole_text(std::complex<double> p) {
  char z[64];
  std::snprintf(z, sizeof z, "%.6g%+.6gj", p.real(), p.imag());
  return z;
}
}  // namespace

const char* model_type_name(const AnyModel& model) {
  return std::visit(Overloads{[](const TransferFunction&) { return "transfer_function"; },
                              [](const MisoModel&) { return "miso"; },
                              [](const StateSpace&) { return "state_space"; },
                              [](const FsfModel&) { return "fsf"; },
                              [](const NarxModel&) { return "narx"; },
                              [](const NdeModel&) { return "nde"; },
                              [](const GreyboxModel&) { return "greybox"; }},
                    model);
}

int model_inputs(const AnyModel& model) {
  return std::visit(Overloads{[](const MisoModel& m) { return m.nu(); }, [](const StateSpace& m) { return m.nu(); },
                              [](const GreyboxModel& m) { return m.nu(); }, [](const auto&) { return 1; }},
                    model);
}

int model_outputs(const AnyModel& model) {
  return std::visit(Overloads{[](const StateSpace& m) { return m.ny(); }, [](const GreyboxModel& m) { return m.ny(); },
                              [](const auto&) { return 1; }},
                    model);
}

bool is_linear(const AnyModel& model) {
  return !std::holds_alternative<NarxModel>(model) && !std::holds_alternative<NdeModel>(model) &&
         !std::holds_alternative<GreyboxModel>(model);
}

bool is_linear_model_type(const std::string& type) {
  return type == "transfer_function" || type == "miso" || type == "state_space" || type == "fsf";
}

int model_coefficient_count(const AnyModel& model) {
  const auto tf = [](const TransferFunction& g) { return g.num().degree() + 1 + g.order(); };
  return std::visit(Overloads{[&](const TransferFunction& m) { return tf(m); },
                              [&](const MisoModel& m) {
                                int n = 0;
                                for (const auto& c : m.channels) n += tf(c);
                                return n;
                              },
                              [](const StateSpace& m) { return (m.nx() + m.ny()) * (m.nx() + m.nu()); },
                              [](const FsfModel& m) { return m.n(); },
                              [](const GreyboxModel& m) { return m.np(); },
                              [](const auto& m) { return static_cast<int>(m.terms().size()); }},
                    model);
}

std::string describe(const AnyModel& model, int precision) {
  return std::visit(
      Overloads{[&](const StateSpace& m) {
                  return "state space: " + std::to_string(m.nx()) + " states, " + std::to_string(m.nu()) + " inputs, " +
                         std::to_string(m.ny()) + " outputs";
                },
                [&](const FsfModel& m) {
                  char t[64];
                  std::snprintf(t, sizeof t, "%.*g", precision, m.T());
                  return "FSF model: N = " + std::to_string(m.N()) + " samples per window, n = " + std::to_string(m.n()) +
                         " filters, T = " + t + " s";
                },
                [&](const NarxModel& m) { return m.process().to_string(precision); },
                [&](const GreyboxModel& m) {
                  std::string s = m.to_string();
                  for (auto& ch : s)
                    if (ch == '\n') ch = ';';
                  return "grey-box model: " + s.substr(0, s.size() - 1);
                },
                [&](const auto& m) { return m.to_string(precision); }},
      model);
}

Eigen::VectorXcd model_poles(const AnyModel& model) {
  return std::visit(Overloads{[](const TransferFunction& m) -> Eigen::VectorXcd { return m.poles(); },
                              [](const StateSpace& m) -> Eigen::VectorXcd { return m.poles(); },
                              [](const MisoModel& m) -> Eigen::VectorXcd {
                                Eigen::VectorXcd p(0);
                                for (const auto& c : m.channels) {
                                  p.conservativeResize(p.size() + c.order());
                                  p.tail(c.order()) = c.poles();
                                }
                                return p;
                              },
                              [](const auto&) -> Eigen::VectorXcd { return Eigen::VectorXcd(0); }},
                    model);
}

std::string unstable_poles_note(const AnyModel& model) {
  std::string s;
  const auto add = [&s](const Eigen::VectorXcd& poles, const std::string& prefix) {
    for (const auto& p : poles)
      if (p.real() >= 0) {
        s += s.empty() ? "; unstable poles: " : ", ";
        s += prefix;
        s += pole_text(p);
      }
  };
  if (const auto* m = std::get_if<MisoModel>(&model); m && m->nu() > 1) {
    for (int i = 0; i < m->nu(); ++i) {
      std::string prefix = "u";
      prefix += std::to_string(i + 1);
      prefix += ": ";
      add(m->channels[static_cast<size_t>(i)].poles(), prefix);
    }
  } else {
    add(model_poles(model), "");
  }
  return s;
}

}  // namespace ctid
