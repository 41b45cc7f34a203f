#include "mresim/app/info_report.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace mresim::app {
namespace {

InfoReport sample() {
  InfoReport report;
  report.add_text("run", "type", "pair_hysteresis");
  report.add_text("run", "title", "a long title that has no note");
  report.add_integer("run", "threads", 0, "", "0 = all cores");
  report.add("model", "k", 0.04, "N/m", "spring stiffness");
  report.add("model", "S0", 6e-6, "m");
  report.add_integer("field", "steps", 401);
  report.add("model", "h_threshold", 1.0 / 3.0, "", "eq. 2.10");
  return report;
}

TEST(InfoReport, TextGroupsSectionsInOrderAndAlignsColumns) {
  EXPECT_EQ(sample().to_text(),
            "[run]\n"
            "  type     pair_hysteresis\n"
            "  title    a long title that has no note\n"
            "  threads  0  0 = all cores\n"
            "\n"
            "[model]\n"
            "  k            0.04 N/m  spring stiffness\n"
            "  S0           6e-06 m\n"
            "  h_threshold  0.333333  eq. 2.10\n"
            "\n"
            "[field]\n"
            "  steps  401\n");
}

TEST(InfoReport, JsonKeepsFullPrecisionAndTypes) {
  const auto json = sample().to_json();
  EXPECT_EQ(json["run"]["type"]["value"], "pair_hysteresis");
  EXPECT_EQ(json["model"]["k"]["unit"], "N/m");
  EXPECT_EQ(json["model"]["k"]["note"], "spring stiffness");
  EXPECT_EQ(json["model"]["h_threshold"]["value"].get<double>(), 1.0 / 3.0);
  EXPECT_TRUE(json["field"]["steps"]["value"].is_number_integer());
  EXPECT_EQ(json["field"]["steps"]["value"].get<int>(), 401);
}

TEST(InfoReport, RejectsDuplicateKeys) {
  InfoReport report;
  report.add("model", "k", 1.0, "N/m");
  EXPECT_THROW(report.add("model", "k", 2.0, "N/m"), std::logic_error);
  EXPECT_NO_THROW(report.add("other", "k", 2.0, "N/m"));
}

}  // namespace
}  // namespace mresim::app
