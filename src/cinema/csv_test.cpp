#include "cinema/csv.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"

using namespace panoptes;
using namespace panoptes::cinema;

TEST(Csv, ParsesQuotedFieldsCrlfAndBom) {
  const auto t = parse_csv("\xEF\xBB\xBFtime,vis,FILE\r\n0.5,\"a, \"\"b\"\"\",x.png\r\n\r\n1.0,\"multi\nline\",y.png", "d.csv");
  ASSERT_EQ(t.header, (std::vector<std::string>{"time", "vis", "FILE"}));
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0][1], "a, \"b\"");
  EXPECT_EQ(t.rows[1][1], "multi\nline");
  EXPECT_EQ(t.lines, (std::vector<int>{2, 4}));
  EXPECT_EQ(t.column("FILE"), 2);
  EXPECT_EQ(t.column("file"), -1);
}

TEST(Csv, RefusesMalformedTables) {
  auto message = [](const char* text) {
    try {
      parse_csv(text, "d.csv");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message("a,b\n1,2,3\n"), "d.csv: line 2 has 3 fields; the header has 2");
  EXPECT_EQ(message("a,b\n\"1,2\n"), "d.csv: line 2: unterminated quoted field");
  EXPECT_EQ(message("a,b\n1\"x\",2\n"), "d.csv: line 2: a quote inside an unquoted field (RFC 4180 quotes whole fields)");
  EXPECT_EQ(message("a,a\n1,2\n"), "d.csv: column name \"a\" appears twice");
  EXPECT_EQ(message(""), "d.csv: empty CSV file; expected a header row");
}

TEST(Csv, WritesFieldsThatReadBack) {
  for (const std::string v : {"plain", "a,b", "say \"hi\"", "two\r\nlines", " padded ", ""}) {
    const auto t = parse_csv("x,y\n" + csv_field(v) + ",1\n", "w.csv");
    ASSERT_EQ(t.rows.size(), 1u) << v;
    EXPECT_EQ(t.rows[0][0], v);
  }
  EXPECT_EQ(csv_field("plain"), "plain");
}

TEST(Csv, FloatsAlwaysHaveADecimalPointAndRoundTrip) {
  EXPECT_EQ(format_float(2), "2.0");
  EXPECT_EQ(format_float(-180), "-180.0");
  EXPECT_EQ(format_float(0.1), "0.1");
  EXPECT_EQ(format_float(1e20), "1e+20");
  for (double v : {0.1, 1.0 / 3, -45.000000001, 123456.789}) {
    double back = 0;
    ASSERT_TRUE(parse_number(format_float(v), back));
    EXPECT_EQ(back, v);
  }
  double x = 0;
  EXPECT_TRUE(parse_number(" 30 ", x));
  EXPECT_EQ(x, 30);
  EXPECT_FALSE(parse_number("30deg", x));
  EXPECT_FALSE(parse_number("", x));
  EXPECT_FALSE(parse_number("nan", x));
}

// Numbers as the export prints them for Cinema viewers: no float or trigonometry noise, exact otherwise.
TEST(Csv, ValuesPrintAsShortestExactDecimals) {
  EXPECT_EQ(format_value(double(0.3f)), "0.3");  // 0.30000001192092896 stored from a float
  EXPECT_EQ(format_value(3.5e-15), "0");         // theta of a camera on the equator, from asin
  EXPECT_EQ(format_value(std::asin(std::sin(30 * M_PI / 180)) * 180 / M_PI), "30");
  EXPECT_EQ(format_value(-180), "-180");
  EXPECT_EQ(format_value(0.1), "0.1");
  for (double v : {1.0 / 3, -45.000000001, 123456.789, 1e-7, 2.5e30}) {
    double back = 0;
    ASSERT_TRUE(parse_number(format_value(v), back)) << v;
    EXPECT_EQ(back, v) << format_value(v);  // values that are neither stay exact
  }
}

