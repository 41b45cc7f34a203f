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

TEST(Progress, FormatsDurations) {
  EXPECT_EQ(format_duration(0.42), "0.4s");
  EXPECT_EQ(format_duration(12.34), "12.3s");
  EXPECT_EQ(format_duration(245), "4m05s");
  EXPECT_EQ(format_duration(2 * 3600 + 3 * 60 + 59), "2h03m");
  EXPECT_EQ(format_duration(-1), "?");
}

TEST(Progress, NonInteractivePrintsOnlyTheFinalLine) {
  std::FILE* f = std::tmpfile();
  {
    Progress progress(10, "sweep", {f, false, 0.0});
    for (int i = 0; i < 10; ++i) progress.advance();
    EXPECT_EQ(contents(f), "");
    progress.finish();
    progress.finish();  // once only
  }
  const std::string text = contents(f);
  EXPECT_EQ(text.rfind("sweep: done 10/10 in ", 0), 0U) << text;
  EXPECT_EQ(text.find('\n'), text.size() - 1);
  std::fclose(f);
}

TEST(Progress, InteractiveRedrawsWithPercentAndEta) {
  std::FILE* f = std::tmpfile();
  Progress progress(4, "loop", {f, true, 0.0});
  progress.advance();
  progress.advance();
  const std::string text = contents(f);
  EXPECT_NE(text.find("\rloop:  50% (2/4)  elapsed "), std::string::npos) << text;
  EXPECT_NE(text.find("ETA "), std::string::npos) << text;
  progress.advance(2);
  progress.finish();
  const std::string final_text = contents(f);
  EXPECT_NE(final_text.find("loop: done 4/4 in "), std::string::npos) << final_text;
  EXPECT_EQ(final_text.back(), '\n');
  std::fclose(f);
}

TEST(Progress, UnknownTotalShowsACount) {
  std::FILE* f = std::tmpfile();
  Progress progress(0, "relax", {f, true, 0.0});
  progress.advance(3);
  EXPECT_NE(contents(f).find("relax: 3 done"), std::string::npos);
  progress.set_total(6);
  progress.advance();
  EXPECT_NE(contents(f).find("relax:  67% (4/6)"), std::string::npos) << contents(f);
  std::fclose(f);
}

TEST(Progress, CountsEveryUnitAcrossThreads) {
  Progress progress(8000, "threads", {nullptr, std::nullopt, 0.5});
  std::vector<std::thread> workers;
  workers.reserve(8);
  for (int t = 0; t < 8; ++t) {
    workers.emplace_back([&] {
      for (int i = 0; i < 1000; ++i) progress.advance();
    });
  }
  for (auto& w : workers) w.join();
  EXPECT_EQ(progress.done(), 8000U);
  progress.finish();  // silent with a null stream
}

}  // namespace
}  // namespace mresim::app
