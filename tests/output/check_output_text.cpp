// check_output_text — the text helpers shared by the writers and readers
// (backlash/output/text.hpp): read_number against the rules of the flags and CSV cells,
// printf_g against printf itself on random doubles, toml_string and shell_word on hostile text.
#include "backlash/output/text.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <limits>
#include <string>

namespace {

using backlash::output::NumberText;
using backlash::output::printf_g;
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

std::string printf_text(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", digits, value);
  return text;
}

// Random bit patterns (every exponent: subnormals, huge values, inf and nan), values on a decimal
// grid (where rounding ties to the printed digit sit), and small integers, at every precision:
// printf_g writes printf's bytes.
TEST(PrintfG, WritesPrintfsBytes) {
  std::mt19937_64 random(20261128);
  std::uniform_int_distribution<int> precision(1, 17);
  long compared = 0;
  for (int k = 0; k < 300000; ++k) {
    double value = 0;
    const std::uint64_t bits = random();
    switch (k % 3) {
      case 0: std::memcpy(&value, &bits, sizeof value); break;
      case 1: value = static_cast<double>(static_cast<std::int64_t>(bits % 2000001) - 1000000) / 1000.0; break;
      default: value = std::ldexp(static_cast<double>(bits >> 40), static_cast<int>(bits % 64) - 32); break;
    }
    const int digits = k % 5 == 0 ? 10 : precision(random);
    ASSERT_EQ(printf_g(value, digits), printf_text(value, digits)) << "digits " << digits << " bits " << bits;
    ++compared;
  }
  for (const double value : {0.0, -0.0, 1e-5, 1e-4, 0.5, 1e15, 1e16, 1e17, 123456789.5, 0.30000000000000004,
                             std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::max(),
                             std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                             std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::quiet_NaN()})
    for (int digits = 1; digits <= 17; ++digits) EXPECT_EQ(printf_g(value, digits), printf_text(value, digits)) << value;
  EXPECT_EQ(compared, 300000);
  EXPECT_THROW(printf_g(1.0, 0), std::invalid_argument);
  EXPECT_THROW(printf_g(1.0, 18), std::invalid_argument);
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
