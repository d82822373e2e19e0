// quoted_text(): file content in messages is escaped and cut short.
#include "core/common/quoted_text.h"

#include <gtest/gtest.h>

namespace lantern {
namespace {

TEST(QuotedText, PrintableTextIsQuotedAsIs) {
  EXPECT_EQ(quoted_text("ITEM: TIMESTEP"), "'ITEM: TIMESTEP'");
  EXPECT_EQ(quoted_text(""), "''");
}

TEST(QuotedText, UnprintableBytesAreEscaped) {
  EXPECT_EQ(quoted_text(std::string("a\x8f\x01\xff", 4)), "'a\\x8f\\x01\\xff'");
  EXPECT_EQ(quoted_text(std::string("a\0b\n\t\r", 6)), "'a\\0b\\n\\t\\r'");
  EXPECT_EQ(quoted_text("it's a\\b"), "'it\\'s a\\\\b'");
}

TEST(QuotedText, LongTextIsCutWithAnEllipsis) {
  EXPECT_EQ(quoted_text("abcdef", 3), "'abc'...");
  EXPECT_EQ(quoted_text("abc", 3), "'abc'");
  EXPECT_EQ(quoted_text(std::string(1000, '\x8f')).size(), 2 + 4 * kQuotedTextLimit + 3);
}

TEST(QuotedText, EscapedTextKeepsPrintableTextAndEscapesTheRest) {
  EXPECT_EQ(escaped_text("plain 'text' \\x"), "plain 'text' \\x");
  EXPECT_EQ(escaped_text(std::string("\x8f\0", 2)), "\\x8f\\0");
}

TEST(QuotedText, NameTextQuotesOnlyUnusualNames) {
  EXPECT_EQ(name_text("xs"), "xs");
  EXPECT_EQ(name_text(std::string("x\x8f", 2)), "'x\\x8f'");
  EXPECT_EQ(name_text(std::string(100, 'n')), "'" + std::string(kQuotedTextLimit, 'n') + "'...");
}

}  // namespace
}  // namespace lantern
