// The 3D run file's vectors and named values as they land in the MessSpec: box.size,
// box.rounding (default from the model profile), particles.positions / centre / axis,
// particles.self_energy, field.values and field.sequence (default per run type).
#include <gtest/gtest.h>

#include <string>
#include <variant>

#include "../support/mess_run_file.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"

namespace {

using mresim::testing::read_spec;
using namespace mresim::mess_config;
namespace lattice = mresim::lattice;
namespace magnetism = mresim::magnetism;

std::string chain(const std::string& model, const std::string& particles, const std::string& box) {
  return "[run]\ntype = \"mess_hysteresis\"\n[model]\n" + model +
         "\n[particles]\nplacement = \"chain\"\ncount = 2\nseparation = 6e-6\n" + particles +
         "\n[box]\nsize = [12e-6, 12e-6, 20e-6]\n" + box + "\n[field]\nmax = 0.06\nsteps = 2\n";
}

TEST(MessConfigNamedValues, BoxSizeAndRoundingWithProfileDefaults) {
  const MessSpec physical = read_spec(chain("", "", ""));
  ASSERT_TRUE(physical.box.has_value());
  EXPECT_EQ(physical.box->lengths, Eigen::Vector3d(12e-6, 12e-6, 20e-6));
  EXPECT_EQ(physical.box->rounding, physical.profile->default_box_rounding);
  const MessSpec seed = read_spec(chain("profile = \"seed\"", "", ""));
  EXPECT_EQ(seed.box->rounding, seed.profile->default_box_rounding);
  // Each name gives its value whatever the profile's default.
  for (const char* profile : {"\"seed\"", "\"physical\""}) {
    const std::string model = std::string("profile = ") + profile;
    EXPECT_EQ(read_spec(chain(model, "", "rounding = \"nearest\"")).box->rounding,
              lattice::BoxRounding::nearest);
    EXPECT_EQ(read_spec(chain(model, "", "rounding = \"seed_floor_divide\"")).box->rounding,
              lattice::BoxRounding::seed_floor_divide);
  }
}

TEST(MessConfigNamedValues, ChainAxisAndCentre) {
  const auto placement = [](const MessSpec& s) {
    return std::get<lattice::ChainPlacement>(s.lattice.placement);
  };
  EXPECT_EQ(placement(read_spec(chain("", "", ""))).axis, 2);
  EXPECT_FALSE(placement(read_spec(chain("", "", ""))).centre.has_value());
  EXPECT_EQ(placement(read_spec(chain("", "axis = \"x\"", ""))).axis, 0);
  EXPECT_EQ(placement(read_spec(chain("", "axis = \"y\"", ""))).axis, 1);
  EXPECT_EQ(placement(read_spec(chain("", "axis = \"z\"", ""))).axis, 2);
  const auto centred = placement(read_spec(chain("", "centre = [6e-6, 6e-6, 9e-6]", "")));
  ASSERT_TRUE(centred.centre.has_value());
  EXPECT_EQ(*centred.centre, Eigen::Vector3d(6e-6, 6e-6, 9e-6));
}

TEST(MessConfigNamedValues, ByHandPositionsSelfEnergyAndFieldVectors) {
  const std::string text = R"(
[run]
type = "mess_magnetostriction"
[particles]
placement = "by_hand"
positions = [[6e-6, 6e-6, 5e-6], [6e-6, 6e-6, 11e-6]]
self_energy = "linearized"
[box]
size = [12e-6, 12e-6, 16e-6]
[field]
values = [[0, 0, 0], [0.01, 0, -0.02]]
)";
  const MessSpec s = read_spec(text);
  const auto& positions = std::get<lattice::ByHandPlacement>(s.lattice.placement).positions;
  ASSERT_EQ(positions.size(), 2U);
  EXPECT_EQ(positions[0], Eigen::Vector3d(6e-6, 6e-6, 5e-6));
  EXPECT_EQ(positions[1], Eigen::Vector3d(6e-6, 6e-6, 11e-6));
  EXPECT_EQ(s.self_energy, magnetism::SelfEnergyForm::linearized);
  EXPECT_EQ(s.field.form, FieldSpec::Form::vectors);
  ASSERT_EQ(s.field.values.size(), 2U);
  EXPECT_EQ(s.field.values[1], Eigen::Vector3d(0.01, 0.0, -0.02));
  EXPECT_DOUBLE_EQ(s.field.max, Eigen::Vector3d(0.01, 0.0, -0.02).norm());
  EXPECT_EQ(read_spec(chain("", "", "")).self_energy, magnetism::SelfEnergyForm::consistent);
  EXPECT_EQ(read_spec(chain("", "self_energy = \"consistent\"", "")).self_energy,
            magnetism::SelfEnergyForm::consistent);
}

TEST(MessConfigNamedValues, FieldSequenceNamedOrDefaultOfTheRunType) {
  const std::string hysteresis = chain("", "", "");
  EXPECT_EQ(read_spec(hysteresis).field.sequence, FieldSequence::loop);
  EXPECT_EQ(read_spec(hysteresis).field.values.size(), 11U);  // 0 -> max -> -max -> max, 2 steps
  const std::string up = hysteresis + "sequence = \"up\"\n";
  EXPECT_EQ(read_spec(up).field.sequence, FieldSequence::up);
  EXPECT_EQ(read_spec(up).field.values.size(), 3U);
  std::string magnetostriction = hysteresis;
  magnetostriction.replace(magnetostriction.find("mess_hysteresis"), 15, "mess_magnetostriction");
  EXPECT_EQ(read_spec(magnetostriction).field.sequence, FieldSequence::up);
  EXPECT_EQ(read_spec(magnetostriction + "sequence = \"loop\"\n").field.sequence,
            FieldSequence::loop);
}

}  // namespace
