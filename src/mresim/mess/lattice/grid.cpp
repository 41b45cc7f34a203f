#include "mresim/mess/lattice/grid.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace mresim::lattice {

double element_length(double particle_radius, int discretization_order) {
  if (!(particle_radius > 0.0) || !std::isfinite(particle_radius)) {
    throw std::invalid_argument(fmt::format(
        "particle_radius = {} m is not allowed: it must be positive and finite", particle_radius));
  }
  if (discretization_order < 1) {
    throw std::invalid_argument(
        fmt::format("discretization_order = {} is not allowed: it must be >= 1 (a particle is "
                    "2 n_d + 1 voxels across)",
                    discretization_order));
  }
  return particle_radius / (discretization_order + 0.5);  // eq. 4.49
}

int nodes_along_axis(double length, double element_length) {
  const double n = std::nearbyint(length / element_length + 1.0);  // ties to even
  if (!(n >= 2.0) || n > std::numeric_limits<int>::max()) {
    throw std::invalid_argument(fmt::format(
        "a box length of {} m gives {} nodes along an axis at l_e = {} m; at least 2 are needed",
        length, n, element_length));
  }
  return static_cast<int>(n);
}

double python_floor_divide(double a, double b) {
  // CPython Objects/floatobject.c, float_floor_div / _float_div_mod.
  const double mod = std::fmod(a, b);
  double div = (a - mod) / b;
  if (mod != 0.0 && (b < 0.0) != (mod < 0.0)) div -= 1.0;
  if (div != 0.0) {
    double floordiv = std::floor(div);
    if (div - floordiv > 0.5) floordiv += 1.0;
    return floordiv;
  }
  return std::copysign(0.0, a / b);
}

int seed_spacing_voxels(double x) {
  const double voxels = std::trunc(std::nearbyint(x * 10.0) / 10.0);
  // Checked before the conversion: a double outside int's range is undefined behaviour (found
  // by UBSan with volume_fraction = 5e-324).
  if (!(voxels >= 0.0 && voxels <= std::numeric_limits<int>::max())) {
    throw std::invalid_argument(fmt::format(
        "gives a particle spacing of {} voxels, beyond the {} that 32-bit indices allow", voxels,
        std::numeric_limits<int>::max()));
  }
  return static_cast<int>(voxels);
}

std::int64_t GridShape::node_count() const {
  return static_cast<std::int64_t>(nodes[0]) * nodes[1] * nodes[2];
}

std::int64_t GridShape::cell_count() const {
  return static_cast<std::int64_t>(nodes[0] - 1) * (nodes[1] - 1) * (nodes[2] - 1);
}

std::array<int, 3> GridShape::node_coordinates(int node) const {
  const int iz = node % nodes[2];
  const int rest = node / nodes[2];
  return {rest % nodes[0], rest / nodes[0], iz};
}

std::array<int, 3> GridShape::cell_coordinates(int cell) const {
  const int cx = nodes[0] - 1;
  const int cy = nodes[1] - 1;
  return {cell % cx, (cell / cx) % cy, cell / (cx * cy)};
}

void validate_grid_shape(const GridShape& shape) {
  for (int a = 0; a < 3; ++a) {
    if (shape.nodes[a] < 2) {
      throw std::invalid_argument(
          fmt::format("the lattice needs at least 2 nodes along each axis, got {} x {} x {}",
                      shape.nodes[0], shape.nodes[1], shape.nodes[2]));
    }
  }
  if (shape.node_count() > std::numeric_limits<std::int32_t>::max()) {
    throw std::invalid_argument(fmt::format(
        "a lattice of {} x {} x {} nodes exceeds the 2^31 - 1 nodes that 32-bit indices allow",
        shape.nodes[0], shape.nodes[1], shape.nodes[2]));
  }
}

NodeClass node_class(std::int8_t type_code) {
  if (type_code < 0) return NodeClass::particle;
  if (type_code == 0) return NodeClass::interior;
  if (type_code <= 6) return NodeClass::face;
  if (type_code <= 18) return NodeClass::edge;
  return NodeClass::corner;
}

std::int8_t node_type_code(const GridShape& shape, int ix, int iy, int iz) {
  using namespace node_type;
  // -1: lower face, +1: upper face, 0: neither (x: left/right, y: front/back, z: bottom/top).
  const int sx = ix == 0 ? -1 : (ix == shape.nx() - 1 ? 1 : 0);
  const int sy = iy == 0 ? -1 : (iy == shape.ny() - 1 ? 1 : 0);
  const int sz = iz == 0 ? -1 : (iz == shape.nz() - 1 ? 1 : 0);
  const int count = (sx != 0) + (sy != 0) + (sz != 0);
  if (count == 0) return kInterior;
  if (count == 1) {
    if (sx != 0) return sx < 0 ? kLeft : kRight;
    if (sy != 0) return sy < 0 ? kFront : kBack;
    return sz < 0 ? kBottom : kTop;
  }
  if (count == 2) {
    if (sx < 0) {
      if (sz != 0) return sz > 0 ? kLeftTop : kLeftBottom;
      return sy < 0 ? kLeftFront : kLeftBack;
    }
    if (sx > 0) {
      if (sz != 0) return sz > 0 ? kRightTop : kRightBottom;
      return sy < 0 ? kRightFront : kRightBack;
    }
    if (sz > 0) return sy < 0 ? kTopFront : kTopBack;
    return sy < 0 ? kBottomFront : kBottomBack;
  }
  // Corners 19-26 in the original's order: (0,0,0), (X,0,0), (0,Y,0), (0,0,Z), (X,Y,0),
  // (X,0,Z), (0,Y,Z), (X,Y,Z).
  const bool x = sx > 0;
  const bool y = sy > 0;
  const bool z = sz > 0;
  if (!x && !y && !z) return kCorner000;
  if (x && !y && !z) return kCornerX00;
  if (!x && y && !z) return kCorner0Y0;
  if (!x && !y && z) return kCorner00Z;
  if (x && y && !z) return kCornerXY0;
  if (x && !y && z) return kCornerX0Z;
  if (!x && y && z) return kCorner0YZ;
  return kCornerXYZ;
}

std::vector<std::int8_t> node_type_codes(const GridShape& shape) {
  std::vector<std::int8_t> codes(static_cast<std::size_t>(shape.node_count()));
  for (int iy = 0; iy < shape.ny(); ++iy) {
    for (int ix = 0; ix < shape.nx(); ++ix) {
      for (int iz = 0; iz < shape.nz(); ++iz) {
        codes[shape.node_index(ix, iy, iz)] = node_type_code(shape, ix, iy, iz);
      }
    }
  }
  return codes;
}

std::vector<int> face_nodes(const GridShape& shape, Face face) {
  int axis = 0;
  bool upper = false;
  switch (face) {
    case Face::left:
      axis = 0;
      upper = false;
      break;
    case Face::right:
      axis = 0;
      upper = true;
      break;
    case Face::front:
      axis = 1;
      upper = false;
      break;
    case Face::back:
      axis = 1;
      upper = true;
      break;
    case Face::bottom:
      axis = 2;
      upper = false;
      break;
    case Face::top:
      axis = 2;
      upper = true;
      break;
  }
  const int fixed = upper ? shape.nodes[axis] - 1 : 0;
  std::vector<int> out;
  for (int iy = 0; iy < shape.ny(); ++iy) {
    for (int ix = 0; ix < shape.nx(); ++ix) {
      for (int iz = 0; iz < shape.nz(); ++iz) {
        const std::array<int, 3> c{ix, iy, iz};
        if (c[axis] == fixed) out.push_back(shape.node_index(ix, iy, iz));
      }
    }
  }
  return out;
}

double sphere_volume(double radius) {
  return 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
}

VolumeFractionBox box_from_volume_fraction(double particle_radius, double element_length,
                                           double volume_fraction,
                                           const std::array<int, 3>& particles_along_axes,
                                           const std::array<double, 3>& anisotropy_factor) {
  if (!(volume_fraction > 0.0 && volume_fraction < 1.0)) {
    throw std::invalid_argument(
        fmt::format("volume_fraction = {} is not allowed: it must lie in the open interval (0, 1)",
                    volume_fraction));
  }
  for (int a = 0; a < 3; ++a) {
    if (particles_along_axes[a] < 1) {
      throw std::invalid_argument(
          fmt::format("particles_along_axes = [{}, {}, {}] is not allowed: each entry must be >= 1",
                      particles_along_axes[0], particles_along_axes[1], particles_along_axes[2]));
    }
    if (!(anisotropy_factor[a] > 0.0) || !std::isfinite(anisotropy_factor[a])) {
      throw std::invalid_argument(fmt::format(
          "anisotropy_factor = [{}, {}, {}] is not allowed: each entry must be positive",
          anisotropy_factor[0], anisotropy_factor[1], anisotropy_factor[2]));
    }
  }
  VolumeFractionBox box;
  box.cube_side = std::cbrt(sphere_volume(particle_radius) / volume_fraction);  // eq. 4.52
  int spacing = 0;
  try {
    spacing = seed_spacing_voxels(box.cube_side / element_length);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("volume_fraction = {} {}", volume_fraction, e.what()));
  }
  for (int a = 0; a < 3; ++a) {
    box.lengths[a] = particles_along_axes[a] * box.cube_side * anisotropy_factor[a];
    box.shape.nodes[a] = nodes_along_axis(box.lengths[a], element_length);
    const double spacing_along_axis = std::trunc(spacing * anisotropy_factor[a]);
    box.spacing_voxels[a] = spacing_along_axis <= std::numeric_limits<int>::max()
                                ? static_cast<int>(spacing_along_axis)
                                : std::numeric_limits<int>::max();
    if (box.spacing_voxels[a] < 1) {
      throw std::invalid_argument(fmt::format(
          "volume_fraction = {} gives a particle spacing of {} voxels along axis {}; at least 1 "
          "is needed",
          volume_fraction, box.spacing_voxels[a], "xyz"[a]));
    }
    const int excess =
        (box.shape.nodes[a] - 1) - box.spacing_voxels[a] * (particles_along_axes[a] - 1);
    box.first_centre[a] = 0.5 * excess + (excess % 2 == 0 ? 0.5 : 0.0);
  }
  validate_grid_shape(box.shape);
  return box;
}

}  // namespace mresim::lattice
