// Progress (progress.hpp) with an injected clock: the lines it writes on a terminal, without
// one and into a log, the heartbeat during a long step, and the ETA it shows.

#include "mresim/app/progress.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <thread>
#include <vector>

namespace mresim::app {
namespace {

// Everything written to a temporary FILE*.
std::string contents(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string text;
  char buffer[256];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) text.append(buffer, n);
  return text;
}

std::size_t count(const std::string& text, const std::string& word) {
  std::size_t n = 0;
  for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) {
    ++n;
  }
  return n;
}

// A stderr stand-in (terminal or not), a log, and a clock the test moves.
struct Bench {
  std::FILE* stream = std::tmpfile();
  std::FILE* log = std::tmpfile();
  double now = 0.0;
  RunOutput output;

  explicit Bench(bool interactive) : output(RunOutput::Options{stream, interactive, log}) {}
  Bench(const Bench&) = delete;
  Bench& operator=(const Bench&) = delete;
  ~Bench() {
    std::fclose(stream);
    std::fclose(log);
  }

  Progress::Options options() {
    Progress::Options o;
    o.output = &output;
    o.min_interval_s = 0.0;
    o.clock = [this] { return now; };
    return o;
  }
};

TEST(Progress, FormatsDurations) {
  EXPECT_EQ(format_duration(0.42), "0.4s");
  EXPECT_EQ(format_duration(12.34), "12.3s");
  EXPECT_EQ(format_duration(245), "4m05s");
  EXPECT_EQ(format_duration(2 * 3600 + 3 * 60 + 59), "2h03m");
  EXPECT_EQ(format_duration(-1), "?");
}

// A map without a terminal: a line per 10 %, not per point, and the final line.
TEST(Progress, NonInteractiveCountsInTenPercentLines) {
  Bench bench(false);
  {
    Progress progress(100, "sweep", bench.options());
    for (int i = 0; i < 100; ++i) {
      bench.now += 0.1;
      progress.advance();
    }
    progress.finish();
    progress.finish();  // once only
  }
  const std::string text = contents(bench.stream);
  EXPECT_EQ(count(text, "\n"), 10U) << text;  // 10 % ... 90 %, then done
  EXPECT_NE(text.find("sweep: 10% (10/100), elapsed 1.0s, ETA 9.0s\n"), std::string::npos) << text;
  EXPECT_NE(text.find("sweep: 90% (90/100)"), std::string::npos) << text;
  EXPECT_NE(text.find("sweep: done 100/100 in 10.0s\n"), std::string::npos) << text;
  EXPECT_EQ(text.find('\r'), std::string::npos);
  EXPECT_EQ(contents(bench.log), text);  // the log gets the same lines
}

// Units slower than 10 % per 30 s: a line every 30 s anyway.
TEST(Progress, NonInteractiveSlowMapPrintsEvery30Seconds) {
  Bench bench(false);
  Progress progress(1000, "map", bench.options());
  bench.now = 29.0;
  progress.advance();
  EXPECT_EQ(contents(bench.stream), "");
  bench.now = 31.0;
  progress.advance();
  EXPECT_NE(contents(bench.stream).find("map: 0% (2/1000), elapsed 31.0s"), std::string::npos)
      << contents(bench.stream);
  bench.now = 45.0;
  progress.advance();
  EXPECT_EQ(count(contents(bench.stream), "\n"), 1U);
}

TEST(Progress, StepLineHoldsIterationsResidualConvergenceAndTime) {
  Bench bench(false);
  Progress progress(3, "hysteresis", bench.options());
  progress.set_residual("max force", "N");
  progress.begin_step("B 0.1 T");
  progress.iteration(41, 3e-6);
  bench.now = 2.0;
  progress.end_step({42, 1.5e-9, true, 2.0});
  progress.begin_step("B 0.2 T, load 0.01");
  progress.end_step({7, 2e-3, false, 0.3});
  progress.begin_step("B 0.3 T");
  progress.end_step({9000, 1e-15, true, 600.0, "fire"});
  EXPECT_EQ(contents(bench.stream),
            "hysteresis: step 1/3 (B 0.1 T): 42 iterations, max force 1.5e-09 N, converged yes, "
            "2.0s\n"
            "hysteresis: step 2/3 (B 0.2 T, load 0.01): 7 iterations, max force 0.002 N, "
            "converged no, 0.3s\n"
            "hysteresis: step 3/3 (B 0.3 T): 9000 iterations, max force 1e-15 N, converged yes, "
            "10m00s, finished by fire\n");
  EXPECT_EQ(progress.done(), 3U);
}

// During a long step: a heartbeat each 30 s with the latest iteration, none in between.
TEST(Progress, HeartbeatEvery30SecondsOfAStep) {
  Bench bench(false);
  Progress progress(4, "strain", bench.options());
  progress.set_residual("max force", "N");
  bench.now = 100.0;
  progress.begin_step("B 0 T");
  for (int i = 1; i <= 70; ++i) {
    bench.now = 100.0 + i;
    progress.iteration(10 * i, 1.0 / i);
  }
  const std::string text = contents(bench.stream);
  EXPECT_EQ(count(text, "\n"), 2U) << text;
  EXPECT_NE(text.find("strain: step 1/4 (B 0 T): iteration 300, max force 0.0333 N, 30.0s in "
                      "this step\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("iteration 600, max force 0.0167 N, 1m00s in this step\n"), std::string::npos)
      << text;
  // A new step starts its own 30 s.
  progress.end_step({700, 0.01, true, 70.0});
  progress.begin_step("B 0.1 T");
  bench.now += 29.0;
  progress.iteration(1, 1.0);
  EXPECT_EQ(count(contents(bench.stream), "\n"), 3U);
}

// A terminal: the live line shows the step, its iteration and the ETA from the step times; the
// log gets step lines and heartbeats but never the live line.
TEST(Progress, InteractiveLiveLineWithIterationAndEta) {
  Bench bench(true);
  Progress progress(4, "hysteresis", bench.options());
  progress.set_residual("max force", "N");
  for (int s = 0; s < 2; ++s) {
    progress.begin_step("B 0 T");
    bench.now += 10.0;
    progress.end_step({5, 1e-9, true, 10.0});
  }
  progress.begin_step("B 0.1 T");
  bench.now += 5.0;
  progress.iteration(5, 2.5e-7);
  const std::string text = contents(bench.stream);
  // 10 s per step: 5 s left of this one, 10 s for the last.
  EXPECT_NE(text.find("\rhysteresis: step 3/4 (B 0.1 T) iteration 5, max force 2.5e-07 N | "
                      "elapsed 25.0s | ETA 15.0s\x1b[K"),
            std::string::npos)
      << text;
  bench.now += 40.0;
  progress.iteration(6, 1e-7);  // a heartbeat: log only on a terminal
  const std::string log = contents(bench.log);
  EXPECT_EQ(log.find('\r'), std::string::npos) << log;
  EXPECT_EQ(count(log, "converged yes"), 2U) << log;
  EXPECT_NE(log.find("iteration 6, max force 1e-07 N, 45.0s in this step"), std::string::npos);
  EXPECT_EQ(contents(bench.stream).find("in this step"), std::string::npos);
  // A record line first clears the live line.
  progress.note("mresim: warning: something");
  EXPECT_NE(contents(bench.stream).find("\r\x1b[Kmresim: warning: something\n"), std::string::npos);
}

TEST(Progress, ResumedStepsAreCountedButNotTimed) {
  Bench bench(true);
  Progress progress(10, "run", bench.options());
  bench.now = 100.0;
  progress.skip(5);
  EXPECT_EQ(progress.done(), 5U);
  progress.begin_step("B 0 T");
  bench.now = 104.0;
  progress.end_step({1, 0.0, true, 4.0});
  progress.begin_step("B 0 T");
  // 4 s per step (not 104 s / 6): 4 steps left.
  EXPECT_NE(contents(bench.stream).find("step 7/10 (B 0 T) | elapsed 1m44s | ETA 16.0s"),
            std::string::npos)
      << contents(bench.stream);
}

TEST(Progress, UnknownTotalShowsACount) {
  Bench bench(true);
  Progress progress(0, "relax", bench.options());
  progress.advance(3);
  EXPECT_NE(contents(bench.stream).find("relax: 3 done"), std::string::npos);
  progress.set_total(6);
  progress.advance();
  EXPECT_NE(contents(bench.stream).find("relax:  67% (4/6)"), std::string::npos)
      << contents(bench.stream);
}

TEST(Progress, QuietPrintsOnlyErrorsButTheLogGetsEverything) {
  std::FILE* errors = std::tmpfile();
  std::FILE* log = std::tmpfile();
  RunOutput output(RunOutput::Options{nullptr, std::nullopt, log, errors});
  EXPECT_TRUE(output.quiet());
  Progress::Options options;
  options.output = &output;
  Progress progress(2, "run", options);
  progress.begin_step("B 0 T");
  progress.end_step({1, 0.0, true, 0.1});
  progress.note("mresim: warning: w");
  output.error("mresim: error: e");
  progress.finish();
  EXPECT_EQ(contents(errors), "mresim: error: e\n");
  const std::string text = contents(log);
  EXPECT_NE(text.find("run: step 1/2 (B 0 T)"), std::string::npos) << text;
  EXPECT_NE(text.find("mresim: warning: w\nmresim: error: e\nrun: done 1/2"), std::string::npos)
      << text;
  std::fclose(errors);
  std::fclose(log);
}

TEST(Progress, CountsEveryUnitAcrossThreads) {
  std::FILE* f = std::tmpfile();
  RunOutput output(RunOutput::Options{f, false, nullptr});
  Progress::Options options;
  options.output = &output;
  options.heartbeat_s = 0.0;  // every call may print: the lines must stay whole
  Progress progress(8000, "threads", options);
  std::vector<std::thread> workers;
  workers.reserve(8);
  for (int t = 0; t < 8; ++t) {
    workers.emplace_back([&] {
      for (int i = 0; i < 1000; ++i) progress.advance();
    });
  }
  for (auto& w : workers) w.join();
  EXPECT_EQ(progress.done(), 8000U);
  progress.finish();
  const std::string text = contents(f);
  std::size_t start = 0;
  for (std::size_t end = text.find('\n'); end != std::string::npos;
       start = end + 1, end = text.find('\n', start)) {
    EXPECT_EQ(text.compare(start, 8, "threads:"), 0) << text.substr(start, end - start);
  }
  std::fclose(f);
}

}  // namespace
}  // namespace mresim::app
