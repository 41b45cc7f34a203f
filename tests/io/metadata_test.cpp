#include "mresim/io/metadata.hpp"

#include <gtest/gtest.h>

#include <array>
#include <mresim/core/git_describe.hpp>
#include <mresim/core/version.hpp>
#include <regex>

#include "../support/hdf5_read.hpp"
#include "../support/temp_dir.hpp"
#include "mresim/app/command_line.hpp"

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

// Provenance: where the program came from (version, git commit), where it ran and how it was
// started. Built from this git checkout, the commit is known: a hex hash, maybe with -dirty.
TEST(Metadata, RecordsGitCommitHostAndCommandLine) {
  const mresim::testing::TempDir dir;
  const auto root = config::TableReader::parse_string("[run]\ntype = \"demo\"\n", "demo.toml");
  const std::array<const char*, 4> argv = {"mresim", "run", "my run.toml", "--set=x='1'"};
  app::set_command_line(static_cast<int>(argv.size()), argv.data());
  {
    Hdf5File h5(dir / "results.h5");
    write_run_metadata(h5, root, "demo");
  }
  const mresim::testing::Hdf5Reader in(dir / "results.h5");
  const std::string git = in.string_attribute("/", "mresim_git");
  EXPECT_EQ(git, kGitDescribe);
  EXPECT_FALSE(git.empty());
  EXPECT_TRUE(std::regex_search(git, std::regex("^(unknown|.*[0-9a-f]{7,}(-dirty)?)$"))) << git;
  EXPECT_FALSE(in.string_attribute("/", "host_name").empty());
  EXPECT_EQ(in.string_attribute("/", "host_name"), host_name());
  EXPECT_EQ(in.string_attribute("/", "command_line"),
            "mresim run 'my run.toml' '--set=x='\\''1'\\'''");
  app::set_command_line(0, nullptr);
}

TEST(Metadata, ShellQuotingLeavesPlainArgumentsAlone) {
  EXPECT_EQ(app::shell_quoted("field.max=0.1"), "field.max=0.1");
  EXPECT_EQ(app::shell_quoted(""), "''");
  EXPECT_EQ(app::shell_quoted("a b"), "'a b'");
  EXPECT_EQ(app::shell_quoted("it's"), "'it'\\''s'");
}

}  // namespace
}  // namespace mresim::io
