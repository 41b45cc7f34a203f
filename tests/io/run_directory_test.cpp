#include "mresim/io/run_directory.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>

#include "../support/temp_dir.hpp"
#include "mresim/io/output_lock.hpp"
#include "mresim/io/run_manifest.hpp"

namespace mresim::io {
namespace {

namespace fs = std::filesystem;
using mresim::testing::read_text;
using mresim::testing::TempDir;
using mresim::testing::write_text;

std::size_t entries_in(const fs::path& dir) {
  return static_cast<std::size_t>(
      std::distance(fs::directory_iterator(dir), fs::directory_iterator{}));
}

// An earlier run to `final_dir` as mresim writes it: committed, with a manifest.
void write_earlier_run(const fs::path& final_dir, const std::string& content) {
  RunDirectory run(final_dir);
  write_text(run.path() / "results.h5", content);
  fs::create_directories(run.path() / "positions");
  write_text(run.path() / "positions" / "step_000000.h5", content);
  run.commit();
}

std::string refusal_of(const fs::path& target) {
  try {
    RunDirectory run(target);
  } catch (const OutputDirectoryError& e) {
    return e.what();
  }
  return "accepted";
}

// A staging directory left by a killed run of pid `pid`, as RunDirectory creates them.
fs::path interrupted_staging(const fs::path& final_dir, long pid) {
  fs::path staging =
      final_dir.parent_path() / (final_dir.filename().string() + ".partial-" + std::to_string(pid));
  fs::create_directories(staging);
  write_text(staging / RunDirectory::kOwnerFile, "mresim, pid " + std::to_string(pid));
  return staging;
}

TEST(RunDirectory, StagesNextToTheFinalDirectoryAndCommitsWithAManifest) {
  const TempDir dir;
  const auto final_dir = dir / "nested" / "run";
  {
    RunDirectory run(final_dir);
    EXPECT_EQ(run.path(), dir.path() / "nested" / ("run.partial-" + std::to_string(::getpid())));
    EXPECT_TRUE(fs::is_directory(run.path()));
    EXPECT_TRUE(fs::exists(run.path() / RunDirectory::kOwnerFile));
    EXPECT_TRUE(fs::exists(OutputLock::lock_path(final_dir)));
    EXPECT_FALSE(fs::exists(final_dir));
    write_text(run.path() / "results.h5", "new");
    run.commit();
    EXPECT_FALSE(fs::exists(run.path()));
  }
  EXPECT_EQ(read_text(final_dir / "results.h5"), "new");
  EXPECT_TRUE(RunDirectory::is_run_directory(final_dir));
  EXPECT_FALSE(fs::exists(final_dir / RunDirectory::kOwnerFile));
  EXPECT_TRUE(run_manifest::unlisted_entries(final_dir).empty());
  EXPECT_NE(read_text(final_dir / run_manifest::kFileName).find("\nresults.h5\n"),
            std::string::npos);
  // The lock is released and its file removed.
  EXPECT_FALSE(fs::exists(OutputLock::lock_path(final_dir)));
  EXPECT_EQ(entries_in(dir / "nested"), 1U);
}

TEST(RunDirectory, AFailedRunRemovesItsStagingAndTheParentsItCreated) {
  const TempDir dir;
  fs::path staging;
  try {
    RunDirectory run(dir / "new" / "deeper" / "run");
    staging = run.path();
    write_text(run.path() / "results.h5", "half");
    throw std::runtime_error("solver failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_FALSE(fs::exists(staging));
  EXPECT_FALSE(fs::exists(dir / "new"));
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(RunDirectory, AFailedRunKeepsParentsThatGainedOtherFiles) {
  const TempDir dir;
  try {
    RunDirectory run(dir / "new" / "run");
    write_text(dir / "new" / "user.txt", "mine");
    throw std::runtime_error("solver failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(read_text(dir / "new" / "user.txt"), "mine");
  EXPECT_EQ(entries_in(dir / "new"), 1U);
}

TEST(RunDirectory, ReplacesAnEarlierRunThatHoldsOnlyItsOwnFiles) {
  const TempDir dir;
  const auto final_dir = dir / "run";
  write_earlier_run(final_dir, "old");
  // Figures drawn after the commit join the manifest.
  const auto before_plot = fs::file_time_type::clock::now() - std::chrono::seconds(1);
  fs::create_directories(final_dir / "figures");
  write_text(final_dir / "figures" / "loop.png", "png");
  run_manifest::add_files_below(final_dir, "figures", before_plot);
  {
    RunDirectory run(final_dir);
    write_text(run.path() / "results.h5", "new");
    run.commit();
    EXPECT_TRUE(run.moved_aside().empty());
  }
  EXPECT_EQ(read_text(final_dir / "results.h5"), "new");
  EXPECT_FALSE(fs::exists(final_dir / "figures"));
  // Neither the old run nor the staging directory is left next to it.
  EXPECT_EQ(entries_in(dir.path()), 1U);
}

// Issue: `echo x > mydata/results.h5; echo work > mydata/thesis.tex; mresim run ... --out mydata`
// replaced the whole directory.
TEST(RunDirectory, RefusesADirectoryThatMerelyContainsAResultsFile) {
  const TempDir dir;
  const auto mydata = dir / "mydata";
  fs::create_directories(mydata);
  write_text(mydata / "results.h5", "x");
  write_text(mydata / "thesis.tex", "work");
  EXPECT_EQ(refusal_of(mydata),
            "output directory '" + mydata.string() +
                "' exists and was not written by mresim (it has no .mresim-manifest and holds "
                "'results.h5', 'thesis.tex'); choose another --out, or add --force to move it "
                "aside (it is renamed, never deleted)");
  EXPECT_EQ(read_text(mydata / "thesis.tex"), "work");
  EXPECT_EQ(read_text(mydata / "results.h5"), "x");
  EXPECT_EQ(entries_in(dir.path()), 1U);  // no staging directory, no lock file
}

TEST(RunDirectory, RefusesARunDirectoryWithFilesTheUserAdded) {
  const TempDir dir;
  const auto final_dir = dir / "run";
  write_earlier_run(final_dir, "old");
  write_text(final_dir / "notes.txt", "my notes");
  fs::create_directories(final_dir / "analysis");
  write_text(final_dir / "analysis" / "fit.py", "code");
  EXPECT_EQ(refusal_of(final_dir), "output directory '" + final_dir.string() +
                                       "' holds files mresim did not write ('analysis', "
                                       "'notes.txt'); choose another --out, or add --force to "
                                       "move it aside (it is renamed, never deleted)");
  EXPECT_EQ(read_text(final_dir / "notes.txt"), "my notes");
  EXPECT_EQ(read_text(final_dir / "results.h5"), "old");
}

TEST(RunDirectory, RefusesAPlainFile) {
  const TempDir dir;
  const auto file = dir / "plain_file";
  write_text(file, "x");
  EXPECT_NE(refusal_of(file).find("exists and is not a directory"), std::string::npos);
  EXPECT_EQ(read_text(file), "x");
}

TEST(RunDirectory, ForceMovesAnUnrecognisedDirectoryAsideAndNeverDeletesIt) {
  const TempDir dir;
  const auto mydata = dir / "mydata";
  fs::create_directories(mydata);
  write_text(mydata / "thesis.tex", "work");
  fs::path aside;
  {
    RunDirectory run(mydata, RunDirectory::Options{true});
    write_text(run.path() / "results.h5", "new");
    run.commit();
    aside = run.moved_aside();
  }
  ASSERT_FALSE(aside.empty());
  EXPECT_EQ(aside.parent_path(), dir.path());
  EXPECT_EQ(aside.filename().string().rfind("mydata.replaced-", 0), 0U);
  EXPECT_EQ(read_text(aside / "thesis.tex"), "work");
  EXPECT_EQ(read_text(mydata / "results.h5"), "new");
}

TEST(RunDirectory, ForceLeavesTheDirectoryAloneIfTheRunFails) {
  const TempDir dir;
  const auto mydata = dir / "mydata";
  fs::create_directories(mydata);
  write_text(mydata / "thesis.tex", "work");
  { RunDirectory run(mydata, RunDirectory::Options{true}); }
  EXPECT_EQ(read_text(mydata / "thesis.tex"), "work");
  EXPECT_EQ(entries_in(dir.path()), 1U);
}

TEST(RunDirectory, KeepsAnEarlierRunIfTheNewOneFails) {
  const TempDir dir;
  const auto final_dir = dir / "run";
  write_earlier_run(final_dir, "old");
  {
    RunDirectory run(final_dir);
    write_text(run.path() / "results.h5", "new");
  }
  EXPECT_EQ(read_text(final_dir / "results.h5"), "old");
}

TEST(RunDirectory, CommitKeepsTheResultsAsideIfTheUserAddedFilesMeanwhile) {
  const TempDir dir;
  const auto final_dir = dir / "run";
  write_earlier_run(final_dir, "old");
  RunDirectory run(final_dir);
  write_text(run.path() / "results.h5", "new");
  write_text(final_dir / "notes.txt", "written during the run");
  try {
    run.commit();
    FAIL() << "commit replaced a directory holding a user's file";
  } catch (const OutputDirectoryError& e) {
    EXPECT_NE(std::string(e.what()).find("'notes.txt'"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find(run.path().string()), std::string::npos);
  }
  EXPECT_EQ(read_text(final_dir / "notes.txt"), "written during the run");
  EXPECT_EQ(read_text(final_dir / "results.h5"), "old");
  EXPECT_EQ(read_text(run.path() / "results.h5"), "new");
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

// Issue: two runs into the same --out at once both "succeeded".
TEST(RunDirectory, ASecondRunToALockedDirectoryIsRefusedNamingTheFirst) {
  const TempDir dir;
  RunDirectory first(dir / "run");
  const std::string refusal = refusal_of(dir / "run");
  EXPECT_NE(refusal.find("is in use by mresim run, pid " + std::to_string(::getpid()) + " on host"),
            std::string::npos)
      << refusal;
  EXPECT_NE(refusal.find("wait for it to finish or choose another --out"), std::string::npos);
  EXPECT_TRUE(fs::is_directory(first.path()));  // the first run is untouched
  try {
    (void)RunDirectory::resume(dir / "run", "checkpoint.h5");
    FAIL() << "resume took over a running run";
  } catch (const OutputDirectoryError& e) {
    EXPECT_NE(std::string(e.what()).find("nothing can be resumed while it runs"), std::string::npos)
        << e.what();
    EXPECT_EQ(std::string(e.what()).find("mresim run'"), std::string::npos);
  }
}

// Issue: a killed run whose pid is reused (pid 1 in a container) could never be resumed. Who
// owns a staging directory is decided by the lock, not by the pid in its name.
TEST(RunDirectory, ResumesAnInterruptedRunWhateverItsPid) {
  const TempDir dir;
  const auto interrupted = interrupted_staging(dir / "run", 1);  // pid 1 is alive (init)
  write_text(interrupted / "checkpoint.h5", "state");
  const auto without_checkpoint = interrupted_staging(dir / "run", 99999998);
  {
    const auto run = RunDirectory::resume(dir / "run", "checkpoint.h5");
    EXPECT_EQ(run->path(), dir.path() / ("run.partial-" + std::to_string(::getpid())));
    EXPECT_EQ(read_text(run->path() / "checkpoint.h5"), "state");
    EXPECT_FALSE(fs::exists(interrupted));
    write_text(run->path() / "results.h5", "done");
    run->commit();
  }
  EXPECT_EQ(read_text(dir / "run" / "results.h5"), "done");
  EXPECT_TRUE(fs::exists(without_checkpoint));
  EXPECT_THROW((void)RunDirectory::resume(dir / "run2", "checkpoint.h5"), OutputDirectoryError);
}

TEST(RunDirectory, ANewRunRemovesInterruptedStagingButNothingElse) {
  const TempDir dir;
  const auto stale = interrupted_staging(dir / "run", 1);
  const auto unrelated = interrupted_staging(dir / "other", 1);
  fs::create_directories(dir / "run.partial-7");  // no owner file: not mresim's
  RunDirectory run(dir / "run");
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(unrelated));
  EXPECT_TRUE(fs::exists(dir / "run.partial-7"));
}

TEST(RunDirectory, KeepForResumeLeavesTheStagingDirectoryToResume) {
  const TempDir dir;
  fs::path staging;
  {
    RunDirectory run(dir / "run");
    staging = run.path();
    write_text(run.path() / "checkpoint.h5", "state");
    run.keep_for_resume();
  }
  EXPECT_TRUE(fs::exists(staging / "checkpoint.h5"));
  EXPECT_FALSE(fs::exists(OutputLock::lock_path(dir / "run")));
  const auto resumed = RunDirectory::resume(dir / "run", "checkpoint.h5");
  EXPECT_EQ(read_text(resumed->path() / "checkpoint.h5"), "state");
}

TEST(RunDirectory, CommitTwiceIsAProgrammingError) {
  const TempDir dir;
  RunDirectory run(dir / "run");
  run.commit();
  EXPECT_THROW(run.commit(), std::logic_error);
}

}  // namespace
}  // namespace mresim::io
