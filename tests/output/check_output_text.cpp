// check_output_text — the text helpers shared by the writers and readers
// (backlash/output/text.hpp): read_number against the rules of the flags and CSV cells,
// toml_string and shell_word on hostile text.
#include "backlash/output/text.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace {

using backlash::output::NumberText;
using backlash::output::read_number;
using backlash::output::shell_word;
using backlash::output::toml_string;

NumberText status(const std::string& text) {
  double value = 0;
  return read_number(text, value);
}

TEST(ReadNumber, ReadsWholeDecimalsCorrectlyRounded) {
  double value = 0;
  ASSERT_EQ(read_number("0.1", value), NumberText::ok);
  EXPECT_EQ(value, 0.1);
  ASSERT_EQ(read_number("+2.5e3", value), NumberText::ok);
  EXPECT_EQ(value, 2500);
  ASSERT_EQ(read_number("-0", value), NumberText::ok);
  EXPECT_TRUE(std::signbit(value));
  ASSERT_EQ(read_number("4.9e-324", value), NumberText::ok) << "a subnormal is read; the caller may refuse it";
  EXPECT_EQ(value, std::numeric_limits<double>::denorm_min());
  ASSERT_EQ(read_number("1.7976931348623157e308", value), NumberText::ok);
  EXPECT_EQ(value, std::numeric_limits<double>::max());
}

TEST(ReadNumber, NamesWhatIsWrong) {
  EXPECT_EQ(status(""), NumberText::empty);
  for (const char* text : {"x", "1x", " 1", "1 ", "+", "++1", "+-1", "1e", "0x1p3", "1,5", "--1"})
    EXPECT_EQ(status(text), NumberText::not_a_number) << text;
  for (const char* text : {"1e400", "-1e400"}) EXPECT_EQ(status(text), NumberText::too_large) << text;
  for (const char* text : {"1e-400", "-1e-400"}) EXPECT_EQ(status(text), NumberText::too_small) << text;
  for (const char* text : {"nan", "inf", "-inf", "+Infinity", "NAN"}) EXPECT_EQ(status(text), NumberText::not_finite) << text;
}

TEST(TomlString, StaysOneValidLine) {
  EXPECT_EQ(toml_string("case V"), "\"case V\"");
  EXPECT_EQ(toml_string("a \"b\" \\c"), "\"a \\\"b\\\" \\\\c\"");
  EXPECT_EQ(toml_string(std::string("x\ny\r\tz\x7f\0w", 10)), "\"xyzw\"");
  EXPECT_EQ(toml_string("θ ≤ 1"), "\"θ ≤ 1\"") << "UTF-8 passes as it is";
}

TEST(ShellWord, QuotesEveryCharacter) {
  EXPECT_EQ(shell_word("/tmp/a b"), "'/tmp/a b'");
  EXPECT_EQ(shell_word("it's $HOME; rm -rf ~"), "'it'\\''s $HOME; rm -rf ~'");
  EXPECT_EQ(shell_word(""), "''");
}

}  // namespace
