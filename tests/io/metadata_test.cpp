#include "mresim/io/metadata.hpp"

#include <gtest/gtest.h>

#include <mresim/core/version.hpp>
#include <regex>

#include "../support/hdf5_read.hpp"
#include "../support/temp_dir.hpp"

namespace mresim::io {
namespace {

TEST(Metadata, RecordsVersionRunTypeInputAndTime) {
  const mresim::testing::TempDir dir;
  const std::string text = "# my run\n[run]\ntype = \"demo\"\n";
  const auto root = config::TableReader::parse_string(text, "demo.toml");
  {
    Hdf5File h5(dir / "results.h5");
    write_run_metadata(h5, root, "demo");
  }
  const mresim::testing::Hdf5Reader in(dir / "results.h5");
  EXPECT_EQ(in.string_attribute("/", "mresim_version"), kVersion);
  EXPECT_EQ(in.string_attribute("/", "run_type"), "demo");
  EXPECT_EQ(in.string_attribute("/", "input_toml"), text);
  EXPECT_EQ(in.string_attribute("/", "input_file"), "demo.toml");
  EXPECT_TRUE(std::regex_match(in.string_attribute("/", "created_utc"),
                               std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)")));
}

}  // namespace
}  // namespace mresim::io
