// mini_md's command line: every numeric option goes through one table of ranges, so NaN,
// infinity and out-of-range values fail alike, with the option, the value and the range named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli.h"
#include "md_error.h"

namespace mini_md {
namespace {

// The MdError message of parsing `mini_md option value`, "" if it parsed.
std::string parse_error(const std::string &option, const std::string &value) {
  const char *argv[] = {"mini_md", option.c_str(), value.c_str()};
  try {
    parse_command_line(3, argv);
  } catch (const MdError &e) {
    return e.what();
  }
  return "";
}

std::string real_text(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

// Values just outside the option's range, plus what is never a valid number.
std::vector<std::string> invalid_values(const NumericOption &o) {
  std::vector<std::string> values = {"nan", "inf", "-inf", "", "abc", "1x"};
  if (o.integer()) {
    values.push_back("2.5");
    values.push_back(std::to_string(static_cast<long long>(o.min) - (o.min_exclusive ? 0 : 1)));
    values.push_back(std::to_string(static_cast<long long>(o.max) + 1));
    values.push_back("99999999999999999999");  // beyond int64: strtoll saturates
  } else {
    values.push_back(o.min_exclusive ? real_text(o.min) : real_text(o.min - 1e-9));
    values.push_back(std::isinf(o.max) ? "1e999" : real_text(o.max * (1 + 1e-9)));
  }
  return values;
}

TEST(MiniMdCliRanges, EveryNumericOptionRejectsInvalidValuesNamingOptionValueAndRange) {
  ASSERT_EQ(numeric_options().size(), 18u);
  for (const NumericOption &o : numeric_options()) {
    for (const std::string &value : invalid_values(o)) {
      const std::string msg = parse_error(o.name, value);
      ASSERT_FALSE(msg.empty()) << o.name << " accepted '" << value << "'";
      EXPECT_EQ(msg.rfind(o.name + " must be ", 0), 0u) << msg;
      EXPECT_NE(msg.find(range_text(o)), std::string::npos) << msg;
      EXPECT_NE(msg.find("got '" + value + "'"), std::string::npos) << msg;
    }
  }
}

TEST(MiniMdCliRanges, EveryNumericOptionAcceptsItsBounds) {
  for (const NumericOption &o : numeric_options()) {
    std::vector<std::string> values;
    if (!o.min_exclusive) values.push_back(real_text(o.min));
    if (!std::isinf(o.max)) values.push_back(real_text(o.max));
    values.push_back(o.integer() ? "1" : "0.5");  // inside every range
    if (o.integer()) {
      for (std::string &v : values) v = std::to_string(std::stoll(v));
    }
    for (const std::string &value : values) {
      EXPECT_EQ(parse_error(o.name, value), "") << o.name << " " << value;
    }
  }
}

// Bad values that were accepted before, then failing later with NaN in the message.
TEST(MiniMdCliRanges, FormerlyAcceptedCasesAreRejectedAtParseTime) {
  EXPECT_EQ(parse_error("--temp", "-1"), "--temp must be a number in [0, 10000], got '-1'");
  EXPECT_EQ(parse_error("--temp", "nan"), "--temp must be a number in [0, 10000], got 'nan'");
  EXPECT_EQ(parse_error("--density", "nan"), "--density must be a number in (0, 10], got 'nan'");
  EXPECT_EQ(parse_error("--density", "-1"), "--density must be a number in (0, 10], got '-1'");
  EXPECT_EQ(parse_error("--impact-speed", "nan"),
            "--impact-speed must be a number in [0, 1000], got 'nan'");
  EXPECT_EQ(parse_error("--dt", "nan"), "--dt must be a number in (0, 1], got 'nan'");
  EXPECT_EQ(parse_error("--cutoff", "nan"), "--cutoff must be a number in (0, 100], got 'nan'");
  EXPECT_EQ(parse_error("--blowup-energy", "inf"),
            "--blowup-energy must be a number in (0, inf), got 'inf'");
  // An int option used to be cast after parsing: 2^32 + 3 cells became 3.
  EXPECT_EQ(parse_error("--cells", "4294967299"),
            "--cells must be an integer in [1, 10000], got '4294967299'");
}

TEST(MiniMdCliRanges, ValuesReachTheirFields) {
  const char *argv[] = {"mini_md",
                        "--temp",
                        "0",
                        "--seed",
                        "123456789012345678",
                        "--blowup-energy",
                        "1e308",
                        "--sweep-time",
                        "0.25",
                        "--thermo",
                        "0"};
  const CommandLine cl = parse_command_line(11, argv);
  EXPECT_EQ(*cl.run.temperature, 0.0);
  EXPECT_EQ(cl.run.seed, 123456789012345678ull);  // exact: integers are never doubles
  EXPECT_EQ(cl.run.blowup_energy, 1e308);
  EXPECT_EQ(cl.sweep_time, 0.25);
  EXPECT_EQ(cl.run.thermo_every, 0);
}

// Every option --help shows with a numeric argument is in the table and the other way round,
// so a new numeric option cannot bypass the ranges.
TEST(MiniMdCliRanges, HelpAndTableListTheSameNumericOptions) {
  const std::set<std::string> not_numeric = {"lattice|void_impact|droplet|random", "yes|no", "XYZ",
                                             "CONFIG", "FILE"};
  std::set<std::string> from_help, from_table;
  std::istringstream lines(usage_text());
  // "  --option META   text": the argument follows the option after one space; a description
  // (e.g. "--dt-sweep           NVE ...") after several.
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string option;
    words >> option;
    const size_t after = line.find(option) + option.size();
    if (option.rfind("--", 0) != 0 || line.compare(after, 1, " ") != 0 ||
        line.compare(after + 1, 1, " ") == 0) {
      continue;
    }
    std::string argument;
    words >> argument;
    if (!not_numeric.count(argument)) from_help.insert(option);
  }
  for (const NumericOption &o : numeric_options()) from_table.insert(o.name);
  EXPECT_EQ(from_help, from_table);
}

}  // namespace
}  // namespace mini_md
