// `mresim info FILE --json` for a 3D run file reports, without running it, everything the issue
// lists: node, cell and spring counts (by kind), l_e, spring constants, kappa, t_c, system
// dimensions, particle centres and the actual volume fraction. The Phi = 1 % two-particle system
// of Fig. 4.4 (dissertation: 42 x 42 x 83 = 146,412 nodes, 137,842 cells).

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "../../support/temp_dir.hpp"

namespace {

using mresim::testing::read_text;
using mresim::testing::TempDir;

TEST(MessInfoCli, JsonReportsTheLatticeWithoutRunning) {
  const TempDir dir;
  std::ofstream(dir / "phi1.toml") << "[run]\ntype = \"mess_hysteresis\"\n"
                                      "[model]\nprofile = \"seed\"\n"
                                      "[particles]\nplacement = \"regular\"\n"
                                      "volume_fraction = 0.01\ncount_per_axis = [1, 1, 2]\n"
                                      "[field]\nmax = 0.06\nsteps = 12\n";
  const std::string command = "cd '" + dir.path().string() + "' && '" + MRESIM_CLI_PATH +
                              "' info phi1.toml --json > info.json";
  const int raw = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0);
  const auto info = nlohmann::json::parse(read_text(dir / "info.json"));
  const auto value = [&](const char* section, const char* key) {
    return info.at(section).at(key).at("value");
  };
  EXPECT_EQ(value("lattice", "nodes").get<std::int64_t>(), 146412);
  EXPECT_EQ(value("lattice", "cells").get<std::int64_t>(), 137842);
  EXPECT_EQ(value("lattice", "grid").get<std::string>(), "42 x 42 x 83");
  const auto edge = value("lattice", "edge_springs").get<std::int64_t>();
  const auto face = value("lattice", "face_springs").get<std::int64_t>();
  const auto body = value("lattice", "body_springs").get<std::int64_t>();
  EXPECT_EQ(edge + face + body, value("lattice", "springs").get<std::int64_t>());
  // l_e = 2R/(2 n_d + 1) = 3 um / 11 (eq. 4.49).
  EXPECT_NEAR(value("lattice", "element_length").get<double>(), 3e-6 / 11.0, 1e-18);
  for (const char* key : {"k_e", "k_f", "k_c", "kappa"}) {
    EXPECT_GT(value("stiffness", key).get<double>(), 0.0) << key;
  }
  EXPECT_NEAR(value("stiffness", "lattice_shear_modulus").get<double>(), 3600.0, 1e-6);  // seed
  EXPECT_GT(value("scales", "time").get<double>(), 0.0);
  EXPECT_NEAR(value("lattice", "box_length_z").get<double>(), 82 * 3e-6 / 11.0, 1e-15);
  EXPECT_EQ(value("particles", "count").get<int>(), 2);
  EXPECT_TRUE(info.at("particles").contains("centre_0"));
  EXPECT_TRUE(info.at("particles").contains("centre_1"));
  EXPECT_NEAR(value("particles", "volume_fraction").get<double>(), 0.0101117, 1e-6);
  EXPECT_EQ(value("mess", "relaxations").get<int>(), 61);  // 13 values, loop: 5 x 12 + 1
}

}  // namespace
