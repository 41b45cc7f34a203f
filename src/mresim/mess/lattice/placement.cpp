#include "mresim/mess/lattice/placement.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "mresim/magnetism/portable_random.hpp"

namespace mresim::lattice {

namespace {

std::string metres(const Eigen::Vector3d& x) {
  return fmt::format("({:.6g}, {:.6g}, {:.6g}) m", x[0], x[1], x[2]);
}

void validate_box(const BoxSpec& box, const char* placement) {
  for (int a = 0; a < 3; ++a) {
    if (!(box.lengths[a] > 0.0) || !std::isfinite(box.lengths[a])) {
      throw std::invalid_argument(fmt::format(
          "{} placement: box lengths {} are not allowed: each must be positive and finite",
          placement, metres(box.lengths)));
    }
  }
}

void validate_count(int count, const char* placement) {
  if (count < 1) {
    throw std::invalid_argument(
        fmt::format("{} placement: count = {} is not allowed: it must be >= 1", placement, count));
  }
}

Eigen::Vector3d centre_or_middle(const std::optional<Eigen::Vector3d>& centre, const BoxSpec& box) {
  return centre ? *centre : Eigen::Vector3d(0.5 * box.lengths);
}

// One integer in {-1, 0, +1}, uniform, from one 53-bit uniform u in (0, 1]: ceil(3u) - 2.
int noise_shift(magnetism::PortableNormal& rng) {
  const int bucket = static_cast<int>(std::ceil(3.0 * rng.uniform_open()));  // 1, 2 or 3
  return std::min(bucket, 3) - 2;
}

PlacedParticles finish(const GridShape& shape, std::vector<std::array<int, 3>> cells,
                       int discretization_order, double element_length) {
  PlacedParticles out;
  out.shape = shape;
  out.particles = voxelize_particles(shape, cells, discretization_order, element_length);
  out.centre_cells = std::move(cells);
  return out;
}

PlacedParticles place(const RegularPlacement& r, double radius, int order, double l_e) {
  const std::array<double, 3> unit{1.0, 1.0, 1.0};
  const VolumeFractionBox box =
      box_from_volume_fraction(radius, l_e, r.volume_fraction, r.particles_along_axes,
                               r.anisotropic ? r.anisotropy_factor : unit);
  magnetism::PortableNormal rng(r.noise_seed);
  std::vector<std::array<int, 3>> cells;
  const auto& n = r.particles_along_axes;
  for (int i = 0; i < n[0]; ++i) {
    for (int j = 0; j < n[1]; ++j) {
      for (int k = 0; k < n[2]; ++k) {
        const std::array<int, 3> index{i, j, k};
        std::array<int, 3> cell{};
        for (int a = 0; a < 3; ++a) {
          // first_centre is a half-integer; the cell below it holds the centre.
          const double centre = box.first_centre[a] + box.spacing_voxels[a] * index[a];
          cell[a] = static_cast<int>(std::floor(centre));
        }
        if (r.noisy) {
          for (int a = 0; a < 3; ++a) cell[a] += noise_shift(rng);
        }
        cells.push_back(cell);
      }
    }
  }
  return finish(box.shape, std::move(cells), order, l_e);
}

PlacedParticles place_positions(const BoxSpec& box, const std::vector<Eigen::Vector3d>& positions,
                                int order, double l_e, const char* placement) {
  validate_box(box, placement);
  const GridShape shape = shape_of_box(box, l_e);
  std::vector<std::array<int, 3>> cells;
  cells.reserve(positions.size());
  for (std::size_t p = 0; p < positions.size(); ++p) {
    cells.push_back(cell_of_position(shape, l_e, positions[p],
                                     fmt::format("{} placement: particle {}", placement, p)));
  }
  return finish(shape, std::move(cells), order, l_e);
}

}  // namespace

PlacementKind parse_placement_kind(std::string_view name) {
  if (name == "regular") return PlacementKind::regular;
  if (name == "regular_noisy") return PlacementKind::regular_noisy;
  if (name == "regular_anisotropic" || name == "anisotropic_regular") {
    return PlacementKind::regular_anisotropic;
  }
  if (name == "regular_anisotropic_noisy" || name == "anisotropic_regular_noisy") {
    return PlacementKind::regular_anisotropic_noisy;
  }
  if (name == "by_hand") return PlacementKind::by_hand;
  if (name == "chain") return PlacementKind::chain;
  if (name == "helix") return PlacementKind::helix;
  if (name == "none") return PlacementKind::none;
  throw std::invalid_argument(fmt::format(
      "unknown particle placement '{}': allowed values are 'regular', 'regular_noisy', "
      "'regular_anisotropic' (or 'anisotropic_regular'), 'regular_anisotropic_noisy' (or "
      "'anisotropic_regular_noisy'), 'by_hand', 'chain', 'helix', 'none'",
      name));
}

std::string to_string(PlacementKind kind) {
  switch (kind) {
    case PlacementKind::regular:
      return "regular";
    case PlacementKind::regular_noisy:
      return "regular_noisy";
    case PlacementKind::regular_anisotropic:
      return "regular_anisotropic";
    case PlacementKind::regular_anisotropic_noisy:
      return "regular_anisotropic_noisy";
    case PlacementKind::by_hand:
      return "by_hand";
    case PlacementKind::chain:
      return "chain";
    case PlacementKind::helix:
      return "helix";
    case PlacementKind::none:
      return "none";
  }
  return "";
}

PlacementKind kind_of(const Placement& placement) {
  if (const auto* r = std::get_if<RegularPlacement>(&placement)) {
    if (r->anisotropic) {
      return r->noisy ? PlacementKind::regular_anisotropic_noisy
                      : PlacementKind::regular_anisotropic;
    }
    return r->noisy ? PlacementKind::regular_noisy : PlacementKind::regular;
  }
  if (const auto* h = std::get_if<ByHandPlacement>(&placement)) {
    return h->positions.empty() ? PlacementKind::none : PlacementKind::by_hand;
  }
  if (std::holds_alternative<ChainPlacement>(placement)) return PlacementKind::chain;
  return PlacementKind::helix;
}

GridShape shape_of_box(const BoxSpec& box, double element_length) {
  GridShape shape;
  for (int a = 0; a < 3; ++a) {
    if (box.rounding == BoxRounding::seed_floor_divide) {
      const double elements = python_floor_divide(box.lengths[a], element_length);
      if (!(elements >= 1.0) || elements > 2.0e9) {
        throw std::invalid_argument(fmt::format(
            "a box length of {} m gives {} elements along {} at l_e = {} m; at least 1 is needed",
            box.lengths[a], elements, "xyz"[a], element_length));
      }
      shape.nodes[a] = static_cast<int>(elements) + 1;
    } else {
      shape.nodes[a] = nodes_along_axis(box.lengths[a], element_length);
    }
  }
  validate_grid_shape(shape);
  return shape;
}

std::array<int, 3> cell_of_position(const GridShape& shape, double element_length,
                                    const Eigen::Vector3d& position, const std::string& what) {
  std::array<int, 3> cell{};
  for (int a = 0; a < 3; ++a) {
    const double length = (shape.nodes[a] - 1) * element_length;
    if (!(position[a] >= 0.0 && position[a] < length)) {
      throw std::invalid_argument(fmt::format(
          "{} at {} is outside the box [0, {:.6g}] x [0, {:.6g}] x [0, {:.6g}] m", what,
          metres(position), (shape.nodes[0] - 1) * element_length,
          (shape.nodes[1] - 1) * element_length, (shape.nodes[2] - 1) * element_length));
    }
    cell[a] =
        std::min(static_cast<int>(std::floor(position[a] / element_length)), shape.nodes[a] - 2);
  }
  return cell;
}

std::vector<Eigen::Vector3d> chain_positions(const ChainPlacement& chain) {
  validate_count(chain.count, "chain");
  if (chain.axis < 0 || chain.axis > 2) {
    throw std::invalid_argument(fmt::format(
        "chain placement: axis = {} is not allowed: use 0 (x), 1 (y) or 2 (z)", chain.axis));
  }
  if (!(chain.separation > 0.0) || !std::isfinite(chain.separation)) {
    throw std::invalid_argument(
        fmt::format("chain placement: separation = {} m is not allowed: it must be positive",
                    chain.separation));
  }
  const Eigen::Vector3d centre = centre_or_middle(chain.centre, chain.box);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < chain.count; ++i) {
    Eigen::Vector3d x = centre;
    x[chain.axis] += (i - 0.5 * (chain.count - 1)) * chain.separation;
    out.push_back(x);
  }
  return out;
}

std::vector<Eigen::Vector3d> helix_positions(const HelixPlacement& helix) {
  validate_count(helix.count, "helix");
  if (!(helix.radius >= 0.0) || !std::isfinite(helix.radius) ||
      !std::isfinite(helix.axial_separation) || !std::isfinite(helix.angle_step)) {
    throw std::invalid_argument(fmt::format(
        "helix placement: radius = {} m, axial_separation = {} m, angle_step = {} rad are not "
        "allowed: the radius must be >= 0 and all must be finite",
        helix.radius, helix.axial_separation, helix.angle_step));
  }
  const Eigen::Vector3d centre = centre_or_middle(helix.centre, helix.box);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < helix.count; ++i) {
    const double phi = i * helix.angle_step;
    out.emplace_back(centre[0] + helix.radius * std::cos(phi),
                     centre[1] + helix.radius * std::sin(phi),
                     centre[2] + (i - 0.5 * (helix.count - 1)) * helix.axial_separation);
  }
  return out;
}

PlacedParticles place_particles(const Placement& placement, double particle_radius,
                                int discretization_order) {
  const double l_e = element_length(particle_radius, discretization_order);
  if (const auto* r = std::get_if<RegularPlacement>(&placement)) {
    return place(*r, particle_radius, discretization_order, l_e);
  }
  if (const auto* h = std::get_if<ByHandPlacement>(&placement)) {
    return place_positions(h->box, h->positions, discretization_order, l_e, "by_hand");
  }
  if (const auto* c = std::get_if<ChainPlacement>(&placement)) {
    return place_positions(c->box, chain_positions(*c), discretization_order, l_e, "chain");
  }
  const auto& helix = std::get<HelixPlacement>(placement);
  return place_positions(helix.box, helix_positions(helix), discretization_order, l_e, "helix");
}

}  // namespace mresim::lattice
