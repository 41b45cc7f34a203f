#include "mresim/io/csv_writer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "../support/temp_dir.hpp"

namespace mresim::io {
namespace {

using mresim::testing::read_text;
using mresim::testing::TempDir;

TEST(CsvWriter, WritesHeaderAndTenSignificantDigits) {
  const TempDir dir;
  const auto file = dir / "summary.csv";
  {
    CsvWriter csv(file, {"B_T", "M_over_Ms"});
    csv.row({0.1, 1.0 / 3.0});
    csv.row({-2.5e-7, 123456789012.0});
    csv.row({std::numeric_limits<double>::quiet_NaN(), HUGE_VAL});
    EXPECT_EQ(csv.rows_written(), 3U);
    csv.close();
  }
  EXPECT_EQ(read_text(file),
            "B_T,M_over_Ms\n"
            "0.1,0.3333333333\n"
            "-2.5e-07,1.23456789e+11\n"
            "nan,inf\n");
}

TEST(CsvWriter, MixedRowsQuoteTextOnlyWhenNeeded) {
  const TempDir dir;
  const auto file = dir / "mixed.csv";
  {
    CsvWriter csv(file, {"label", "value", "note, with comma"});
    csv.row_cells({std::string("tanh"), 1.5, std::string("say \"hi\"")});
    csv.row_cells({std::string("two\nlines"), 2.0, std::string(" padded")});
  }
  EXPECT_EQ(read_text(file),
            "label,value,\"note, with comma\"\n"
            "tanh,1.5,\"say \"\"hi\"\"\"\n"
            "\"two\nlines\",2,\" padded\"\n");
}

TEST(CsvWriter, ChecksRowSize) {
  const TempDir dir;
  CsvWriter csv(dir / "s.csv", {"a", "b"});
  try {
    csv.row({1.0});
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "CSV file '" + (dir / "s.csv").string() + "': row has 1 values, expected 2 columns");
  }
  EXPECT_THROW(csv.row_cells({1.0, 2.0, 3.0}), std::invalid_argument);
}

TEST(CsvWriter, ReportsAnUnwritableFile) {
  EXPECT_THROW(CsvWriter("/nonexistent/dir/x.csv", {"a"}), std::runtime_error);
}

}  // namespace
}  // namespace mresim::io
