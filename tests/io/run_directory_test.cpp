#include "mresim/io/run_directory.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>

#include "../support/temp_dir.hpp"

namespace mresim::io {
namespace {

namespace fs = std::filesystem;
using mresim::testing::read_text;
using mresim::testing::TempDir;
using mresim::testing::write_text;

TEST(RunDirectory, StagesNextToTheFinalDirectoryAndCommits) {
  const TempDir dir;
  const auto final_dir = dir / "nested" / "run";
  {
    RunDirectory run(final_dir);
    EXPECT_EQ(run.path(), dir.path() / "nested" / ("run.partial-" + std::to_string(::getpid())));
    EXPECT_TRUE(fs::is_directory(run.path()));
    EXPECT_FALSE(fs::exists(final_dir));
    write_text(run.path() / "results.h5", "new");
    run.commit();
    EXPECT_FALSE(fs::exists(run.path()));
  }
  EXPECT_EQ(read_text(final_dir / "results.h5"), "new");
  EXPECT_TRUE(RunDirectory::is_run_directory(final_dir));
}

TEST(RunDirectory, RemovesTheStagingDirectoryWhenAnExceptionEscapes) {
  const TempDir dir;
  fs::path staging;
  try {
    RunDirectory run(dir / "run");
    staging = run.path();
    write_text(run.path() / "results.h5", "half");
    throw std::runtime_error("solver failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_FALSE(fs::exists(staging));
  EXPECT_FALSE(fs::exists(dir / "run"));
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(RunDirectory, ReplacesAnEarlierRun) {
  const TempDir dir;
  const auto final_dir = dir / "run";
  fs::create_directories(final_dir / "figures");
  write_text(final_dir / "results.h5", "old");
  write_text(final_dir / "figures" / "old.png", "old");
  {
    RunDirectory run(final_dir);
    write_text(run.path() / "results.h5", "new");
    run.commit();
  }
  EXPECT_EQ(read_text(final_dir / "results.h5"), "new");
  EXPECT_FALSE(fs::exists(final_dir / "figures"));
  // Neither the old run nor the staging directory is left next to it.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator{}), 1);
}

TEST(RunDirectory, KeepsAnEarlierRunIfTheNewOneFails) {
  const TempDir dir;
  const auto final_dir = dir / "run";
  fs::create_directories(final_dir);
  write_text(final_dir / "results.h5", "old");
  {
    RunDirectory run(final_dir);
    write_text(run.path() / "results.h5", "new");
  }
  EXPECT_EQ(read_text(final_dir / "results.h5"), "old");
}

std::string refusal_of(const fs::path& target) {
  try {
    RunDirectory run(target);
  } catch (const OutputDirectoryError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(RunDirectory, RefusesADirectoryThatIsNotARun) {
  const TempDir dir;
  const auto precious = dir / "thesis";
  fs::create_directories(precious);
  write_text(precious / "chapter1.tex", "years of work");
  EXPECT_EQ(refusal_of(precious),
            "output directory '" + precious.string() +
                "' exists and is not an mresim run directory; choose another --out");
  EXPECT_EQ(read_text(precious / "chapter1.tex"), "years of work");
  // Nothing was created beside it.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator{}), 1);

  const auto file = dir / "plain_file";
  write_text(file, "x");
  EXPECT_EQ(refusal_of(file),
            "output directory '" + file.string() +
                "' exists and is not an mresim run directory; choose another --out");
}

TEST(RunDirectory, AcceptsAnEmptyDirectoryAndATrailingSlash) {
  const TempDir dir;
  fs::create_directories(dir / "empty");
  {
    RunDirectory run((dir / "empty").string() + "/");
    EXPECT_EQ(run.final_path(), dir / "empty");
    write_text(run.path() / "results.h5", "x");
    run.commit();
  }
  EXPECT_TRUE(RunDirectory::is_run_directory(dir / "empty"));
}

TEST(RunDirectory, RemovesStagingLeftByAKilledRun) {
  const TempDir dir;
  // No process can have this id (above Linux's pid_max limit of 2^22).
  const auto stale = dir / "run.partial-99999999";
  fs::create_directories(stale);
  const auto unrelated = dir / "other.partial-99999999";
  fs::create_directories(unrelated);
  RunDirectory run(dir / "run");
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(unrelated));
}

// `mresim resume`: the staging directory of a finished process that holds the marker file is
// found, taken over with its contents, and committed like a fresh run.
TEST(RunDirectory, ResumesTheStagingDirectoryOfAnInterruptedRun) {
  const TempDir dir;
  const auto interrupted = dir / "run.partial-99999999";  // no such process (above pid_max)
  const auto without_checkpoint = dir / "run.partial-99999998";
  fs::create_directories(interrupted);
  fs::create_directories(without_checkpoint);
  write_text(interrupted / "checkpoint.h5", "state");
  EXPECT_EQ(RunDirectory::find_interrupted(dir / "run", "checkpoint.h5"), interrupted);
  EXPECT_TRUE(RunDirectory::find_interrupted(dir / "other", "checkpoint.h5").empty());
  {
    RunDirectory run(dir / "run", interrupted);
    EXPECT_EQ(run.path(), dir.path() / ("run.partial-" + std::to_string(::getpid())));
    EXPECT_EQ(read_text(run.path() / "checkpoint.h5"), "state");
    EXPECT_FALSE(fs::exists(interrupted));
    write_text(run.path() / "results.h5", "done");
    run.commit();
  }
  EXPECT_EQ(read_text(dir / "run" / "checkpoint.h5"), "state");
  EXPECT_EQ(read_text(dir / "run" / "results.h5"), "done");
  EXPECT_THROW(RunDirectory(dir / "run2", dir / "run2.partial-1"), OutputDirectoryError);
}

TEST(RunDirectory, CommitTwiceIsAProgrammingError) {
  const TempDir dir;
  RunDirectory run(dir / "run");
  run.commit();
  EXPECT_THROW(run.commit(), std::logic_error);
}

}  // namespace
}  // namespace mresim::io
