#pragma once

// Test-only energy evaluators for affine deformations x -> F x (no gradients, no solver):
//  - one periodic cell, from the per-cell spring share of eqs. 4.23-4.27 (3 edge, 6 face and
//    4 body springs) plus the volume term 0.5 kappa (V/V0 - 1)^2 (eq. 4.16);
//  - a whole built Lattice, from its own SpringSet and elements (cell_volume, eq. 4.48).
// Both return energy per undeformed volume (J/m^3).

#include <Eigen/Dense>

#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/lattice/volume_elements.hpp"

namespace mresim::lattice::testing {

inline double cell_energy_density(const LatticeStiffness& s, double l_e, const Eigen::Matrix3d& f) {
  double energy = 0.0;
  const auto spring = [&](double k, const Eigen::Vector3d& r) {
    const double stretch = (f * r).norm() - r.norm();
    energy += 0.5 * k * stretch * stretch;
  };
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitX() * l_e;
  const Eigen::Vector3d ey = Eigen::Vector3d::UnitY() * l_e;
  const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ() * l_e;
  for (const Eigen::Vector3d& r : {ex, ey, ez}) spring(s.springs.edge, r);  // eq. 4.23
  for (const Eigen::Vector3d& r : {Eigen::Vector3d(ex + ey + ez), Eigen::Vector3d(ex + ey - ez),
                                   Eigen::Vector3d(ex - ey + ez), Eigen::Vector3d(-ex + ey + ez)}) {
    spring(s.springs.body, r);  // eqs. 4.24-4.25
  }
  for (const Eigen::Vector3d& r :
       {Eigen::Vector3d(ex + ey), Eigen::Vector3d(ex - ey), Eigen::Vector3d(ey + ez),
        Eigen::Vector3d(ey - ez), Eigen::Vector3d(ex + ez), Eigen::Vector3d(ex - ez)}) {
    spring(s.springs.face, r);  // eqs. 4.26-4.27
  }
  const double v0 = l_e * l_e * l_e;
  const double dv = f.determinant() - 1.0;
  return energy / v0 + 0.5 * s.kappa * dv * dv;
}

inline double lattice_energy_density(const Lattice& lat, const Eigen::Matrix3d& f) {
  const Eigen::Matrix3Xd x = f * lat.positions;
  double energy = 0.0;
  const SpringSet& s = lat.springs;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double stretch = (x.col(s.second(i)) - x.col(s.first[i])).norm() - s.rest_length(i);
    energy += 0.5 * s.stiffness(i) * stretch * stretch;
  }
  const double v0 = std::pow(lat.element_length, 3);
  for (const auto& e : lat.elements) {
    CellVertices v;
    for (int k = 0; k < 8; ++k) v[k] = x.col(e[k]);
    const double dv = cell_volume(v) / v0 - 1.0;
    energy += 0.5 * lat.polymer.kappa * v0 * dv * dv;
  }
  return energy / lat.box_lengths().prod();
}

// Second derivative of w(F(h)) at h = 0 by central differences (w(0) = 0 for affine modes).
template <class EnergyOfH>
double second_derivative(EnergyOfH w, double h = 1e-5) {
  return (w(h) - 2.0 * w(0.0) + w(-h)) / (h * h);
}

// Deformation gradients: simple shear x += gamma z; uniaxial strain along x; equibiaxial strain
// in x and y; uniform dilation.
inline Eigen::Matrix3d simple_shear(double gamma) {
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  f(0, 2) = gamma;
  return f;
}
inline Eigen::Matrix3d uniaxial(double e) {
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  f(0, 0) += e;
  return f;
}
inline Eigen::Matrix3d biaxial(double e) {
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  f(0, 0) += e;
  f(1, 1) += e;
  return f;
}
inline Eigen::Matrix3d dilation(double e) { return (1.0 + e) * Eigen::Matrix3d::Identity(); }

// Moduli measured from an energy-density function W(F): G from simple shear (W = G g^2/2),
// C11 from uniaxial strain (W = C11 e^2/2), C12 from biaxial (W = (C11 + C12) e^2), K from
// dilation (W = 9 K e^2/2); E and nu under uniaxial stress of a cubic medium.
struct MeasuredModuli {
  double shear, c11, c12, bulk, youngs, poisson;
};
template <class EnergyOfF>
MeasuredModuli measure_moduli(EnergyOfF w) {
  MeasuredModuli m{};
  m.shear = second_derivative([&](double h) { return w(simple_shear(h)); });
  m.c11 = second_derivative([&](double h) { return w(uniaxial(h)); });
  m.c12 = 0.5 * second_derivative([&](double h) { return w(biaxial(h)); }) - m.c11;
  m.bulk = second_derivative([&](double h) { return w(dilation(h)); }) / 9.0;
  m.youngs = (m.c11 - m.c12) * (m.c11 + 2.0 * m.c12) / (m.c11 + m.c12);
  m.poisson = m.c12 / (m.c11 + m.c12);
  return m;
}

}  // namespace mresim::lattice::testing
