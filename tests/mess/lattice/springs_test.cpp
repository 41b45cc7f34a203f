#include "mresim/mess/lattice/springs.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <set>
#include <tuple>

#include "../../support/dissertation_values.hpp"
#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/profile/model_profile.hpp"

namespace mresim::lattice {
namespace {

using mresim::testing::kLe;

const SpringConstants kPolymer{22.0, 6.0, 6.0};
const SpringConstants kParticle{220000.0, 60000.0, 60000.0};

// Counts of springs by kind and by weight (1/4, 1/2, 1 of the bulk constant) or particle.
struct Tally {
  std::int64_t quarter[3] = {0, 0, 0}, half[3] = {0, 0, 0}, full[3] = {0, 0, 0},
               particle[3] = {0, 0, 0};
  std::int64_t kind_total(int k) const { return quarter[k] + half[k] + full[k] + particle[k]; }
};
Tally tally(const SpringSet& s, const SpringConstants& polymer) {
  Tally t;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const int k = static_cast<int>(s.kind(i));
    if (s.particle(i)) {
      ++t.particle[k];
      continue;
    }
    const double w = s.stiffness(i) / constant_of(polymer, s.kind(i));
    if (std::abs(w - 0.25) < 1e-12) {
      ++t.quarter[k];
    } else if (std::abs(w - 0.5) < 1e-12) {
      ++t.half[k];
    } else if (std::abs(w - 1.0) < 1e-12) {
      ++t.full[k];
    } else {
      ADD_FAILURE() << "unexpected weight " << w;
    }
  }
  return t;
}

TEST(LatticeSprings, ForwardNeighboursRaiseTheIndexAndCoverAll26) {
  const GridShape s{{3, 3, 3}};
  std::set<std::array<int, 3>> all;
  for (const auto& d : kForwardNeighbours) {
    EXPECT_GT(s.node_index(1 + d[0], 1 + d[1], 1 + d[2]), s.node_index(1, 1, 1));
    all.insert(d);
    all.insert({-d[0], -d[1], -d[2]});
  }
  EXPECT_EQ(all.size(), 26u);
  EXPECT_EQ(kind_of_offset(kForwardNeighbours[2]), SpringKind::edge);
  EXPECT_EQ(kind_of_offset(kForwardNeighbours[8]), SpringKind::face);
  EXPECT_EQ(kind_of_offset(kForwardNeighbours[12]), SpringKind::body);
  EXPECT_DOUBLE_EQ(rest_length_factor(SpringKind::face), std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(rest_length_factor(SpringKind::body), std::sqrt(3.0));
}

// Every spring of a particle-free box, by kind and weight, against the closed forms of
// docs/original-code.md#springs.
TEST(LatticeSprings, CountsMatchClosedForms) {
  for (const GridShape shape : {GridShape{{2, 2, 2}}, GridShape{{2, 3, 5}}, GridShape{{3, 3, 3}},
                                GridShape{{4, 5, 6}}, GridShape{{7, 3, 9}}}) {
    const SpringSet s =
        build_springs(shape, kLe, kPolymer, kParticle, {}, ParticleSpringRule::same_particle);
    const Tally t = tally(s, kPolymer);
    const SpringCounts c = closed_form_spring_counts(shape);
    const std::int64_t nx = shape.nx(), ny = shape.ny(), nz = shape.nz();
    EXPECT_EQ(t.kind_total(0), (nx - 1) * ny * nz + nx * (ny - 1) * nz + nx * ny * (nz - 1));
    EXPECT_EQ(t.kind_total(1),
              2 * ((nx - 1) * (ny - 1) * nz + (nx - 1) * ny * (nz - 1) + nx * (ny - 1) * (nz - 1)));
    EXPECT_EQ(t.kind_total(2), 4 * (nx - 1) * (ny - 1) * (nz - 1));
    EXPECT_EQ(t.quarter[0], c.edge.quarter);
    EXPECT_EQ(t.half[0], c.edge.half);
    EXPECT_EQ(t.full[0], c.edge.full);
    EXPECT_EQ(t.quarter[1], 0);
    EXPECT_EQ(t.half[1], c.face.half);
    EXPECT_EQ(t.full[1], c.face.full);
    EXPECT_EQ(t.full[2], c.body.full);
    EXPECT_EQ(static_cast<std::int64_t>(s.size()), c.total());
    for (std::size_t i = 0; i < s.size(); ++i) ASSERT_LT(s.first[i], s.second(i));
    // Every cell holds exactly 12 x 1/4 edge, 12 x 1/2 face and 4 body springs' worth.
    double sum[3] = {0, 0, 0};
    for (std::size_t i = 0; i < s.size(); ++i) sum[static_cast<int>(s.kind(i))] += s.stiffness(i);
    const double cells = static_cast<double>(shape.cell_count());
    EXPECT_NEAR(sum[0], cells * 3 * kPolymer.edge, 1e-9 * sum[0]);
    EXPECT_NEAR(sum[1], cells * 6 * kPolymer.face, 1e-9 * sum[1]);
    EXPECT_NEAR(sum[2], cells * 4 * kPolymer.body, 1e-9 * sum[2]);
  }
}

// The first node's springs come in the original's order (+z, +x, +y, then face diagonals...).
TEST(LatticeSprings, OrderOfTheOriginal) {
  const GridShape shape{{3, 3, 3}};
  const SpringSet s =
      build_springs(shape, kLe, kPolymer, kParticle, {}, ParticleSpringRule::same_particle);
  // Node 0 = (0,0,0): +z, +x, +y, (+y,+z), (+x,+z), (+x,+y), (+x,+y,+z) exist.
  const int expected[] = {1, 3, 9, 10, 4, 12, 13};
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(s.first[i], 0);
    EXPECT_EQ(s.second(i), expected[i]);
  }
  EXPECT_EQ(s.stiffness(0), kPolymer.edge / 4);  // corner: along an edge line
  EXPECT_EQ(s.stiffness(3), kPolymer.face / 2);  // in the left face
  EXPECT_EQ(s.stiffness(6), kPolymer.body);
  EXPECT_DOUBLE_EQ(s.rest_length(3), std::sqrt(2.0) * kLe);
}

// The original's node-type rules (docs/original-code.md#springs), transcribed from their
// description; they must give the same stiffness as the cell count for boxes >= 3 per axis.
std::set<int> planes_of(std::int8_t code, const GridShape& shape, int node) {
  (void)code;
  const auto c = shape.node_coordinates(node);
  std::set<int> p;
  for (int a = 0; a < 3; ++a) {
    if (c[a] == 0) p.insert(2 * a);
    if (c[a] == shape.nodes[a] - 1) p.insert(2 * a + 1);
  }
  return p;
}
double seed_weight(SpringKind kind, const std::set<int>& a, const std::set<int>& b) {
  const std::size_t na = a.size(), nb = b.size();
  std::set<int> common;
  for (const int x : a) {
    if (b.count(x)) common.insert(x);
  }
  if (kind == SpringKind::body) return 1.0;
  if (kind == SpringKind::edge) {
    if (na == 3 || nb == 3) return 0.25;                           // corner-anything
    if (na == 2 && nb == 2 && a == b) return 0.25;                 // along an edge line
    if (na == 1 && nb == 1 && a == b) return 0.5;                  // same surface
    if ((na == 1 && nb == 2) || (na == 2 && nb == 1)) return 0.5;  // surface-edge
    return 1.0;
  }
  if (na == 3 || nb == 3) return 0.5;            // touches a corner
  if (na == 1 && nb == 1 && a == b) return 0.5;  // same surface
  if (((na == 1 && nb == 2) || (na == 2 && nb == 1)) && !common.empty()) return 0.5;
  if (na == 2 && nb == 2 && !common.empty()) return 0.5;  // edges sharing a face
  return 1.0;
}

TEST(LatticeSprings, CellCountWeightingEqualsTheOriginalsNodeTypeRules) {
  for (const GridShape shape : {GridShape{{3, 3, 3}}, GridShape{{4, 5, 6}}, GridShape{{3, 6, 4}}}) {
    const SpringSet s =
        build_springs(shape, kLe, kPolymer, kParticle, {}, ParticleSpringRule::same_particle);
    const auto codes = node_type_codes(shape);
    for (std::size_t i = 0; i < s.size(); ++i) {
      const double w = seed_weight(s.kind(i), planes_of(codes[s.first[i]], shape, s.first[i]),
                                   planes_of(codes[s.second(i)], shape, s.second(i)));
      ASSERT_DOUBLE_EQ(s.stiffness(i), w * constant_of(kPolymer, s.kind(i)))
          << "spring " << i << " of " << shape.nx() << "x" << shape.ny() << "x" << shape.nz();
    }
  }
}

// docs/original-code.md#springs: the Phi = 1 % two-particle system, 42 x 42 x 83 nodes, has
// 1,825,730 springs = 430,500 edge (656 at k/4, 32,964 at k/2, 391,216 at k, 5,664 particle)
// + 843,862 face (33,620 at k/2, 799,586 at k, 10,656 particle) + 551,368 body (544,544 at k,
// 6,824 particle). Built only if that takes less than 2 s.
TEST(LatticeSprings, CountsOfThePhiOnePercentSystem) {
  LatticeSpec spec;
  mresim::mess::model_profile("seed").apply_to(spec);
  spec.placement = RegularPlacement{0.01, {1, 1, 2}};
  const auto start = std::chrono::steady_clock::now();
  const Lattice lat = build_lattice(spec);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (seconds > 2.0) GTEST_SKIP() << "building took " << seconds << " s";
  RecordProperty("build_seconds", std::to_string(seconds));
  EXPECT_EQ(lat.node_count(), 146412);
  EXPECT_EQ(lat.cell_count(), 137842);
  EXPECT_EQ(lat.springs.size(), 1825730u);
  const Tally t = tally(lat.springs, lat.polymer.springs);
  EXPECT_EQ(t.kind_total(0), 430500);
  EXPECT_EQ(t.quarter[0], 656);
  EXPECT_EQ(t.half[0], 32964);
  EXPECT_EQ(t.full[0], 391216);
  EXPECT_EQ(t.particle[0], 5664);
  EXPECT_EQ(t.kind_total(1), 843862);
  EXPECT_EQ(t.half[1], 33620);
  EXPECT_EQ(t.full[1], 799586);
  EXPECT_EQ(t.particle[1], 10656);
  EXPECT_EQ(t.kind_total(2), 551368);
  EXPECT_EQ(t.full[2], 544544);
  EXPECT_EQ(t.particle[2], 6824);
  // Both rules agree when particles are far apart.
  mresim::mess::model_profile("physical").apply_to(spec);
  const Lattice phys = build_lattice(spec);
  const Tally tp = tally(phys.springs, phys.polymer.springs);
  EXPECT_EQ(tp.particle[0], 5664);
  EXPECT_EQ(tp.particle[1], 10656);
  EXPECT_EQ(tp.particle[2], 6824);
}

// One n_d = 5 particle has 2832 edge, 5328 face and 3412 body springs between its nodes; of
// those, 312 face and 456 body springs lie only in polymer cells (the node-based rule stiffens
// them too, docs/original-code.md#springs), and no edge spring does.
TEST(LatticeSprings, SpringsOfOneParticle) {
  LatticeSpec spec;
  spec.placement = ByHandPlacement{{Eigen::Vector3d(5e-6, 5e-6, 5e-6)},
                                   {Eigen::Vector3d(2.5e-6, 2.5e-6, 2.5e-6)}};
  const Lattice lat = build_lattice(spec);
  ASSERT_EQ(lat.particle_count(), 1u);
  std::set<std::array<int, 3>> voxels;
  for (const auto& v : sphere_voxel_offsets(5)) {
    const auto& c = lat.particle_centre_cells[0];
    voxels.insert({c[0] + v[0], c[1] + v[1], c[2] + v[2]});
  }
  std::int64_t count[3] = {0, 0, 0}, polymer_only[3] = {0, 0, 0};
  const SpringSet& s = lat.springs;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!s.particle(i)) continue;
    const int k = static_cast<int>(s.kind(i));
    ++count[k];
    EXPECT_DOUBLE_EQ(s.stiffness(i), constant_of(lat.particle_springs, s.kind(i)));
    const auto a = lat.shape.node_coordinates(s.first[i]);
    const auto b = lat.shape.node_coordinates(s.second(i));
    // Cells containing the spring: lower corner from min(a, b) along spanned axes, both
    // layers along the others.
    bool any_particle_cell = false;
    for (int dx = -1; dx <= 0; ++dx) {
      for (int dy = -1; dy <= 0; ++dy) {
        for (int dz = -1; dz <= 0; ++dz) {
          const int d[3] = {dx, dy, dz};
          std::array<int, 3> cell{};
          bool valid = true;
          for (int ax = 0; ax < 3; ++ax) {
            if (a[ax] != b[ax]) {
              if (d[ax] != 0) valid = false;
              cell[ax] = std::min(a[ax], b[ax]);
            } else {
              cell[ax] = a[ax] + d[ax];
            }
          }
          if (valid && voxels.count(cell)) any_particle_cell = true;
        }
      }
    }
    if (!any_particle_cell) ++polymer_only[k];
  }
  EXPECT_EQ(count[0], 2832);
  EXPECT_EQ(count[1], 5328);
  EXPECT_EQ(count[2], 3412);
  EXPECT_EQ(polymer_only[0], 0);
  EXPECT_EQ(polymer_only[1], 312);
  EXPECT_EQ(polymer_only[2], 456);
}

// Two particles one voxel layer apart: the original (seed) stiffens springs joining nodes of
// different particles as well, the text (physical) only those within one particle.
TEST(LatticeSprings, ParticleRulesDifferOnlyBetweenNeighbouringParticles) {
  LatticeSpec spec;
  const double l_e = element_length(spec.particle_radius, 5);
  // Centres 12 voxels apart along z: one layer of polymer cells between the spheres' tips.
  spec.placement = ByHandPlacement{{Eigen::Vector3d(20 * l_e, 20 * l_e, 40 * l_e)},
                                   {Eigen::Vector3d(10.5 * l_e, 10.5 * l_e, 13.5 * l_e),
                                    Eigen::Vector3d(10.5 * l_e, 10.5 * l_e, 25.5 * l_e)}};
  mresim::mess::model_profile("physical").apply_to(spec);
  const Lattice phys = build_lattice(spec);
  mresim::mess::model_profile("seed").apply_to(spec);
  const Lattice seed = build_lattice(spec);
  std::int64_t phys_particle = 0, seed_particle = 0, cross = 0;
  for (std::size_t i = 0; i < phys.springs.size(); ++i) {
    phys_particle += phys.springs.particle(i);
    seed_particle += seed.springs.particle(i);
    const auto pa = seed.particle_of_node[seed.springs.first[i]];
    const auto pb = seed.particle_of_node[seed.springs.second(i)];
    if (pa >= 0 && pb >= 0 && pa != pb) ++cross;
  }
  EXPECT_EQ(phys_particle, 2 * (2832 + 5328 + 3412));
  EXPECT_GT(cross, 0);
  EXPECT_EQ(seed_particle, phys_particle + cross);
}

// The one-byte property table gives back every pushed entry bit for bit, shares equal entries,
// and refuses a 257th distinct one; a lattice with a particle needs at most 38 entries.
TEST(LatticeSprings, PropertyTableKeepsEveryValueExactly) {
  SpringProperties table;
  std::vector<SpringProperties::Entry> pushed;
  for (int i = 0; i < 256; ++i) {
    const double k = std::nextafter(1.0 + (i / 2) / 7.0, 2.0);  // not exactly representable sums
    // The same stiffness with two kinds or particle flags: distinct entries.
    const SpringProperties::Entry e{k, 7, i % 2 == 0 ? SpringKind::face : SpringKind::body,
                                    i % 4 < 2};
    table.push_back(e);
    table.push_back(e);
    pushed.push_back(e);
    pushed.push_back(e);
  }
  ASSERT_EQ(table.size(), pushed.size());
  for (std::size_t s = 0; s < pushed.size(); ++s) {
    EXPECT_EQ(table[s].stiffness, pushed[s].stiffness) << s;
    EXPECT_EQ(table[s].index_step, pushed[s].index_step) << s;
    EXPECT_EQ(table[s].kind, pushed[s].kind) << s;
    EXPECT_EQ(table[s].particle, pushed[s].particle) << s;
  }
  EXPECT_EQ(table.table().size(), 256u);
  EXPECT_THROW(table.push_back({3.5, 1, SpringKind::edge, false}), std::length_error);
  table.push_back(pushed[5]);  // a known entry still fits
  EXPECT_EQ(table[table.size() - 1], pushed[5]);

  LatticeSpec spec;
  spec.placement = ByHandPlacement{{Eigen::Vector3d(5e-6, 5e-6, 5e-6)},
                                   {Eigen::Vector3d(2.5e-6, 2.5e-6, 2.5e-6)}};
  const Lattice lat = build_lattice(spec);
  const std::vector<SpringProperties::Entry>& distinct = lat.springs.properties.table();
  EXPECT_LE(distinct.size(), 38u);
  std::set<std::tuple<double, int, int, bool>> seen;
  bool any_particle = false;
  for (std::size_t i = 0; i < lat.springs.size(); ++i) {
    const int step = lat.springs.second(i) - lat.springs.first[i];
    seen.insert({lat.springs.stiffness(i), step, static_cast<int>(lat.springs.kind(i)),
                 lat.springs.particle(i)});
    any_particle = any_particle || lat.springs.particle(i);
  }
  std::set<std::tuple<double, int, int, bool>> listed;
  for (const auto& e : distinct) {
    listed.insert({e.stiffness, e.index_step, static_cast<int>(e.kind), e.particle});
  }
  EXPECT_EQ(seen, listed);
  EXPECT_EQ(seen.size(), distinct.size());  // each entry once in the table
  EXPECT_TRUE(any_particle);
}

}  // namespace
}  // namespace mresim::lattice
