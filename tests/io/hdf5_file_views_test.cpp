// The Hdf5File features the standard views of results.h5 use (docs/outputs-3d.md): compressed
// chunked arrays, one-dimensional attributes, hard links and virtual datasets over other files.

#include <gtest/gtest.h>
#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "../support/hdf5_read.hpp"
#include "../support/temp_dir.hpp"
#include "mresim/io/hdf5_file.hpp"

namespace mresim::io {
namespace {

using mresim::testing::Hdf5Reader;
using mresim::testing::TempDir;

TEST(Hdf5FileViews, CompressedArraysRoundTripInChunksWithShuffleAndGzip) {
  const TempDir dir;
  std::vector<double> values(std::size_t{3} * 1000);
  for (std::size_t i = 0; i < values.size(); ++i) {
    values[i] = 1e-6 * std::sin(0.01 * static_cast<double>(i));
  }
  {
    Hdf5File h5(dir / "p.h5");
    h5.write_compressed_array("/positions", {1000, 3}, values, "m", 256);
    h5.write_compressed_array("/empty", {0, 3}, {}, "m", 256);
  }
  const Hdf5Reader in(dir / "p.h5");
  EXPECT_EQ(in.doubles("/positions"), values);
  EXPECT_EQ(in.string_attribute("/positions", "unit"), "m");
  EXPECT_EQ(in.shape("/empty"), (std::vector<hsize_t>{0, 3}));

  const hid_t file = H5Fopen((dir / "p.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t dataset = H5Dopen2(file, "/positions", H5P_DEFAULT);
  const hid_t creation = H5Dget_create_plist(dataset);
  std::array<hsize_t, 2> chunk{};
  EXPECT_EQ(H5Pget_chunk(creation, 2, chunk.data()), 2);
  EXPECT_EQ(chunk, (std::array<hsize_t, 2>{256, 3}));
  const int filter_count = H5Pget_nfilters(creation);
  std::vector<H5Z_filter_t> filters;
  filters.reserve(static_cast<std::size_t>(std::max(filter_count, 0)));
  for (int i = 0; i < filter_count; ++i) {
    filters.push_back(H5Pget_filter2(creation, static_cast<unsigned>(i), nullptr, nullptr, nullptr,
                                     0, nullptr, nullptr));
  }
  EXPECT_EQ(filters, (std::vector<H5Z_filter_t>{H5Z_FILTER_SHUFFLE, H5Z_FILTER_DEFLATE}));
  EXPECT_LT(H5Dget_storage_size(dataset), values.size() * sizeof(double));
  H5Pclose(creation);
  H5Dclose(dataset);
  H5Fclose(file);
}

TEST(Hdf5FileViews, HardLinksAndVirtualStacksReadTheSameData) {
  const TempDir dir;
  for (int s = 0; s < 2; ++s) {
    Hdf5File part(dir / ("part_" + std::to_string(s) + ".h5"));
    part.write_matrix("/positions", 2, 3, std::vector<double>(6, s + 1.0), "m");
  }
  {
    Hdf5File h5(dir / "results.h5");
    h5.write_vector("/steps/field", {0.0, 0.1}, "T");
    h5.hard_link("/steps/field", "/observables/field/value");
    h5.write_int_vector_attribute("/h5md", "version", {1, 1});
    h5.write_string_vector_attribute("/box", "boundary", {"none", "none", "none"});
    // part_2.h5 does not exist: its entry reads as NaN.
    h5.write_virtual_stack(
        "/nodes", {2, 3},
        {{"part_0.h5", "/positions"}, {"part_1.h5", "/positions"}, {"part_2.h5", "/positions"}},
        "m");
    EXPECT_THROW(h5.hard_link("/missing", "/other"), std::runtime_error);
  }
  const Hdf5Reader in(dir / "results.h5");
  EXPECT_EQ(in.doubles("/observables/field/value"), (std::vector<double>{0.0, 0.1}));
  EXPECT_EQ(in.string_attribute("/observables/field/value", "unit"), "T");
  EXPECT_EQ(in.shape("/nodes"), (std::vector<hsize_t>{3, 2, 3}));
  const std::vector<double> nodes = in.doubles("/nodes");
  for (std::size_t i = 0; i < 12; ++i) EXPECT_EQ(nodes[i], i < 6 ? 1.0 : 2.0) << i;
  for (std::size_t i = 12; i < 18; ++i) EXPECT_TRUE(std::isnan(nodes[i])) << i;

  const hid_t file = H5Fopen((dir / "results.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t attribute = H5Aopen_by_name(file, "/h5md", "version", H5P_DEFAULT, H5P_DEFAULT);
  std::array<std::int64_t, 2> version{};
  H5Aread(attribute, H5T_NATIVE_INT64, version.data());
  EXPECT_EQ(version, (std::array<std::int64_t, 2>{1, 1}));
  H5Aclose(attribute);
  const hid_t boundary = H5Aopen_by_name(file, "/box", "boundary", H5P_DEFAULT, H5P_DEFAULT);
  const hid_t space = H5Aget_space(boundary);
  EXPECT_EQ(H5Sget_simple_extent_npoints(space), 3);
  H5Sclose(space);
  H5Aclose(boundary);
  H5Fclose(file);
}

}  // namespace
}  // namespace mresim::io
