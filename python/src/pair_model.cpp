// The two-dipole models (src/mresim/pair/) at single states, for exploring a pair from Python:
// energy, gradient and magnetization at given separations, one relaxation, a loop, its
// critical fields. The pair is read from the run file's two-dipole tables, so the defaults,
// validation and messages are those of `mresim run`.

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "config_source.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/config/config_error.hpp"
#include "mresim/pair/critical_fields.hpp"
#include "mresim/pair/hysteresis.hpp"
#include "mresim/pair/pair_energy.hpp"
#include "mresim/pair/pair_magnetization.hpp"
#include "mresim/pair/runs/pair_setup.hpp"
#include "mresim/pair/stiffness.hpp"

namespace py = pybind11;

namespace mresim::python {

namespace {

using Rows3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using pair::runs::PairSetup;

// PairEnergy works in units of R (and mu0 Ms^2 V); Python passes and gets metres and joules.

// The energy terms of eqs. 2.3/2.4 in this order, as in results.h5 /cases/<i>/energy/.
const std::vector<std::string> kEnergyTerms = {"total",  "zeeman", "dipole", "self",
                                               "spring", "anchor", "penalty"};

py::dict energy_dict(const std::vector<pair::EnergyBreakdown>& energies) {
  std::vector<Eigen::VectorXd> columns(kEnergyTerms.size(),
                                       Eigen::VectorXd(static_cast<Eigen::Index>(energies.size())));
  for (std::size_t i = 0; i < energies.size(); ++i) {
    const pair::EnergyBreakdown& e = energies[i];
    const double terms[] = {e.total(), e.zeeman, e.dipole, e.self, e.spring, e.anchor, e.penalty};
    for (std::size_t t = 0; t < kEnergyTerms.size(); ++t) {
      columns[t](static_cast<Eigen::Index>(i)) = terms[t];
    }
  }
  py::dict out;
  for (std::size_t t = 0; t < kEnergyTerms.size(); ++t) out[kEnergyTerms[t].c_str()] = columns[t];
  return out;
}

// Relaxed states as the arrays of results.h5 /cases/<i>/ (same names and units).
py::dict states_dict(const std::vector<pair::PairState>& states, const Eigen::Vector3d& direction) {
  const auto n = static_cast<Eigen::Index>(states.size());
  Eigen::VectorXd field(n);
  Eigen::VectorXd distance(n);
  Eigen::VectorXd rotation(n);
  Eigen::VectorXd along(n);
  Eigen::VectorXd position_error(n);
  Rows3 separation(n, 3);
  Rows3 moment(n, 3);
  std::vector<int> branch(states.size());
  std::vector<int> iterations(states.size());
  std::vector<bool> converged(states.size());
  std::vector<bool> saturated(states.size());
  std::vector<pair::EnergyBreakdown> energies(states.size());
  for (Eigen::Index i = 0; i < n; ++i) {
    const pair::PairState& s = states[static_cast<std::size_t>(i)];
    const auto k = static_cast<std::size_t>(i);
    field(i) = s.field;
    distance(i) = s.distance();
    rotation(i) = s.rotation_deg();
    along(i) = s.magnetization_along(direction);
    position_error(i) = s.position_error;
    separation.row(i) = s.separation.transpose();
    moment.row(i) = s.magnetization.m.transpose();
    branch[k] = s.branch;
    iterations[k] = s.iterations;
    converged[k] = s.converged;
    saturated[k] = s.magnetization.saturated;
    energies[k] = s.energy;
  }
  py::dict out;
  out["field"] = field;
  out["branch"] = branch;
  out["separation"] = separation;
  out["distance"] = distance;
  out["rotation"] = rotation;
  out["moment"] = moment;
  out["magnetization_along_field"] = along;
  out["saturated"] = saturated;
  out["energy"] = energy_dict(energies);
  out["iterations"] = iterations;
  out["converged"] = converged;
  out["position_error"] = position_error;
  return out;
}

class PairModel {
 public:
  PairModel(const py::handle& source, const std::vector<std::string>& overrides,
            const py::object& case_key) {
    const config::TableReader root = read_config(source, overrides);
    // A whole pair_hysteresis run file works too: its [run] table is read (and checked) here.
    if (root.has("run")) (void)app::read_run_settings(root);
    const std::vector<PairSetup> cases = pair::runs::read_pair_cases(root);
    root.reject_unknown_keys();
    setup_ = pick_case(cases, case_key);
    system_ = setup_.system();
  }

  [[nodiscard]] py::dict parameters() const {
    py::dict p;
    p["label"] = setup_.label;
    p["spring_model"] = system_.springs.model == pair::SpringModel::single ? "single" : "three";
    p["radius"] = system_.material.radius;
    p["saturation_magnetization"] = system_.material.saturation_magnetization;
    p["susceptibility"] = system_.material.susceptibility;
    p["rest_separation"] = system_.springs.rest_separation;
    p["k12"] = system_.springs.k12;
    p["k0"] = system_.springs.k0;
    p["penalty"] = system_.penalty.kind == pair::PenaltyKind::tanh ? "tanh" : "wca";
    p["field_max"] = setup_.sweep.b_max;
    p["field_step"] = setup_.sweep.b_step;
    p["field_angle"] = setup_.sweep.theta_h_deg;
    p["critical_field_tolerance"] = setup_.critical_field_tolerance;
    return p;
  }

  [[nodiscard]] py::dict energy(const Rows3& separations, const Eigen::Vector3d& field) const {
    std::vector<pair::EnergyBreakdown> energies(static_cast<std::size_t>(separations.rows()));
    {
      const py::gil_scoped_release computing;
      const pair::PairEnergy model(system_, field);
      for (Eigen::Index i = 0; i < separations.rows(); ++i) {
        energies[static_cast<std::size_t>(i)] =
            model.breakdown(separations.row(i).transpose() / model.length_scale());
      }
    }
    return energy_dict(energies);
  }

  // dE/dd in J/m: the scaled gradient times (mu0 Ms^2 V) / R.
  [[nodiscard]] Rows3 gradient(const Rows3& separations, const Eigen::Vector3d& field) const {
    const py::gil_scoped_release computing;
    const pair::PairEnergy model(system_, field);
    Rows3 out(separations.rows(), 3);
    const double scale = model.energy_scale() / model.length_scale();
    for (Eigen::Index i = 0; i < separations.rows(); ++i) {
      const Eigen::Vector3d d = separations.row(i).transpose() / model.length_scale();
      out.row(i) = scale * model.scaled_gradient(d).transpose();
    }
    return out;
  }

  [[nodiscard]] std::pair<Rows3, std::vector<bool>> magnetization(
      const Rows3& separations, const Eigen::Vector3d& field) const {
    const py::gil_scoped_release computing;
    const pair::PairEnergy model(system_, field);
    Rows3 moments(separations.rows(), 3);
    std::vector<bool> saturated(static_cast<std::size_t>(separations.rows()));
    for (Eigen::Index i = 0; i < separations.rows(); ++i) {
      const pair::PairMagnetization m =
          model.magnetization(separations.row(i).transpose() / model.length_scale());
      moments.row(i) = m.m.transpose();
      saturated[static_cast<std::size_t>(i)] = m.saturated;
    }
    return {moments, saturated};
  }

  [[nodiscard]] py::dict relax(double field, const std::optional<Eigen::Vector3d>& start) const {
    const Eigen::Vector3d direction = pair::field_direction(setup_.sweep.theta_h_deg);
    pair::PairState state;
    {
      const py::gil_scoped_release computing;
      state = pair::relax_at_field(system_, field, direction,
                                   start.value_or(pair::rest_configuration(system_)),
                                   setup_.sweep.relax);
    }
    return states_dict({state}, direction);
  }

  [[nodiscard]] py::dict hysteresis() const {
    pair::HysteresisLoop loop;
    {
      const py::gil_scoped_release computing;
      loop = pair::run_hysteresis(system_, setup_.sweep);
    }
    return states_dict(loop.states, pair::field_direction(setup_.sweep.theta_h_deg));
  }

  // Critical fields from the first quadrant 0 -> +max -> 0, as a pair_map point computes them.
  [[nodiscard]] py::dict critical_fields() const {
    pair::CriticalFields f;
    {
      const py::gil_scoped_release computing;
      pair::SweepOptions sweep = setup_.sweep;
      sweep.first_quadrant_only = true;
      pair::CriticalFieldOptions options;
      options.tolerance = setup_.critical_field_tolerance;
      f = pair::critical_fields_of(system_, sweep, options);
    }
    py::dict out;
    out["hysteresis"] = f.hysteresis;
    out["HC1"] = f.hc1;
    out["HC2"] = f.hc2;
    out["dH"] = f.delta();
    out["uncertainty"] = f.uncertainty;
    out["dH_uncertainty"] = f.delta_uncertainty;
    out["dH_resolved"] = f.delta_resolved;
    out["converged"] = f.converged;
    out["valid"] = f.valid();
    out["problem"] = f.problem;
    return out;
  }

 private:
  static PairSetup pick_case(const std::vector<PairSetup>& cases, const py::object& key) {
    if (key.is_none()) {
      if (cases.size() == 1) return cases.front();
      throw config::ConfigError("the run file has " + std::to_string(cases.size()) +
                                " [[case]] tables: choose one with case=<index or label>");
    }
    if (py::isinstance<py::str>(key)) {
      const auto label = key.cast<std::string>();
      for (const PairSetup& c : cases) {
        if (c.label == label) return c;
      }
      std::string labels;
      for (const PairSetup& c : cases) labels += (labels.empty() ? "" : ", ") + c.label;
      throw config::ConfigError("case = \"" + label +
                                "\": no [[case]] has this label; labels: " + labels);
    }
    const auto index = key.cast<long>();
    if (index < 0 || static_cast<std::size_t>(index) >= cases.size()) {
      throw config::ConfigError("case = " + std::to_string(index) + ": must be in [0, " +
                                std::to_string(cases.size()) + ")");
    }
    return cases[static_cast<std::size_t>(index)];
  }

  PairSetup setup_;
  pair::PairSystem system_;
};

pair::SphereMaterial material_of(double radius, double saturation_magnetization) {
  pair::SphereMaterial material;
  material.radius = radius;
  material.saturation_magnetization = saturation_magnetization;
  return material;
}

}  // namespace

void bind_pair(py::module_& m) {
  py::class_<PairModel>(m, "PairModel", "A two-dipole pair (use mresim.pair.Pair)")
      .def(py::init<const py::handle&, const std::vector<std::string>&, const py::object&>(),
           py::arg("source"), py::arg("overrides") = std::vector<std::string>{},
           py::arg("case") = py::none())
      .def("parameters", &PairModel::parameters)
      .def("energy", &PairModel::energy, py::arg("separations"), py::arg("field"))
      .def("gradient", &PairModel::gradient, py::arg("separations"), py::arg("field"))
      .def("magnetization", &PairModel::magnetization, py::arg("separations"), py::arg("field"))
      .def("relax", &PairModel::relax, py::arg("field"), py::arg("start") = py::none())
      .def("hysteresis", &PairModel::hysteresis)
      .def("critical_fields", &PairModel::critical_fields);

  m.def("field_direction", &pair::field_direction, py::arg("angle_deg"));
  const pair::SphereMaterial defaults;
  m.def(
      "clustering_threshold_separation",
      [](double k, double radius, double ms) {
        return pair::clustering_threshold_separation(material_of(radius, ms), k);
      },
      py::arg("k"), py::arg("radius") = defaults.radius,
      py::arg("saturation_magnetization") = defaults.saturation_magnetization);
  m.def(
      "clustering_threshold_stiffness",
      [](double s0, double radius, double ms) {
        return pair::clustering_threshold_stiffness(material_of(radius, ms), s0);
      },
      py::arg("rest_separation"), py::arg("radius") = defaults.radius,
      py::arg("saturation_magnetization") = defaults.saturation_magnetization);
  m.def(
      "puljiz_stiffness",
      [](double g, double radius, double s0) {
        const pair::PuljizStiffness k = pair::puljiz_stiffness(g, radius, s0);
        return std::make_pair(k.k0, k.k12);
      },
      py::arg("shear_modulus"), py::arg("radius"), py::arg("rest_separation"));
}

}  // namespace mresim::python
