// Invalid 3D run files: each gives one line naming the key, the value and what is allowed.
#include <gtest/gtest.h>

#include <string>

#include "../../support/run_file_edits.hpp"
#include "../support/mess_run_file.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"

namespace {

using mresim::testing::BadInput;
using mresim::testing::edit;
using mresim::testing::spec_error_of;

const std::string kValid = R"(
[run]
type = "mess_hysteresis"
[model]
profile = "physical"
youngs_modulus = 9e3
poisson_ratio = 0.47
discretization_order = 5
[particles]
placement = "regular"
volume_fraction = 0.05
count_per_axis = [1, 1, 2]
[field]
max = 0.06
steps = 12
)";

const std::string kByHand = R"(
[run]
type = "mess_hysteresis"
[particles]
placement = "by_hand"
positions = [[6e-6, 6e-6, 5e-6], [6e-6, 6e-6, 11e-6]]
[box]
size = [12e-6, 12e-6, 16e-6]
[field]
max = 0.06
steps = 12
)";

const std::string kStrain = R"(
[run]
type = "mess_strain"
[particles]
placement = "regular"
volume_fraction = 0.05
count_per_axis = [1, 1, 2]
[field]
magnitudes = [0.0, 0.05]
[strain]
kind = "shear"
normal = "z"
direction = "x"
max = 0.1
steps = 10
)";

// The valid file with the first occurrence of `from` replaced by `to`.
std::string with(const std::string& from, const std::string& to) { return edit(kValid, from, to); }

TEST(MessConfigRunFile, ValidFilesAreAccepted) {
  EXPECT_EQ(spec_error_of(kValid), "(no error)");
  EXPECT_EQ(spec_error_of(kByHand), "(no error)");
  EXPECT_EQ(spec_error_of(kStrain), "(no error)");
}

class MessConfigErrors : public ::testing::TestWithParam<BadInput> {};

TEST_P(MessConfigErrors, NameTheKeyTheValueAndWhatIsAllowed) {
  EXPECT_EQ(spec_error_of(GetParam().text), GetParam().message);
}

INSTANTIATE_TEST_SUITE_P(
    MessConfig, MessConfigErrors,
    ::testing::Values(
        BadInput{"NegativeYoungsModulus", with("youngs_modulus = 9e3", "youngs_modulus = -9e3"),
                 "model.youngs_modulus = -9000.0: must be > 0 (Pa)"},
        BadInput{"PoissonRatioOneHalf", with("poisson_ratio = 0.47", "poisson_ratio = 0.5"),
                 "model.poisson_ratio = 0.5: must be in (-1, 0.5)"},
        BadInput{"PoissonRatioBelowMinusOne", with("poisson_ratio = 0.47", "poisson_ratio = -1.2"),
                 "model.poisson_ratio = -1.2: must be in (-1, 0.5)"},
        BadInput{
            "SeedProfileUnstablePoissonRatio",
            edit(with("poisson_ratio = 0.47", "poisson_ratio = -0.2"), "\"physical\"", "\"seed\""),
            "model.poisson_ratio = -0.2: must be > -0.1124 with profile = \"seed\": below it "
            "the seed lattice's bulk modulus kappa + 2E/3 is not positive (unstable); use "
            "profile = \"physical\""},
        BadInput{"ZeroDiscretizationOrder",
                 with("discretization_order = 5", "discretization_order = 0"),
                 "model.discretization_order = 0: must be in [1, 1000]"},
        BadInput{"BadProfile", with("profile = \"physical\"", "profile = \"exact\""),
                 "model.profile = \"exact\": must be one of physical, seed"},
        BadInput{"UnknownPlacement", with("placement = \"regular\"", "placement = \"random\""),
                 "particles.placement = \"random\": must be one of regular, regular_noisy, "
                 "regular_anisotropic, regular_anisotropic_noisy, anisotropic_regular, "
                 "anisotropic_regular_noisy, by_hand, chain, helix, none"},
        BadInput{"UnknownKey", with("steps = 12", "steps = 12\nstpes = 13"),
                 "unknown key 'field.stpes' in [field]; allowed keys: magnitudes, max, phi, "
                 "sequence, steps, theta, values"},
        BadInput{"WrongType", with("youngs_modulus = 9e3", "youngs_modulus = \"soft\""),
                 "model.youngs_modulus = \"soft\": expected a number (Pa)"},
        BadInput{"ZeroFieldSteps", with("steps = 12", "steps = 0"),
                 "field.steps = 0: must be in [1, 100000]"},
        BadInput{"NegativeFieldMax", with("max = 0.06", "max = -0.06"),
                 "field.max = -0.06: must be > 0 (T)"},
        BadInput{"FieldMaxWithoutSteps", with("steps = 12", ""),
                 "field.steps = (missing): field.max needs field.steps, the number of increments "
                 "from 0 to max (integer >= 1)"},
        BadInput{"TwoFieldForms", with("steps = 12", "steps = 12\nvalues = [[0, 0, 0.1]]"),
                 "field.values = [[0, 0, 0.1]]: give one of field.max and field.steps, "
                 "field.magnitudes or field.values (also given: field.max)"},
        BadInput{"FieldVectorWithTwoComponents",
                 with("max = 0.06\nsteps = 12", "values = [[0, 0, 0], [0.1, 0]]"),
                 "field.values[1] = [0.1, 0]: expected [x, y, z] (T)"},
        BadInput{"LoopMagnitudesNotRising",
                 with("max = 0.06\nsteps = 12", "magnitudes = [0.0, 0.06, 0.03]"),
                 "field.magnitudes = [0.0, 0.06, 0.03]: with field.sequence = \"loop\" the list "
                 "must start at 0 and increase strictly (it is the rising branch 0 -> max of the "
                 "loop)"},
        BadInput{"FieldAngleOutOfRange", with("steps = 12", "steps = 12\ntheta = 200"),
                 "field.theta = 200: must be in [0, 180] (deg)"},
        BadInput{"OverlappingByHandParticles",
                 edit(kByHand, "[6e-6, 6e-6, 11e-6]", "[6e-6, 6e-6, 7e-6]"),
                 "particles.positions[1] = [6e-06, 6e-06, 7e-06]: particles 0 and 1 overlap: "
                 "centred at (6.13636e-06, 6.13636e-06, 5.04545e-06) m and (6.13636e-06, "
                 "6.13636e-06, 6.95455e-06) m (1.90909e-06 m apart), their voxelized spheres "
                 "share nodes; centres must be far enough apart that at least one layer of "
                 "polymer nodes separates them"},
        BadInput{"ByHandParticleOutsideTheBox",
                 edit(kByHand, "[6e-6, 6e-6, 11e-6]", "[6e-6, 6e-6, 17e-6]"),
                 "particles.positions[1] = [6e-06, 6e-06, 1.7e-05]: particle 1 at (6e-06, 6e-06, "
                 "1.7e-05) m is outside the box [0, 1.2e-05] x [0, 1.2e-05] x [0, 1.60909e-05] m"},
        BadInput{"ByHandParticleTouchingTheBoxFace",
                 edit(kByHand, "[6e-6, 6e-6, 11e-6]", "[6e-6, 6e-6, 15e-6]"),
                 "particles.positions[1] = [6e-06, 6e-06, 1.5e-05]: particle 1 centred at "
                 "(6.13636e-06, 6.13636e-06, 1.51364e-05) m is outside the box or touches its "
                 "outer faces: along z it spans [1.36364e-05, 1.66364e-05] m, but particle nodes "
                 "must lie strictly inside (0, 1.60909e-05) m"},
        BadInput{
            "VolumeFractionTooHigh", with("volume_fraction = 0.05", "volume_fraction = 0.45"),
            "particles.volume_fraction = 0.45: particle 0 centred at (1.77273e-06, 1.77273e-06, "
            "1.77273e-06) m is outside the box or touches its outer faces: along x it spans "
            "[2.72727e-07, 3.27273e-06] m, but particle nodes must lie strictly inside (0, "
            "3.27273e-06) m (the particles do not fit at this volume fraction and "
            "discretization order)"},
        BadInput{
            "NoiseMovesAParticleOutOfTheBox",
            edit(edit(with("volume_fraction = 0.05", "volume_fraction = 0.357\nnoise_seed = 1"),
                      "[1, 1, 2]", "[2, 2, 2]"),
                 "\"regular\"", "\"regular_noisy\""),
            "particles.noise_seed = 1: particle 0 centred at (1.5e-06, 1.5e-06, 1.77273e-06) m is "
            "outside the box or touches its outer faces: along x it spans [0, 3e-06] m, but "
            "particle nodes must lie strictly inside (0, 6.81818e-06) m (after the noise; try "
            "another noise_seed)"},
        BadInput{
            "ChainParticlesOverlap",
            edit(edit(kByHand, "placement = \"by_hand\"", "placement = \"chain\""),
                 "positions = [[6e-6, 6e-6, 5e-6], [6e-6, 6e-6, 11e-6]]", "separation = 2e-6"),
            "particles.separation = 2e-06: particles 0 and 1 overlap: centred at (6.13636e-06, "
            "6.13636e-06, 6.95455e-06) m and (6.13636e-06, 6.13636e-06, 9.13636e-06) m "
            "(2.18182e-06 m apart), their voxelized spheres share nodes; centres must be far "
            "enough apart that at least one layer of polymer nodes separates them"},
        BadInput{"HelixTooWideForTheBox",
                 edit(edit(kByHand, "placement = \"by_hand\"", "placement = \"helix\""),
                      "positions = [[6e-6, 6e-6, 5e-6], [6e-6, 6e-6, 11e-6]]",
                      "helix_radius = 5e-6\ncount = 2"),
                 "particles.helix_radius = 5e-06: particle 0 centred at (1.10455e-05, 6.13636e-06, "
                 "5.59091e-06) m is outside the box or touches its outer faces: along x it spans "
                 "[9.54545e-06, 1.25455e-05] m, but particle nodes must lie strictly inside (0, "
                 "1.2e-05) m"},
        BadInput{"ByHandWithoutBox", edit(kByHand, "[box]\nsize = [12e-6, 12e-6, 16e-6]\n", ""),
                 "missing table [box]"},
        BadInput{"BoxWithRegularPlacement", kValid + "[box]\nsize = [1e-5, 1e-5, 1e-5]\n",
                 "box = {...}: placement = \"regular\" sizes the box from "
                 "particles.volume_fraction (eqs. 4.50-4.52); [box] is only read with placement "
                 "= \"by_hand\", \"none\", \"chain\" or \"helix\""},
        BadInput{
            "KeyOfAnotherPlacement",
            with("count_per_axis = [1, 1, 2]", "count_per_axis = [1, 1, 2]\nseparation = 6e-6"),
            "particles.separation = 6e-06: not used by placement = \"regular\" (only by "
            "chain)"},
        BadInput{"NoisyWithoutSeed", with("\"regular\"", "\"regular_noisy\""),
                 "missing key 'particles.noise_seed'"},
        BadInput{"CountPerAxisNotIntegers",
                 with("count_per_axis = [1, 1, 2]", "count_per_axis = [1, 1, 2.0]"),
                 "particles.count_per_axis[2] = 2.0: expected an integer"},
        BadInput{"BoxTooLarge",
                 edit(kByHand, "size = [12e-6, 12e-6, 16e-6]", "size = [2e-4, 2e-4, 2e-4]"),
                 "box.size = [0.0002, 0.0002, 0.0002]: gives 734 x 734 x 734 = 395446904 nodes at "
                 "l_e = 2.72727e-07 m; at most 100000000 are supported"},
        BadInput{
            "ShearNormalEqualsDirection", edit(kStrain, "direction = \"x\"", "direction = \"z\""),
            "strain.direction = \"z\": must differ from strain.normal = \"z\": shear moves the "
            "face normal to strain.normal along direction"},
        BadInput{"ShearDefaultDirectionEqualsNormal",
                 edit(edit(kStrain, "direction = \"x\"\n", ""), "normal = \"z\"", "normal = \"x\""),
                 "strain.direction = \"x\" (default): must differ from strain.normal = \"x\": "
                 "shear moves the face normal to strain.normal along direction"},
        BadInput{"TensionAlongAnotherAxis", edit(kStrain, "kind = \"shear\"", "kind = \"tension\""),
                 "strain.direction = \"x\": tension acts along the normal strain.normal = \"z\"; "
                 "leave direction out or set it to \"z\""},
        BadInput{"TorsionWithDirection", edit(kStrain, "kind = \"shear\"", "kind = \"torsion\""),
                 "strain.direction = \"x\": torsion twists the face normal to strain.normal about "
                 "that axis; give no direction (the sign of the angle sets the sense)"},
        BadInput{"UnknownStrainKind", edit(kStrain, "kind = \"shear\"", "kind = \"bending\""),
                 "strain.kind = \"bending\": must be one of shear, tension, compression, torsion"},
        BadInput{"StrainValuesNotFromZero",
                 edit(kStrain, "max = 0.1\nsteps = 10", "values = [0.01, 0.02]"),
                 "strain.values = [0.01, 0.02]: must start with 0: the zero-strain state at each "
                 "field is the reference of the loaded ones (Section 4.2.7)"},
        BadInput{"ShearStrainTooLarge", edit(kStrain, "max = 0.1", "max = 1.2"),
                 "strain.max = 1.2: must be in (0, 1) (rad)"},
        BadInput{"StrainWithoutTable",
                 edit(kStrain,
                      "[strain]\nkind = \"shear\"\nnormal = \"z\"\n"
                      "direction = \"x\"\nmax = 0.1\nsteps = 10\n",
                      ""),
                 "missing table [strain]"},
        BadInput{"StrainTableInAHysteresisRun",
                 kValid + "[strain]\nkind = \"shear\"\nmax = 0.1\nsteps = 10\n",
                 "strain = {...}: only read by [run] type = \"mess_strain\" (this is "
                 "\"mess_hysteresis\")"},
        BadInput{"LeapfrogSettingsWithTheMinimiser", kValid + "[solver.leapfrog]\ndt = 4e-3\n",
                 "solver.leapfrog = {...}: only read with solver.method = \"leapfrog\" (the method "
                 "is \"minimiser\")"},
        BadInput{"LoadStepStartInAHysteresisRun",
                 kValid + "[solver]\nload_step_start = \"previous\"\n",
                 "solver.load_step_start = \"previous\": only read with run.type = "
                 "\"mess_strain\" (the runs whose load steps start from the previous load "
                 "value)"},
        BadInput{"UnknownLoadStepStart", kStrain + "[solver]\nload_step_start = \"predicted\"\n",
                 "solver.load_step_start = \"predicted\": must be one of extrapolated, secant, "
                 "previous"},
        BadInput{"NegativeMagnetizationTolerance",
                 kValid + "[solver.magnetization]\natol = -1e-3\n",
                 "solver.magnetization.atol = -0.001: must be >= 1e-15 (Ms)"},
        BadInput{"MagnetizationToleranceBelowRounding",
                 kValid + "[solver.magnetization]\natol = 1e-17\n",
                 "solver.magnetization.atol = 1e-17: must be >= 1e-15 (Ms)"},
        BadInput{"UnknownMagnetizationTolerance",
                 kValid + "[solver.magnetization]\ntolerance = \"loose\"\n",
                 "solver.magnetization.tolerance = \"loose\": must be one of tight, original"},
        BadInput{"NotA3DRunType", with("type = \"mess_hysteresis\"", "type = \"pair_hysteresis\""),
                 "run.type = \"pair_hysteresis\": must be one of mess_hysteresis, mess_strain, "
                 "mess_magnetostriction, mess_stress"}),
    [](const auto& info) { return info.param.name; });

}  // namespace
