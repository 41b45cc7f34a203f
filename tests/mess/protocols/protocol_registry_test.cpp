// The protocol registry (src/mresim/mess/protocols/protocol.hpp): every protocol of the 3D model
// registers itself, becomes the run type of its name, reads its own table, and is the only
// place the runner and the outputs learn its boundary conditions, strain and analysis from.
// A test-only protocol below shows that one file is all a new protocol needs.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "../support/small_runs.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/config/config_error.hpp"
#include "mresim/mess/protocols/protocol.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"

namespace {

namespace mp = mresim::mess_protocol;
namespace mc = mresim::mess_config;
using mresim::config::TableReader;

// ---- a protocol (not registered, so the lists stay those of the built-in ones) ----------

constexpr double kSentinelStrain = 0.125;

class TestClamp final : public mp::ProtocolWith<std::string> {
 public:
  using ProtocolWith::ProtocolWith;
  [[nodiscard]] mp::LoadState load(const mresim::lattice::Lattice& lattice,
                                   const mp::StepSpec& /*step*/,
                                   const Eigen::Matrix3Xd& reference) const override {
    mp::LoadState s;
    s.constraints = mresim::mess::BoundaryConstraints::none(lattice.node_count());
    s.constraints.fix_face(
        lattice.shape,
        settings() == "top" ? mresim::lattice::Face::top : mresim::lattice::Face::bottom,
        reference);
    return s;
  }
  [[nodiscard]] double measured_strain(const mresim::lattice::Lattice& /*lattice*/,
                                       const mp::StepSpec& /*step*/,
                                       const Eigen::Matrix3Xd& /*positions*/,
                                       const Eigen::Matrix3Xd& /*zero_load*/) const override {
    return kSentinelStrain;
  }
};

// In the order the messages list them (ProtocolType::order).
const std::vector<std::string> kBuiltIn{"mess_hysteresis", "mess_strain", "mess_magnetostriction",
                                        "mess_stress"};

std::string message_of(const std::string& toml) {
  try {
    (void)mp::testing::spec_of(toml);
  } catch (const mresim::config::ConfigError& e) {
    return e.what();
  }
  return "no error";
}

std::string small_run(const std::string& type, const std::string& tables) {
  return "[run]\ntype = \"" + type + "\"\n" + mp::testing::kSmallModel +
         "\n[field]\nmagnitudes = [0.0]\nsequence = \"up\"\n" + tables;
}

TEST(ProtocolRegistry, ListsEveryProtocolEachAsARunType) {
  EXPECT_EQ(mp::protocol_names(), kBuiltIn);  // nothing else claims to be a 3D protocol
  for (const mp::ProtocolType& t : mp::protocol_types()) {
    const mresim::app::RunType* run_type = mresim::app::find_run_type(t.name);
    ASSERT_NE(run_type, nullptr) << t.name;
    EXPECT_EQ(run_type->summary, t.summary);
    EXPECT_FALSE(t.summary.empty());
  }
  EXPECT_EQ(mp::find_protocol("mess_strain").tables, (std::vector<std::string>{"strain"}));
  EXPECT_EQ(mp::find_protocol("mess_stress").tables, (std::vector<std::string>{"stress"}));
  EXPECT_EQ(mp::find_protocol("mess_hysteresis").default_field_sequence, mc::FieldSequence::loop);
  EXPECT_EQ(mp::find_protocol("mess_magnetostriction").default_field_sequence,
            mc::FieldSequence::up);
}

TEST(ProtocolRegistry, AnUnknownProtocolIsRefusedNamingTheRegisteredOnes) {
  try {
    (void)mp::find_protocol("mess_shaking");
    FAIL() << "mess_shaking was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'mess_shaking' is not a 3D protocol"), std::string::npos) << m;
    for (const std::string& n : mp::protocol_names()) {
      EXPECT_NE(m.find(n), std::string::npos) << m;
    }
  }
  // In a run file: the [run] type key, with every allowed name.
  const std::string m = message_of(small_run("mess_shaking", ""));
  EXPECT_NE(m.find("mess_shaking"), std::string::npos) << m;
  for (const std::string& n : mp::protocol_names()) EXPECT_NE(m.find(n), std::string::npos) << m;
}

TEST(ProtocolRegistry, EachProtocolReadsOnlyItsOwnTable) {
  // Another protocol's table is refused, naming its owner and this run's type.
  EXPECT_EQ(message_of(small_run("mess_hysteresis", "[strain]\nkind = \"shear\"\n")),
            "strain = {...}: only read by [run] type = \"mess_strain\" (this is "
            "\"mess_hysteresis\")");
  EXPECT_NE(message_of(small_run("mess_strain",
                                 "[strain]\nkind = \"shear\"\nmax = 0.1\nsteps = "
                                 "1\n[stress]\nkind = \"shear\"\nmax = 1\nsteps = 1\n"))
                .find("only read by [run] type = \"mess_stress\" (this is \"mess_strain\")"),
            std::string::npos);
}

TEST(ProtocolRegistry, TheRunnerTakesLoadAndStrainFromTheProtocol) {
  mc::MessSpec spec = mp::testing::spec_of(small_run("mess_hysteresis", ""));
  spec.protocol = std::make_shared<const TestClamp>("top");  // instead of all faces held
  mp::ProtocolRunner runner(spec);
  ASSERT_EQ(runner.steps().size(), 1U);
  mp::ProtocolState state = runner.initial_state();
  const mp::StepRecord& r = runner.run_next_step(state);
  EXPECT_EQ(r.measured_strain, kSentinelStrain);
  // Only the top face is held: its nodes stay exactly put, the bottom's are free.
  const auto& lat = runner.system().lattice();
  const auto& c = runner.system().constraints();
  const std::vector<int> top = mresim::lattice::face_nodes(lat.shape, mresim::lattice::Face::top);
  const std::vector<int> bottom =
      mresim::lattice::face_nodes(lat.shape, mresim::lattice::Face::bottom);
  for (const int n : top) EXPECT_TRUE(c.is_fixed(n, 2)) << n;
  for (const int n : bottom) EXPECT_FALSE(c.is_fixed(n, 2)) << n;
}

TEST(ProtocolRegistry, TheBuiltInProtocolsNameTheirUnitAndAnalysis) {
  const std::string strain = "[strain]\nkind = \"KIND\"\nmax = 0.1\nsteps = 2\n";
  const auto with_kind = [&](const std::string& kind) {
    std::string t = strain;
    t.replace(t.find("KIND"), 4, kind);
    return mp::testing::spec_of(small_run("mess_strain", t));
  };
  const mc::MessSpec shear = with_kind("shear");
  EXPECT_STREQ(shear.protocol->load_unit(), "rad");
  EXPECT_EQ(shear.protocol->analysis().kind, mp::AnalysisKind::energy_modulus);
  EXPECT_EQ(shear.protocol->analysis().modulus_name, "G_eff");
  EXPECT_TRUE(shear.protocol->analysis().drop_zero_point_above_next);
  EXPECT_TRUE(shear.protocol->loads_from_zero_load_state());
  EXPECT_EQ(shear.protocol->load_values().size(), 3U);
  EXPECT_EQ(mp::plan_steps(shear).size(), 3U);  // 3 strains x 1 field
  const mc::MessSpec tension = with_kind("tension");
  EXPECT_STREQ(tension.protocol->load_unit(), "1");
  EXPECT_EQ(tension.protocol->analysis().modulus_name, "E_eff");
  EXPECT_FALSE(tension.protocol->analysis().drop_zero_point_above_next);
  EXPECT_EQ(with_kind("torsion").protocol->analysis().modulus_name, "torsion_stiffness");

  const mc::MessSpec stress = mp::testing::spec_of(
      small_run("mess_stress", "[stress]\nkind = \"tension\"\nmax = 100\nsteps = 1\n"));
  EXPECT_STREQ(stress.protocol->load_unit(), "Pa");
  EXPECT_EQ(stress.protocol->analysis().kind, mp::AnalysisKind::stress_modulus);
  EXPECT_EQ(stress.protocol->analysis().modulus_name, "E_eff");
  EXPECT_FALSE(stress.protocol->loads_from_zero_load_state());

  for (const char* type : {"mess_hysteresis", "mess_magnetostriction"}) {
    const mc::MessSpec s = mp::testing::spec_of(small_run(type, ""));
    EXPECT_EQ(s.protocol->analysis().kind, mp::AnalysisKind::none) << type;
    EXPECT_FALSE(s.protocol->has_load()) << type;
    EXPECT_EQ(s.protocol->load_values(), std::vector<double>{0.0}) << type;
    EXPECT_STREQ(s.protocol->load_unit(), "1") << type;
  }
}

}  // namespace
