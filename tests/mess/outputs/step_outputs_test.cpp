// The per-step outputs derived from the relaxed states (docs/outputs-3d.md, /steps): the box
// strain and magnetostriction, the closest pair's angle to the field and the cluster distance
// of [analysis], written by real runs of the small two-particle system (tests/mess/support/
// small_runs.hpp: 7 um apart along z, field along z).

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "../../support/hdf5_read.hpp"
#include "../../support/temp_dir.hpp"
#include "../support/cli_run.hpp"
#include "../support/small_runs.hpp"

namespace mresim::mess_protocol {
namespace {

using mresim::testing::Hdf5Reader;
using mresim::testing::TempDir;
using testing::column_of;
using testing::csv_rows;
using testing::kSmallModel;
using testing::run_in;
using testing::with;

const std::string kMagnetostriction = std::string("[run]\ntype = \"mess_magnetostriction\"\n") +
                                      kSmallModel +
                                      "\n[field]\nmagnitudes = [0.0, 0.1]\n"
                                      "\n[output]\ncheckpoint_every = 0\n";

// The WCA cut-off 2^(1/6)(2R + 100 nm) of R = 1.5 um (eq. 4.79), the default cluster distance.
const double kWcaCutoff = std::pow(2.0, 1.0 / 6.0) * (3.0e-6 + 100e-9);

TEST(MessStepOutputs, MagnetostrictionIsTheBoxStrainAlongTheField) {
  const TempDir dir;
  const auto r = run_in(dir, kMagnetostriction);
  ASSERT_EQ(r.status, 0) << r.err;
  const Hdf5Reader h5(dir / "out" / "results.h5");
  ASSERT_EQ(h5.shape("/steps/box_strain"), (std::vector<hsize_t>{2, 3}));
  const auto e = h5.doubles("/steps/box_strain");
  const auto m = h5.doubles("/steps/magnetostriction");
  ASSERT_EQ(m.size(), 2U);
  // d = z: the magnetostriction is the z column.
  EXPECT_EQ(m[0], e[2]);
  EXPECT_EQ(m[1], e[5]);
  // At zero field nothing moves (the initial lattice is at rest).
  EXPECT_NEAR(m[0], 0.0, 1e-12);
  // At 0.1 T the pair attracts along z and pulls the free top face down: a contraction along
  // the field (the particles snap into contact in this small box; the box shortens by ~12 %).
  EXPECT_LT(m[1], -0.01);
  // Poisson: the sides bulge out (the lattice is compressible, nu = 0.47: less than e_z/2 each).
  EXPECT_GT(e[3], 0.0);
  EXPECT_GT(e[4], 0.0);
  EXPECT_LT(e[3], -0.5 * e[5]);
  // summary.csv carries the same numbers.
  const auto rows = csv_rows(dir / "out" / "summary.csv");
  ASSERT_EQ(rows.size(), 3U);
  EXPECT_NEAR(std::stod(rows[2][column_of(rows[0], "magnetostriction")]), m[1],
              1e-9 * std::abs(m[1]));
}

TEST(MessStepOutputs, HysteresisHoldsTheFacesSoTheBoxDoesNotStrain) {
  const TempDir dir;
  const auto r = run_in(dir, testing::small_hysteresis(0.1, 1, 0));
  ASSERT_EQ(r.status, 0) << r.err;
  const Hdf5Reader h5(dir / "out" / "results.h5");
  for (const double e : h5.doubles("/steps/box_strain")) EXPECT_EQ(e, 0.0);
  for (const double m : h5.doubles("/steps/magnetostriction")) EXPECT_EQ(m, 0.0);
}

TEST(MessStepOutputs, PairAngleOfAPairAlongTheField) {
  const TempDir dir;
  const auto r = run_in(dir, testing::small_hysteresis(0.1, 1, 0));
  ASSERT_EQ(r.status, 0) << r.err;
  const Hdf5Reader h5(dir / "out" / "results.h5");
  const auto angle = h5.doubles("/steps/pair_angle");
  ASSERT_EQ(angle.size(), 6U);
  // The pair starts exactly along z, and with every face held nothing tilts it (the lattice
  // is symmetric about the pair's axis): the angle stays 0 to rounding.
  for (const double a : angle) EXPECT_NEAR(a, 0.0, 1e-6);
  EXPECT_NE(h5.string_attribute("/steps/pair_angle", "reference").find("field direction"),
            std::string::npos);
  const auto rows = csv_rows(dir / "out" / "summary.csv");
  EXPECT_NEAR(std::stod(rows[1][column_of(rows[0], "pair_angle_deg")]),
              angle[0] * 180.0 / std::numbers::pi, 1e-9);
}

TEST(MessStepOutputs, PairAngleAcrossTheField) {
  // The same pair with the field along x: 90 degrees.
  const TempDir dir;
  const auto r = run_in(dir, with(kMagnetostriction, "magnitudes = [0.0, 0.1]",
                                  "magnitudes = [0.0, 0.02]\ntheta = 90\nphi = 0"));
  ASSERT_EQ(r.status, 0) << r.err;
  const Hdf5Reader h5(dir / "out" / "results.h5");
  for (const double a : h5.doubles("/steps/pair_angle")) {
    EXPECT_NEAR(a, std::numbers::pi / 2, 1e-3);
  }
  // d = x: the magnetostriction is the x column now.
  const auto e = h5.doubles("/steps/box_strain");
  EXPECT_EQ(h5.doubles("/steps/magnetostriction")[1], e[3]);
}

TEST(MessStepOutputs, DefaultClusterDistanceIsTheWcaCutoff) {
  const TempDir dir;
  const auto r = run_in(dir, kMagnetostriction);
  ASSERT_EQ(r.status, 0) << r.err;
  const Hdf5Reader h5(dir / "out" / "results.h5");
  EXPECT_NEAR(h5.scalar_attribute<double>("/steps", "cluster_distance", H5T_NATIVE_DOUBLE),
              kWcaCutoff, 1e-12 * kWcaCutoff);
  // 7 um apart at zero field: two clusters.
  EXPECT_EQ(h5.ints("/steps/cluster_count")[0], 2);
}

TEST(MessStepOutputs, ClusterDistanceFromTheRunFileIsUsedAndRecorded) {
  // 8 um: the pair 7 um apart at zero field counts as one cluster.
  const TempDir dir;
  const auto r = run_in(dir, kMagnetostriction + "\n[analysis]\ncluster_distance = 8e-6\n");
  ASSERT_EQ(r.status, 0) << r.err;
  const Hdf5Reader h5(dir / "out" / "results.h5");
  EXPECT_EQ(h5.scalar_attribute<double>("/steps", "cluster_distance", H5T_NATIVE_DOUBLE), 8e-6);
  EXPECT_EQ(h5.ints("/steps/cluster_count")[0], 1);
  EXPECT_EQ(h5.ints("/steps/largest_cluster")[0], 2);
  EXPECT_EQ(h5.ints("/steps/cluster_id"), (std::vector<std::int64_t>{0, 0, 0, 0}));
}

}  // namespace
}  // namespace mresim::mess_protocol
