#include "mresim/mess/terms/elastic_terms.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

#include "mresim/mess/lattice/volume_elements.hpp"
#include "mresim/mess/system/fixed_order.hpp"

namespace mresim::mess {

namespace {

lattice::CellVertices gather_vertices(const std::array<std::int32_t, 8>& element,
                                      const Eigen::Matrix3Xd& x) {
  lattice::CellVertices v;
  for (int k = 0; k < 8; ++k) v[k] = x.col(element[k]);
  return v;
}

// Builds node -> entries lists by counting sort; entries of a node keep increasing order of
// the producing item, so the gather order is fixed.
template <class ForEach>
void build_incidence(std::int64_t node_count, std::int64_t items, int per_item, ForEach node_of,
                     std::vector<std::int64_t>& offsets, std::vector<std::int32_t>& entries) {
  offsets.assign(static_cast<std::size_t>(node_count + 1), 0);
  for (std::int64_t i = 0; i < items; ++i) {
    for (int k = 0; k < per_item; ++k) ++offsets[static_cast<std::size_t>(node_of(i, k)) + 1];
  }
  for (std::int64_t n = 0; n < node_count; ++n) {
    offsets[static_cast<std::size_t>(n + 1)] += offsets[static_cast<std::size_t>(n)];
  }
  entries.resize(static_cast<std::size_t>(offsets.back()));
  std::vector<std::int64_t> fill(offsets.begin(), offsets.end() - 1);
  for (std::int64_t i = 0; i < items; ++i) {
    for (int k = 0; k < per_item; ++k) {
      entries[static_cast<std::size_t>(fill[static_cast<std::size_t>(node_of(i, k))]++)] =
          static_cast<std::int32_t>(i * per_item + k);
    }
  }
}

}  // namespace

// ---------------------------------------------------------------- serial reference formulas

double spring_energy(const lattice::SpringSet& springs, const Eigen::Matrix3Xd& x) {
  double energy = 0.0;
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const double stretch =
        (x.col(springs.second[s]) - x.col(springs.first[s])).norm() - springs.rest_length(s);
    energy += 0.5 * springs.stiffness[s] * stretch * stretch;  // eq. 4.62
  }
  return energy;
}

void add_spring_gradient(const lattice::SpringSet& springs, const Eigen::Matrix3Xd& x,
                         Eigen::Matrix3Xd& gradient) {
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const Eigen::Vector3d r = x.col(springs.second[s]) - x.col(springs.first[s]);
    const double l = r.norm();
    // eq. 4.63: the force on the second end is -k (l - L) r^; the gradient is its negative.
    const Eigen::Vector3d g = springs.stiffness[s] * (l - springs.rest_length(s)) / l * r;
    gradient.col(springs.second[s]) += g;
    gradient.col(springs.first[s]) -= g;
  }
}

double volume_energy(const std::vector<std::array<std::int32_t, 8>>& elements, double kappa,
                     double element_length, const Eigen::Matrix3Xd& x) {
  const double v0 = element_length * element_length * element_length;
  double energy = 0.0;
  for (const auto& e : elements) {
    const double dv = lattice::cell_volume(gather_vertices(e, x)) / v0 - 1.0;
    energy += 0.5 * kappa * v0 * dv * dv;  // eq. 4.64 times V0
  }
  return energy;
}

void add_volume_gradient(const std::vector<std::array<std::int32_t, 8>>& elements, double kappa,
                         double element_length, const Eigen::Matrix3Xd& x,
                         Eigen::Matrix3Xd& gradient, double force_factor) {
  const double v0 = element_length * element_length * element_length;
  lattice::CellVertices dv_dx;
  for (const auto& e : elements) {
    const double v = lattice::cell_volume_and_gradient(gather_vertices(e, x), dv_dx);
    // eq. 4.65: dU/dx_v = kappa (V/V0 - 1) dV/dx_v (V0 cancels against the 1/V0 of V/V0).
    const double f = force_factor * kappa * (v / v0 - 1.0);
    for (int k = 0; k < 8; ++k) gradient.col(e[k]) += f * dv_dx[k];
  }
}

// ------------------------------------------------------------------------- ElasticTerms

ElasticTerms::ElasticTerms(const lattice::Lattice& lat, ElasticTermSettings settings)
    : settings_(settings), node_count_(lat.node_count()) {
  const lattice::SpringSet& sp = lat.springs;
  // Incidence entries are int32: 2 s + 1 and 8 c + 7 must fit.
  if (sp.size() >= (std::size_t{1} << 30) || lat.elements.size() >= (std::size_t{1} << 28)) {
    throw std::invalid_argument("ElasticTerms: too many springs or cells for 32-bit incidence");
  }
  build_incidence(
      node_count_, static_cast<std::int64_t>(sp.size()), 2,
      [&](std::int64_t s, int k) {
        return k == 0 ? sp.first[static_cast<std::size_t>(s)]
                      : sp.second[static_cast<std::size_t>(s)];
      },
      spring_offsets_, spring_entries_);
  build_incidence(
      node_count_, static_cast<std::int64_t>(lat.elements.size()), 8,
      [&](std::int64_t c, int v) { return lat.elements[static_cast<std::size_t>(c)][v]; },
      cell_offsets_, cell_entries_);
}

ElasticEnergies ElasticTerms::evaluate(const lattice::Lattice& lat, const Eigen::Matrix3Xd& x,
                                       Eigen::Matrix3Xd* gradient) const {
  if (x.cols() != node_count_ || lat.node_count() != node_count_) {
    throw std::invalid_argument("ElasticTerms::evaluate: positions do not match the lattice");
  }
  const lattice::SpringSet& sp = lat.springs;
  const auto springs = static_cast<std::int64_t>(sp.size());
  const auto cells = static_cast<std::int64_t>(lat.elements.size());
  const double kappa = lat.polymer.kappa;
  const double v0 = std::pow(lat.element_length, 3);
  const bool want_gradient = gradient != nullptr;
  if (want_gradient) {
    tension_.resize(static_cast<std::size_t>(springs));
    cell_terms_.resize(static_cast<std::size_t>(9 * cells));
  }

  ElasticEnergies out;
  // Springs: energy (eq. 4.62) and tension k (l - L)/l (eq. 4.63).
  const auto spring_sums = detail::fixed_order_sums(springs, [&](std::int64_t s) {
    const auto u = static_cast<std::size_t>(s);
    const double l = (x.col(sp.second[u]) - x.col(sp.first[u])).norm();
    const double stretch = l - sp.rest_length(u);
    if (want_gradient) tension_[u] = sp.stiffness[u] * stretch / l;
    const double k_stretch = sp.stiffness[u] * stretch;
    return std::array<double, 2>{0.5 * k_stretch * stretch, std::abs(k_stretch) * l};
  });
  out.springs = spring_sums[0];
  out.springs_rounding = spring_sums[1];
  // Cells: energy (eq. 4.64 x V0) and f (b x c), f (c x a), f (a x b) with
  // f = factor kappa (V/V0 - 1)/4, so that dU/dx_v = s_a f (b x c) + s_b f (c x a) + s_c f (a x b)
  // (eqs. 4.66-4.69 with the 1/4 of the averaged edge vectors).
  const double factor = settings_.volume_force_factor;
  const auto volume_sums = detail::fixed_order_sums(cells, [&](std::int64_t c) {
    const lattice::EdgeVectors e = lattice::averaged_edge_vectors(
        gather_vertices(lat.elements[static_cast<std::size_t>(c)], x));
    const Eigen::Vector3d bxc = e.b.cross(e.c);
    const double dv = e.a.dot(bxc) / v0 - 1.0;
    if (want_gradient) {
      const double f = 0.25 * factor * kappa * dv;
      double* t = cell_terms_.data() + 9 * c;
      Eigen::Map<Eigen::Vector3d> t_bc(t);
      Eigen::Map<Eigen::Vector3d> t_ca(t + 3);
      Eigen::Map<Eigen::Vector3d> t_ab(t + 6);
      t_bc = f * bxc;
      t_ca = f * e.c.cross(e.a);
      t_ab = f * e.a.cross(e.b);
    }
    return std::array<double, 2>{0.5 * kappa * v0 * dv * dv, std::abs(kappa * v0 * dv)};
  });
  out.volume = volume_sums[0];
  out.volume_rounding = volume_sums[1];
  if (gradient == nullptr) return out;

  // Gather: every node sums its own springs and cells in a fixed order (no races, no atomics).
  gradient->resize(3, node_count_);
#pragma omp parallel for schedule(static) if (node_count_ >= detail::kParallelMinimum / 4)
  for (std::int64_t n = 0; n < node_count_; ++n) {
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (std::int64_t k = spring_offsets_[n]; k < spring_offsets_[n + 1]; ++k) {
      const std::int32_t entry = spring_entries_[static_cast<std::size_t>(k)];
      const auto s = static_cast<std::size_t>(entry >> 1);
      const Eigen::Vector3d r = x.col(sp.second[s]) - x.col(sp.first[s]);
      if (entry & 1) {
        g += tension_[s] * r;
      } else {
        g -= tension_[s] * r;
      }
    }
    for (std::int64_t k = cell_offsets_[n]; k < cell_offsets_[n + 1]; ++k) {
      const std::int32_t entry = cell_entries_[static_cast<std::size_t>(k)];
      const int v = entry & 7;
      const double* t = cell_terms_.data() + 9 * static_cast<std::int64_t>(entry >> 3);
      // Signs of lattice::cell_volume_and_gradient: bit 1 = +x face (a), bit 2 = +y (b),
      // bit 0 = +z (c).
      const double sa = (v & 2) ? 1.0 : -1.0;
      const double sb = (v & 4) ? 1.0 : -1.0;
      const double sc = (v & 1) ? 1.0 : -1.0;
      g += sa * Eigen::Map<const Eigen::Vector3d>(t) +
           sb * Eigen::Map<const Eigen::Vector3d>(t + 3) +
           sc * Eigen::Map<const Eigen::Vector3d>(t + 6);
    }
    gradient->col(n) = g;
  }
  return out;
}

}  // namespace mresim::mess
