#include "mresim/io/hdf5_file.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "../support/hdf5_read.hpp"
#include "../support/temp_dir.hpp"

namespace mresim::io {
namespace {

using mresim::testing::Hdf5Reader;
using mresim::testing::TempDir;

TEST(Hdf5File, RoundTripsDatasetsWithUnitsAndNestedGroups) {
  const TempDir dir;
  const auto file = dir / "results.h5";
  {
    Hdf5File h5(file);
    h5.write_vector("/steps/field", {0.0, 0.25, -1.5e-7}, "T");
    h5.write_int_vector("steps/iterations", {3, 0, -7, 1LL << 40});
    h5.write_matrix("/steps/positions", 2, 3, {1, 2, 3, 4, 5, 6}, "m");
    h5.write_array("/cube", {2, 1, 2}, {1, 2, 3, 4}, "1");
    h5.write_string_vector("/labels", {"tanh", "wca", "", "ünïcode"});
    h5.write_vector("/empty", {}, "J");
    h5.close();
  }
  const Hdf5Reader in(file);
  EXPECT_EQ(in.doubles("/steps/field"), (std::vector<double>{0.0, 0.25, -1.5e-7}));
  EXPECT_EQ(in.string_attribute("/steps/field", "unit"), "T");
  EXPECT_EQ(in.ints("/steps/iterations"), (std::vector<std::int64_t>{3, 0, -7, 1LL << 40}));
  EXPECT_FALSE(in.has_attribute("/steps/iterations", "unit"));
  EXPECT_EQ(in.shape("/steps/positions"), (std::vector<hsize_t>{2, 3}));
  EXPECT_EQ(in.doubles("/steps/positions"), (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(in.string_attribute("/steps/positions", "unit"), "m");
  EXPECT_EQ(in.shape("/cube"), (std::vector<hsize_t>{2, 1, 2}));
  EXPECT_EQ(in.strings("/labels"), (std::vector<std::string>{"tanh", "wca", "", "ünïcode"}));
  EXPECT_EQ(in.shape("/empty"), (std::vector<hsize_t>{0}));
}

TEST(Hdf5File, WritesAndOverwritesAttributes) {
  const TempDir dir;
  const auto file = dir / "a.h5";
  {
    Hdf5File h5(file);
    h5.write_string_attribute("/", "run_type", "first");
    h5.write_string_attribute("/", "run_type", "second");
    h5.write_number_attribute("/model", "k", 0.04);
    h5.write_int_attribute("/model/deeper", "steps", 12);
    h5.write_vector("/model/x", {1.0}, "m");
    h5.write_number_attribute("/model/x", "scale", 2.5);
    h5.write_string_attribute("/", "long", std::string(200000, 'x'));  // beyond the 64 KiB header
    EXPECT_TRUE(h5.exists("/model/deeper"));
    EXPECT_TRUE(h5.exists("/"));
    EXPECT_FALSE(h5.exists("/nothing/below"));
  }
  const Hdf5Reader in(file);
  EXPECT_EQ(in.string_attribute("/", "run_type"), "second");
  EXPECT_DOUBLE_EQ(in.scalar_attribute<double>("/model", "k", H5T_NATIVE_DOUBLE), 0.04);
  EXPECT_EQ(in.scalar_attribute<std::int64_t>("/model/deeper", "steps", H5T_NATIVE_INT64), 12);
  EXPECT_DOUBLE_EQ(in.scalar_attribute<double>("/model/x", "scale", H5T_NATIVE_DOUBLE), 2.5);
  EXPECT_EQ(in.string_attribute("/", "long").size(), 200000U);
}

TEST(Hdf5File, KeepsNonFiniteValues) {
  const TempDir dir;
  {
    Hdf5File h5(dir / "nan.h5");
    h5.write_vector("/v", {std::numeric_limits<double>::quiet_NaN(), -HUGE_VAL}, "1");
  }
  const auto v = Hdf5Reader(dir / "nan.h5").doubles("/v");
  EXPECT_TRUE(std::isnan(v[0]));
  EXPECT_EQ(v[1], -HUGE_VAL);
}

// The message of the std::runtime_error `action` throws.
template <typename Action>
std::string error_of(Action action) {
  try {
    action();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}

TEST(Hdf5File, RefusesToWriteADatasetTwice) {
  const TempDir dir;
  Hdf5File h5(dir / "twice.h5");
  h5.write_vector("/steps/field", {1.0}, "T");
  EXPECT_EQ(error_of([&] { h5.write_vector("/steps/field", {2.0}, "T"); }),
            "cannot write dataset '/steps/field' in '" + (dir / "twice.h5").string() +
                "': it already exists");
}

TEST(Hdf5File, ChecksMatrixSize) {
  const TempDir dir;
  Hdf5File h5(dir / "m.h5");
  EXPECT_EQ(
      error_of([&] {
        h5.write_matrix("/m", 2, 2, {1, 2, 3}, "m");
      }),
      "dataset '/m' in '" + (dir / "m.h5").string() + "': shape [2, 2] needs 4 values, got 3");
}

TEST(Hdf5File, ErrorsNameFileAndObject) {
  const TempDir dir;
  const std::string file = (dir / "missing_dir" / "r.h5").string();
  const std::string message = error_of([&] { Hdf5File h5(file); });
  EXPECT_EQ(message.rfind("cannot create HDF5 file '" + file + "': ", 0), 0U) << message;

  Hdf5File h5(dir / "e.h5");
  h5.write_vector("/data", {1.0}, "m");
  // A group cannot be created below a dataset.
  const std::string nested = error_of([&] { h5.write_vector("/data/below", {1.0}, "m"); });
  EXPECT_EQ(
      nested.rfind("cannot create dataset '/data/below' in '" + (dir / "e.h5").string() + "': ", 0),
      0U)
      << nested;
  h5.close();
  EXPECT_EQ(error_of([&] { h5.write_vector("/x", {1.0}, "m"); }),
            "cannot write '/x' in '" + (dir / "e.h5").string() + "': the file is closed");
}

TEST(Hdf5File, IsMovable) {
  const TempDir dir;
  Hdf5File a(dir / "move.h5");
  Hdf5File b(std::move(a));
  b.write_vector("/v", {1.0}, "1");
  b.close();
  EXPECT_EQ(Hdf5Reader(dir / "move.h5").doubles("/v"), std::vector<double>{1.0});
}

}  // namespace
}  // namespace mresim::io
