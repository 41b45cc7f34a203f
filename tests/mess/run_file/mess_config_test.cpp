// The 3D run file: the Chapter 4 systems read from run files, with the counts and constants
// `info` reports for them (docs/lattice.md's D1 table), defaults, field and load sequences.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "../../support/dissertation_values.hpp"
#include "../support/mess_run_file.hpp"
#include "mresim/mess/protocols/protocol.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"

namespace {

using mresim::app::InfoReport;
using mresim::config::TableReader;
using mresim::testing::kR;
using mresim::testing::read_spec;
using namespace mresim::mess_config;
namespace lattice = mresim::lattice;

// The protocol's settings (mresim::mess_protocol::settings_of): nullptr for another protocol.
const StrainSpec* strain_of(const MessSpec& s) {
  return mresim::mess_protocol::settings_of<StrainSpec>(s);
}
const StressSpec* stress_of(const MessSpec& s) {
  return mresim::mess_protocol::settings_of<StressSpec>(s);
}

InfoReport info(const MessSpec& spec) {
  InfoReport report;
  describe_mess(spec, report);
  return report;
}

const InfoReport::Entry& entry(const InfoReport& r, const std::string& section,
                               const std::string& key) {
  for (const auto& e : r.entries()) {
    if (e.section == section && e.key == key) return e;
  }
  throw std::logic_error("no [" + section + "] " + key + " in the report");
}
double number(const InfoReport& r, const std::string& section, const std::string& key) {
  return std::get<double>(entry(r, section, key).value);
}
std::int64_t integer(const InfoReport& r, const std::string& section, const std::string& key) {
  return std::get<std::int64_t>(entry(r, section, key).value);
}
std::string text(const InfoReport& r, const std::string& section, const std::string& key) {
  return std::get<std::string>(entry(r, section, key).value);
}

// A two-particle regular system at volume fraction phi, as in Figs. 4.3-4.9.
std::string regular_two(double phi, const std::string& extra_model = "") {
  return "[run]\ntype = \"mess_hysteresis\"\n[model]\n" + extra_model +
         "\n[particles]\nplacement = \"regular\"\nvolume_fraction = " + std::to_string(phi) +
         "\ncount_per_axis = [1, 1, 2]\n[field]\nmax = 0.06\nsteps = 12\n";
}

constexpr double kLe = kR / 5.5;

// Phi = 1 %, two particles along z: docs/original-code.md#springs lists every spring category.
TEST(MessConfigSystems, OnePercentTwoParticles) {
  for (const std::string profile : {"physical", "seed"}) {
    SCOPED_TRACE(profile);
    const MessSpec spec = read_spec(regular_two(0.01, "profile = \"" + profile + "\""));
    const InfoReport r = info(spec);
    EXPECT_EQ(text(r, "lattice", "grid"), "42 x 42 x 83");
    EXPECT_EQ(integer(r, "lattice", "nodes"), 146412);
    EXPECT_EQ(integer(r, "lattice", "cells"), 137842);
    EXPECT_EQ(integer(r, "lattice", "springs"), 1825730);
    EXPECT_EQ(integer(r, "lattice", "edge_springs"), 430500);
    EXPECT_EQ(integer(r, "lattice", "face_springs"), 843862);
    EXPECT_EQ(integer(r, "lattice", "body_springs"), 551368);
    EXPECT_EQ(entry(r, "lattice", "edge_springs").note,
              "656 at k_e/4, 32,964 at k_e/2, 5,664 with the particle constant");
    EXPECT_EQ(entry(r, "lattice", "face_springs").note,
              "33,620 at k_f/2, 10,656 with the particle constant");
    EXPECT_EQ(entry(r, "lattice", "body_springs").note, "6,824 with the particle constant");
    EXPECT_EQ(integer(r, "lattice", "particle_springs"), 5664 + 10656 + 6824);
    EXPECT_NEAR(number(r, "lattice", "element_length"), kLe, 1e-20);
    EXPECT_EQ(integer(r, "particles", "count"), 2);
    EXPECT_EQ(integer(r, "particles", "nodes_per_particle"), 1064);
    // The dissertation's separation for 1 %: 11.1818 um = 41 l_e, along z.
    EXPECT_NEAR(number(r, "particles", "closest_centre_distance"), 41 * kLe, 1e-15);
    EXPECT_NEAR(spec.geometry.particle_centres[1][2] - spec.geometry.particle_centres[0][2],
                11.1818e-6, 1e-10);
    const double volume = 41.0 * 41.0 * 82.0 * std::pow(kLe, 3);
    EXPECT_NEAR(number(r, "particles", "volume_fraction"),
                2.0 * 4.0 / 3.0 * std::numbers::pi * std::pow(kR, 3) / volume, 1e-15);
    EXPECT_DOUBLE_EQ(number(r, "particles", "requested_volume_fraction"), 0.01);
    EXPECT_EQ(integer(r, "field", "fields"), 61);  // 0..60 mT in 5 mT, as a loop
    EXPECT_EQ(integer(r, "mess", "relaxations"), 61);
  }
}

struct D1 {
  double phi;
  std::string grid;
  std::int64_t nodes;
  std::int64_t cells;
};

class MessConfigVolumeFraction : public ::testing::TestWithParam<D1> {};

TEST_P(MessConfigVolumeFraction, NodeAndCellCountsOfTheDissertation) {
  const InfoReport r = info(read_spec(regular_two(GetParam().phi)));
  EXPECT_EQ(text(r, "lattice", "grid"), GetParam().grid);
  EXPECT_EQ(integer(r, "lattice", "nodes"), GetParam().nodes);
  EXPECT_EQ(integer(r, "lattice", "cells"), GetParam().cells);
}

INSTANTIATE_TEST_SUITE_P(MessConfigChapter4, MessConfigVolumeFraction,
                         ::testing::Values(D1{0.01, "42 x 42 x 83", 146412, 137842},
                                           D1{0.03, "30 x 30 x 58", 52200, 47937},
                                           D1{0.04, "27 x 27 x 53", 38637, 35152},
                                           D1{0.05, "25 x 25 x 49", 30625, 27648},
                                           D1{0.06, "24 x 24 x 46", 26496, 23805},
                                           D1{0.07, "23 x 23 x 44", 23276, 20812}),
                         [](const auto& i) {
                           return "Phi" + std::to_string(std::lround(i.param.phi * 100));
                         });

const std::string kLargeBoxChain = R"(
[run]
type = "mess_strain"
[model]
profile = "seed"
[particles]
placement = "chain"
count = 2
separation = 6.5454e-6
[box]
size = [12e-6, 12e-6, 40e-6]
[field]
magnitudes = [0.0, 0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.1, 0.12, 0.14]
[strain]
kind = "shear"
normal = "z"
direction = "x"
max = 0.1
steps = 10
)";

// Figs. 4.10-4.13: two particles 6.5454 um apart in a 12 x 12 x 40 um box; the seed profile
// sizes by-hand boxes as the original did (44 x 44 x 147, Phi 0.516 %). The strain protocol
// of Listing A.2: 12 fields x 11 strains.
TEST(MessConfigSystems, TwoParticlesInTheLargeBox) {
  const MessSpec spec = read_spec(kLargeBoxChain);
  const InfoReport r = info(spec);
  EXPECT_EQ(text(r, "lattice", "grid"), "44 x 44 x 147");
  EXPECT_EQ(integer(r, "lattice", "nodes"), 284592);
  EXPECT_EQ(integer(r, "lattice", "cells"), 269954);
  EXPECT_EQ(text(r, "lattice", "box_rounding"), "seed_floor_divide");
  EXPECT_NEAR(number(r, "particles", "volume_fraction"), 0.00516, 0.000005);
  EXPECT_NEAR(number(r, "particles", "closest_centre_distance"), 24 * kLe, 1e-15);
  EXPECT_EQ(integer(r, "field", "fields"), 12);
  EXPECT_EQ(text(r, "field", "sequence"), "up");
  EXPECT_EQ(integer(r, "strain", "values"), 11);
  EXPECT_EQ(integer(r, "mess", "relaxations"), 132);
  ASSERT_TRUE(strain_of(spec));
  EXPECT_EQ(strain_of(spec)->kind, LoadKind::shear);
  EXPECT_EQ(strain_of(spec)->normal, 2);
  EXPECT_EQ(strain_of(spec)->direction, 0);
  EXPECT_EQ(strain_of(spec)->boundary, ShearBoundary::all_faces);
  EXPECT_NEAR(strain_of(spec)->values[3], 0.03, 1e-15);

  // The physical profile rounds to the nearest node count (12 um = 44 l_e exactly).
  std::string physical = kLargeBoxChain;
  physical.replace(physical.find("profile = \"seed\""), 16, "profile = \"physical\"");
  EXPECT_EQ(text(info(read_spec(physical)), "lattice", "grid"), "45 x 45 x 148");
  // ... unless told otherwise.
  physical.replace(physical.find("[box]"), 5, "[box]\nrounding = \"seed_floor_divide\"");
  EXPECT_EQ(text(info(read_spec(physical)), "lattice", "grid"), "44 x 44 x 147");
}

// Fig. 4.20: four particles 6 um apart in the same box, Phi ~ 1 %.
TEST(MessConfigSystems, FourParticleChain) {
  std::string text_ = kLargeBoxChain;
  text_.replace(text_.find("count = 2\nseparation = 6.5454e-6"), 32,
                "count = 4\nseparation = 6e-6");
  const MessSpec spec = read_spec(text_);
  const InfoReport r = info(spec);
  EXPECT_EQ(integer(r, "lattice", "nodes"), 284592);
  EXPECT_EQ(integer(r, "particles", "count"), 4);
  EXPECT_NEAR(number(r, "particles", "volume_fraction"), 0.0103, 0.0001);
  EXPECT_NEAR(number(r, "particles", "closest_centre_distance"), 6e-6, 1e-12);
}

// Section 4.3.3 / Listing A.2: the 8-particle helix, R_helix = 3.5 um, in 18 x 18 x 62 um
// (66 x 66 x 228 nodes). `info` must stay fast: no lattice is built.
TEST(MessConfigSystems, Helix) {
  const MessSpec spec = read_spec(R"(
[run]
type = "mess_strain"
[model]
profile = "seed"
[particles]
placement = "helix"
helix_radius = 3.5e-6
[box]
size = [18e-6, 18e-6, 62e-6]
[field]
magnitudes = [0.0, 0.01, 0.02]
theta = 90
[strain]
kind = "shear"
direction = "x"
values = [0.0, 0.01, 0.02]
[solver]
method = "leapfrog"
[solver.leapfrog]
dt = 4e-3
)");
  const InfoReport r = info(spec);
  EXPECT_EQ(text(r, "lattice", "grid"), "66 x 66 x 228");
  EXPECT_EQ(integer(r, "lattice", "nodes"), 993168);
  EXPECT_EQ(integer(r, "lattice", "cells"), 959075);
  EXPECT_EQ(integer(r, "particles", "count"), 8);
  // Appendix A: particle 0 at (9 + 3.5, 9, 13.5) um, snapped to its cell's centre.
  const Eigen::Vector3d& x0 = spec.geometry.particle_centres[0];
  EXPECT_NEAR(x0[0], (std::floor(12.5e-6 / kLe) + 0.5) * kLe, 1e-18);
  EXPECT_NEAR(x0[2], (std::floor(13.5e-6 / kLe) + 0.5) * kLe, 1e-18);
  EXPECT_NEAR(number(r, "particles", "volume_fraction"), 0.0058, 0.0001);
  // Field along +x.
  EXPECT_NEAR(spec.field.values[2][0], 0.02, 1e-15);
  EXPECT_NEAR(spec.field.values[2][2], 0.0, 1e-15);
  EXPECT_EQ(spec.solver.method, SolverMethod::leapfrog);
  EXPECT_DOUBLE_EQ(spec.solver.leapfrog.dt, 4e-3);
  EXPECT_EQ(spec.solver.leapfrog.steps_per_round, 5000);
}

// docs/lattice.md's table for E = 9 kPa, nu = 0.47, A = 1, and the scales of
// docs/original-code.md#lengths-spring-constants-and-scaling (k_eff, t_c) from the seed's closed
// forms.
TEST(MessConfigSystems, StiffnessAndScalesOfBothProfiles) {
  const InfoReport physical = info(read_spec(regular_two(0.05)));
  EXPECT_NEAR(number(physical, "stiffness", "k_e"), 1.3120e-3, 1e-7);
  EXPECT_NEAR(number(physical, "stiffness", "k_f"), 3.5781e-4, 1e-8);
  EXPECT_NEAR(number(physical, "stiffness", "k_c"), 3.5781e-4, 1e-8);
  EXPECT_NEAR(number(physical, "stiffness", "kappa"), 44898, 1);
  EXPECT_NEAR(number(physical, "stiffness", "lattice_shear_modulus"), 9e3 / (2 * 1.47), 1e-6);
  EXPECT_NEAR(number(physical, "stiffness", "lattice_youngs_modulus"), 9e3, 1e-6);
  EXPECT_NEAR(number(physical, "stiffness", "lattice_poisson_ratio"), 0.47, 1e-12);

  const InfoReport seed = info(read_spec(regular_two(0.05, "profile = \"seed\"")));
  const double E = 9e3;
  const double k_e = 22.0 / 35.0 * E * kLe;
  const double k_c = 6.0 / 35.0 * E * kLe;
  EXPECT_NEAR(number(seed, "stiffness", "k_e"), k_e, 1e-15);
  EXPECT_NEAR(number(seed, "stiffness", "k_f"), k_c, 1e-15);
  EXPECT_NEAR(number(seed, "stiffness", "k_c"), k_c, 1e-15);
  EXPECT_NEAR(number(seed, "stiffness", "kappa"), 44898, 1);
  EXPECT_NEAR(number(seed, "stiffness", "lattice_shear_modulus"), 3600.0, 1e-9);
  EXPECT_NEAR(number(seed, "stiffness", "particle_k_e"), 1e4 * k_e, 1e-9);

  const double m_c = 965.0 * std::pow(kLe, 3);
  const double k_eff = 2 * k_e + 8 * k_c / std::sqrt(2.0) + 4 * k_c;
  EXPECT_NEAR(number(seed, "scales", "mass"), m_c, 1e-30);
  EXPECT_NEAR(number(seed, "scales", "k_eff"), k_eff, 1e-15);
  EXPECT_NEAR(number(seed, "scales", "time"), 2 * std::numbers::pi * std::sqrt(m_c / k_eff), 1e-20);
  EXPECT_NEAR(number(seed, "scales", "time"), 3.288e-7, 0.001e-7);
  // rho_iron V_p / 1064 nodes = 1.044e-16 kg (docs/original-code.md#particles).
  EXPECT_NEAR(number(seed, "scales", "particle_node_mass"), 1.044e-16, 0.001e-16);
}

// A minimal file: every default of docs/run-files-3d.md.
TEST(MessConfigSystems, Defaults) {
  const MessSpec s = read_spec(regular_two(0.05));
  EXPECT_EQ(s.run_type, "mess_hysteresis");
  EXPECT_EQ(s.profile->name, "physical");
  EXPECT_EQ(s.lattice.youngs_modulus, 9e3);
  EXPECT_EQ(s.lattice.poisson_ratio, 0.47);
  EXPECT_EQ(s.lattice.stiffness_ratio, 1.0);
  EXPECT_EQ(s.lattice.discretization_order, 5);
  EXPECT_EQ(s.lattice.polymer_density, 965.0);
  EXPECT_EQ(s.lattice.iron_density, 7860.0);
  EXPECT_EQ(s.lattice.particle_radius, 1.5e-6);
  EXPECT_EQ(s.particles.radius, 1.5e-6);
  EXPECT_EQ(s.particles.Ms, 1.6e6);
  EXPECT_EQ(s.particles.chi0, 70.0);
  EXPECT_FALSE(s.demagnetization);
  EXPECT_EQ(s.self_energy, mresim::magnetism::SelfEnergyForm::consistent);
  EXPECT_EQ(s.placement_kind, lattice::PlacementKind::regular);
  EXPECT_FALSE(s.box);
  EXPECT_EQ(s.field.theta_deg, 0.0);
  EXPECT_EQ(s.field.phi_deg, 0.0);
  EXPECT_EQ(s.field.sequence, FieldSequence::loop);
  EXPECT_EQ(s.solver.method, SolverMethod::minimiser);
  EXPECT_EQ(s.solver.minimiser.force_tolerance, 1e-6);
  // M solved tightly by default, for every profile (docs/magnetization-3d.md).
  EXPECT_EQ(s.solver.magnetization.atol, 1e-12);
  EXPECT_EQ(s.solver.magnetization.rtol, 1e-12);
  EXPECT_EQ(s.solver.magnetization.max_fixed_point_iterations, 60);
  EXPECT_FALSE(s.solver.magnetization.demagnetization);
  EXPECT_EQ(s.solver.leapfrog.dt, 5e-3);
  EXPECT_EQ(s.solver.leapfrog.steps_per_round, 5000);
  EXPECT_EQ(s.solver.leapfrog.max_rounds, 40);
  EXPECT_EQ(s.solver.leapfrog.drag, 1.0);
  EXPECT_FALSE(s.output.node_positions);
  EXPECT_EQ(s.output.checkpoint_every, 1);
  EXPECT_FALSE(strain_of(s));
  EXPECT_FALSE(stress_of(s));
  // The spec builds the lattice it describes.
  const lattice::Lattice lat = lattice::build_lattice(s.lattice);
  EXPECT_EQ(lat.node_count(), s.geometry.node_count());
  EXPECT_EQ(static_cast<std::int64_t>(lat.springs.size()), s.geometry.springs.total());
  std::int64_t stiff = 0;
  for (std::size_t i = 0; i < lat.springs.size(); ++i) stiff += lat.springs.particle(i) ? 1 : 0;
  EXPECT_EQ(stiff, s.geometry.particle_springs.total());
  ASSERT_EQ(lat.particle_centres.size(), 2u);
  EXPECT_NEAR((lat.particle_centres[1] - s.geometry.particle_centres[1]).norm(), 0.0, 1e-18);
}

// [solver.magnetization] tolerance: "tight" by default with either profile, "original" the
// original code's loose band; explicit atol and rtol override the named tolerance.
TEST(MessConfigSystems, MagnetizationTolerance) {
  const std::string seed = regular_two(0.05, "profile = \"seed\"");
  const MessSpec tight = read_spec(seed);
  EXPECT_EQ(tight.solver.magnetization.atol, 1e-12);
  EXPECT_EQ(tight.solver.magnetization.rtol, 1e-12);
  EXPECT_EQ(text(info(tight), "solver", "magnetization_tolerance"), "tight");

  const MessSpec original = read_spec(seed + "[solver.magnetization]\ntolerance = \"original\"\n");
  EXPECT_EQ(original.solver.magnetization.atol, 1e-3);
  EXPECT_EQ(original.solver.magnetization.rtol, 5e-3);
  EXPECT_EQ(number(info(original), "solver", "magnetization_atol"), 1e-3);
  EXPECT_EQ(text(info(original), "solver", "magnetization_tolerance"), "original");

  const MessSpec mixed = read_spec(
      regular_two(0.05) + "[solver.magnetization]\ntolerance = \"original\"\natol = 1e-6\n");
  EXPECT_EQ(mixed.solver.magnetization.atol, 1e-6);
  EXPECT_EQ(mixed.solver.magnetization.rtol, 5e-3);
  EXPECT_EQ(text(info(mixed), "solver", "magnetization_tolerance"), "custom");

  const MessSpec named_tight =
      read_spec(regular_two(0.05) + "[solver.magnetization]\ntolerance = \"tight\"\nrtol = 0\n");
  EXPECT_EQ(named_tight.solver.magnetization.atol, 1e-12);
  EXPECT_EQ(named_tight.solver.magnetization.rtol, 0.0);
}

// The loop of docs/original-code.md#field-sequences: 0 -> max -> -max -> max, 5 n + 1 fields.
TEST(MessConfigField, HysteresisLoopAndDirections) {
  const std::vector<double> loop = hysteresis_loop({0.0, 1.0, 2.0});
  EXPECT_EQ(loop, (std::vector<double>{0, 1, 2, 1, 0, -1, -2, -1, 0, 1, 2}));
  const MessSpec s = read_spec(regular_two(0.05));
  ASSERT_EQ(s.field.values.size(), 61u);
  EXPECT_NEAR(s.field.values[12][2], 0.06, 1e-15);
  EXPECT_NEAR(s.field.values[36][2], -0.06, 1e-15);
  EXPECT_EQ(s.field.values[24], Eigen::Vector3d::Zero());
  EXPECT_EQ(s.field.values[48], Eigen::Vector3d::Zero());
  EXPECT_NEAR(s.field.values[60][2], 0.06, 1e-15);

  // Exact along the axes (no 6e-17 components).
  EXPECT_EQ(field_vector(2.0, 90.0, 90.0), Eigen::Vector3d(0.0, 2.0, 0.0));
  EXPECT_EQ(field_vector(2.0, 90.0, -180.0), Eigen::Vector3d(-2.0, 0.0, 0.0));
  EXPECT_EQ(field_vector(2.0, 180.0, 0.0), Eigen::Vector3d(0.0, 0.0, -2.0));
  const Eigen::Vector3d b = field_vector(1.0, 45.0, 30.0);
  EXPECT_NEAR(b[0], std::sqrt(0.5) * std::sqrt(0.75), 1e-15);
  EXPECT_NEAR(b[1], std::sqrt(0.5) * 0.5, 1e-15);
  EXPECT_NEAR(b[2], std::sqrt(0.5), 1e-15);

  std::string vectors = regular_two(0.05);
  vectors.replace(vectors.find("max = 0.06\nsteps = 12"), 21,
                  "values = [[0, 0, 0], [0.01, 0, 0.02], [0, -0.03, 0]]");
  const MessSpec v = read_spec(vectors);
  ASSERT_EQ(v.field.values.size(), 3u);
  EXPECT_EQ(v.field.values[1], Eigen::Vector3d(0.01, 0, 0.02));
  EXPECT_NEAR(v.field.max, 0.03, 1e-15);

  std::string up = regular_two(0.05);
  up.replace(up.find("steps = 12"), 10, "steps = 12\nsequence = \"up\"");
  EXPECT_EQ(read_spec(up).field.values.size(), 13u);
}

TEST(MessConfigPlacement, AnisotropicAliasNoiseAndByHand) {
  const std::string aniso = R"(
[run]
type = "mess_magnetostriction"
[particles]
placement = "anisotropic_regular_noisy"
volume_fraction = 0.01
count_per_axis = [2, 2, 2]
anisotropy_factor = 1.5
noise_seed = 7
[field]
max = 0.1
steps = 2
)";
  const MessSpec a = read_spec(aniso);
  EXPECT_EQ(a.placement_kind, lattice::PlacementKind::regular_anisotropic_noisy);
  const auto& r = std::get<lattice::RegularPlacement>(a.lattice.placement);
  EXPECT_TRUE(r.anisotropic);
  EXPECT_TRUE(r.noisy);
  EXPECT_EQ(r.noise_seed, 7u);
  EXPECT_NEAR(r.anisotropy_factor[0], 1 / std::sqrt(1.5), 1e-15);
  EXPECT_NEAR(r.anisotropy_factor[2], 1.5, 1e-15);
  EXPECT_EQ(a.geometry.particle_count(), 8u);
  EXPECT_EQ(a.field.sequence, FieldSequence::up);
  EXPECT_EQ(a.field.values.size(), 3u);
  // The same seed gives the same centres; the explicit factors give the same box.
  EXPECT_EQ(read_spec(aniso).geometry.centre_cells, a.geometry.centre_cells);
  std::string explicit_factors = aniso;
  explicit_factors.replace(explicit_factors.find("anisotropy_factor = 1.5"), 23,
                           "anisotropy_factor = [0.8164965809277261, 0.8164965809277261, 1.5]");
  EXPECT_EQ(read_spec(explicit_factors).geometry.shape.nodes, a.geometry.shape.nodes);

  const MessSpec h = read_spec(R"(
[run]
type = "mess_hysteresis"
[particles]
placement = "by_hand"
positions = [[6e-6, 6e-6, 5e-6], [6e-6, 6e-6, 11e-6]]
[box]
size = [12e-6, 12e-6, 16e-6]
[field]
max = 0.05
steps = 5
)");
  ASSERT_EQ(h.geometry.particle_count(), 2u);
  EXPECT_EQ(h.geometry.centre_cells[0][2], static_cast<int>(std::floor(5e-6 / kLe)));
  EXPECT_EQ(h.box->rounding, lattice::BoxRounding::nearest);
  EXPECT_EQ(h.geometry.shape.nodes, (std::array<int, 3>{45, 45, 60}));
}

TEST(MessConfigLoads, TensionCompressionTorsionAndStress) {
  const std::string base = R"(
[run]
type = "TYPE"
[particles]
placement = "regular"
volume_fraction = 0.05
count_per_axis = [1, 1, 2]
[field]
magnitudes = [0.0, 0.05]
)";
  const auto with_type = [&](const std::string& type, const std::string& table) {
    std::string t = base;
    t.replace(t.find("TYPE"), 4, type);
    return read_spec(t + table);
  };
  const MessSpec c = with_type("mess_strain",
                               "[strain]\nkind = \"compression\"\nnormal = \"x\"\nmax = 0.1\n"
                               "steps = 4\n");
  EXPECT_EQ(strain_of(c)->kind, LoadKind::compression);
  EXPECT_EQ(strain_of(c)->normal, 0);
  EXPECT_EQ(strain_of(c)->direction, 0);
  ASSERT_EQ(strain_of(c)->values.size(), 5u);
  EXPECT_NEAR(strain_of(c)->values[4], -0.1, 1e-15);
  EXPECT_EQ(c.relaxation_count(), 10u);

  const MessSpec t =
      with_type("mess_strain", "[strain]\nkind = \"torsion\"\nvalues = [0, 5, -5]\n");
  EXPECT_NEAR(strain_of(t)->values[1], 5 * std::numbers::pi / 180, 1e-15);
  EXPECT_NEAR(strain_of(t)->values[2], -5 * std::numbers::pi / 180, 1e-15);
  EXPECT_EQ(strain_of(t)->normal, 2);

  const MessSpec s = with_type("mess_stress",
                               "[stress]\nkind = \"shear\"\nnormal = \"z\"\ndirection = \"y\"\n"
                               "loading = \"both_faces\"\nmax = 100\nsteps = 2\n");
  EXPECT_EQ(stress_of(s)->kind, LoadKind::shear);
  EXPECT_EQ(stress_of(s)->direction, 1);
  EXPECT_EQ(stress_of(s)->loading, StressLoading::both_faces);
  EXPECT_EQ(stress_of(s)->values, (std::vector<double>{0.0, 50.0, 100.0}));
  const InfoReport r = info(s);
  EXPECT_EQ(integer(r, "stress", "values"), 3);
  EXPECT_EQ(integer(r, "mess", "relaxations"), 6);
  EXPECT_NEAR(number(r, "stress", "loaded_face_area"),
              s.geometry.box_lengths[0] * s.geometry.box_lengths[1], 1e-24);
}

TEST(MessConfigReport, TextOfTheReportNamesTheCounts) {
  const std::string out = info(read_spec(regular_two(0.01))).to_text();
  EXPECT_NE(out.find("nodes"), std::string::npos);
  EXPECT_NE(out.find("146412"), std::string::npos);
  EXPECT_NE(out.find("centre_1"), std::string::npos);
}

TEST(MessConfigReport, OnlyMessRunTypes) {
  const TableReader root = TableReader::parse_string(regular_two(0.05), "run.toml");
  EXPECT_THROW((void)read_mess_spec(root, "pair_hysteresis"), std::invalid_argument);
  // The registered protocols (a test-only one, tests/mess/protocols, may be among them).
  const std::vector<std::string> names = mess_run_type_names();
  for (const char* n : {"mess_hysteresis", "mess_magnetostriction", "mess_strain", "mess_stress"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
  }
}

}  // namespace
