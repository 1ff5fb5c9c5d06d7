// ctid Python module — Gawthrop & Wang (2005) stage 2: physical parameters of a partially known model
// (an expression in s and the parameters) by Levenberg-Marquardt against the FSF-compressed step or
// frequency response, or by output error on the raw record.
#include "common.hpp"
#include "ctid/core/check.hpp"

namespace ctid::python {

std::vector<PhysicalParameter> parameters_of(const py::dict& spec) {
  // {"name": initial} or {"name": {"initial": .., "lower": .., "upper": .., "fixed": ..}}
  std::vector<PhysicalParameter> v;
  for (const auto& [k, val] : spec) {
    PhysicalParameter p;
    p.name = py::cast<std::string>(k);
    if (py::isinstance<py::dict>(val)) {
      const auto d = py::cast<py::dict>(val);
      for (const auto& [kk, vv] : d) {
        const auto key = py::cast<std::string>(kk);
        if (key == "initial") p.initial = py::cast<double>(vv);
        else if (key == "lower") p.lower = py::cast<double>(vv);
        else if (key == "upper") p.upper = py::cast<double>(vv);
        else if (key == "fixed") p.fixed = py::cast<bool>(vv);
        else throw InvalidArgument("parameter '" + p.name + "': unknown field '" + key + "' (initial, lower, upper, fixed)");
      }
    } else {
      p.initial = py::cast<double>(val);
    }
    v.push_back(p);
  }
  return v;
}

void bind_physical(py::module_& m) {
  py::class_<PhysicalModel>(m, "PhysicalModel", "G(s; Theta) from an expression such as 'k/(s*(J*s + b))'.")
      .def(py::init<const std::string&, std::vector<std::string>>(), py::arg("expression"), py::arg("parameters"));
  bind_options<PhysicalFitOptions>(m, "PhysicalFitOptions");
  m.def("fit_physical_step", [](const PhysicalModel& pm, const py::dict& p, const FsfModel& c, const PhysicalFitOptions& o,
                                const IdData* d) {
          const auto ps = parameters_of(p);
          return interruptible([&] { return fit_physical_step(pm, ps, c, o, d); });
        }, py::arg("model"), py::arg("parameters"), py::arg("compressed"), py::arg("options") = PhysicalFitOptions{},
        py::arg("data") = nullptr);
  m.def("fit_physical_frequency", [](const PhysicalModel& pm, const py::dict& p, const FsfModel& c,
                                     const PhysicalFitOptions& o, const IdData* d) {
          const auto ps = parameters_of(p);
          return interruptible([&] { return fit_physical_frequency(pm, ps, c, o, d); });
        }, py::arg("model"), py::arg("parameters"), py::arg("compressed"), py::arg("options") = PhysicalFitOptions{},
        py::arg("data") = nullptr);
  m.def("fit_physical_raw", [](const PhysicalModel& pm, const py::dict& p, const IdData& d, double a,
                               const PhysicalFitOptions& o) {
          const auto ps = parameters_of(p);
          return interruptible([&] { return fit_physical_raw(pm, ps, d, a, o); });
        }, py::arg("model"), py::arg("parameters"), py::arg("data"), py::arg("a") = 0.0,
        py::arg("options") = PhysicalFitOptions{});
  m.def("fit_physical_raw", [](const PhysicalModel& pm, const py::dict& p, const std::vector<IdData>& d, double a,
                               const PhysicalFitOptions& o) {
          const auto ps = parameters_of(p);
          return interruptible([&] { return fit_physical_raw(pm, ps, d, a, o); });
        }, py::arg("model"), py::arg("parameters"), py::arg("data"), py::arg("a") = 0.0,
        py::arg("options") = PhysicalFitOptions{});

  py::class_<RlsSvf>(m, "RlsSvf", "Johansson (1986) recursive least squares on filtered signals (one sample at a time).")
      .def(py::init([](int nb, int nf, const RlsSvfOptions& o) { return RlsSvf(TfOrders{nb, nf, 0}, o); }),
           py::arg("nb"), py::arg("nf"), py::arg("options") = RlsSvfOptions{})
      .def("update", &RlsSvf::update, py::arg("t"), py::arg("u"), py::arg("y"))
      .def("run", [](RlsSvf& r, const Eigen::VectorXd& t, const Eigen::VectorXd& u, const Eigen::VectorXd& y) {
             CTID_REQUIRE(t.size() == u.size() && u.size() == y.size(), "RlsSvf.run: t, u, y have {}, {}, {} samples",
                          t.size(), u.size(), y.size());
             Eigen::MatrixXd history(t.size(), r.parameters().size());
             for (Eigen::Index k = 0; k < t.size(); ++k) {
               r.update(t(k), u(k), y(k));
               history.row(k) = r.parameters().transpose();
             }
             return history;
           }, py::arg("t"), py::arg("u"), py::arg("y"), "Feed a record; returns the parameter history (one row per sample).")
      .def("reset", &RlsSvf::reset)
      .def("parameters", &RlsSvf::parameters)
      .def("model", &RlsSvf::model);
}

}  // namespace ctid::python
