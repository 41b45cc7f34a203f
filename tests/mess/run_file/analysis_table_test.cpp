// [analysis] of the 3D run files (src/mresim/mess/run_file/read_analysis.hpp): the cluster
// distance's default (the WCA cut-off), a given value, and the refused ones (below touching
// spheres, not finite, not positive, unknown keys), each named with its value and the range.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "../support/small_runs.hpp"
#include "mresim/config/config_error.hpp"

namespace {

namespace mc = mresim::mess_config;
using mresim::mess_protocol::testing::small_hysteresis;
using mresim::mess_protocol::testing::spec_of;

std::string with_analysis(const std::string& table) {
  return small_hysteresis(0.1, 1, 0) + "\n[analysis]\n" + table + "\n";
}

std::string error_of(const std::string& toml) {
  try {
    (void)spec_of(toml);
  } catch (const mresim::config::ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(MessAnalysisTable, DefaultClusterDistanceIsTheWcaCutoff) {
  // R = 1.5 um: 2^(1/6) (2R + 100 nm), eq. 4.79's cut-off.
  const mc::MessSpec s = spec_of(small_hysteresis(0.1, 1, 0));
  EXPECT_FALSE(s.analysis.cluster_distance_given);
  EXPECT_NEAR(s.analysis.cluster_distance, std::pow(2.0, 1.0 / 6.0) * 3.1e-6, 1e-20);
  // An empty [analysis] table is the same.
  EXPECT_EQ(spec_of(with_analysis("")).analysis.cluster_distance, s.analysis.cluster_distance);
}

TEST(MessAnalysisTable, GivenClusterDistanceIsKept) {
  const mc::MessSpec s = spec_of(with_analysis("cluster_distance = 3.2e-6"));
  EXPECT_TRUE(s.analysis.cluster_distance_given);
  EXPECT_EQ(s.analysis.cluster_distance, 3.2e-6);
  // Exactly touching spheres is the smallest allowed.
  EXPECT_EQ(spec_of(with_analysis("cluster_distance = 3e-6")).analysis.cluster_distance, 3e-6);
}

TEST(MessAnalysisTable, RefusedValuesNameKeyValueAndRange) {
  EXPECT_EQ(error_of(with_analysis("cluster_distance = 2.9e-6")),
            "analysis.cluster_distance = 2.9e-06: must be >= 2R = 3e-06 m (touching spheres) and "
            "finite; the default is the WCA cut-off 2^(1/6)(2R + 100 nm) = 3.47963e-06 m");
  EXPECT_EQ(error_of(with_analysis("cluster_distance = nan")),
            "analysis.cluster_distance = nan: expected a finite number (m)");
  EXPECT_EQ(error_of(with_analysis("cluster_distance = inf")),
            "analysis.cluster_distance = inf: expected a finite number (m)");
  EXPECT_EQ(error_of(with_analysis("cluster_distance = -1e-6")),
            "analysis.cluster_distance = -1e-06: must be > 0 (m)");
  EXPECT_NE(error_of(with_analysis("cluster_distanse = 4e-6")).find("unknown key"),
            std::string::npos);
}

}  // namespace
