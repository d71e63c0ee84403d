// A property-based fuzz of the two loaders of outside text: the case-file reader
// (model::parse_case) and the measured CSV reader (measurements::parse_measured_csv).
// Inputs: valid files mutated byte by byte (flips, insertions, deletions, duplicated and
// swapped lines, hostile tokens spliced in: huge and tiny exponents, NaN, NUL, CR, very long
// lines) and pure random bytes, from fixed seeds — the same inputs on every run.
// Properties, for every input: the reader returns or throws its own error type (CaseFileError,
// MeasuredDataError), never anything else, never crashes; the message is one line, non-empty,
// and starts with the file's name; an accepted case has finite, in-range numbers (inertia and
// gain > 0, friction and backlash ≥ 0); an accepted record has as many values in every column
// as times, every value finite, times strictly increasing.
// Bounded by a count of inputs (no clock): fuzz_inputs per reader (200000; 20000 under sanitizers).
#include "backlash/measurements/measured_record.hpp"
#include "backlash/model/case_spec.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace backlash;

#ifdef BACKLASH_FUZZ_SANITIZED
constexpr int fuzz_inputs = 20000;
#else
constexpr int fuzz_inputs = 200000;
#endif

const std::string valid_case =
    "name = \"Case V\"\nmeasured_at = \"load\"\nK = 1\nbacklash = 0.3\nreference = 1\n"
    "[motor]\nJ = 0.5\nF = 0.1\n[load]\nJ = 0.5\nF = 0.3\n[experiment]\nstep = 0.62\nt_end = 60\n"
    "[effects]\ncoulomb_load = 0.01\nrestitution = 0.2\n";

std::string valid_csv() {
  std::string text = "t,theta_out,drive\n";
  char row[96];
  for (int i = 0; i < 14; ++i) {
    std::snprintf(row, sizeof row, "%.3f,%.6f,%g\n", 0.01 * i, std::sin(0.1 * i), 0.5 * i);
    text += row;
  }
  return text;
}

const std::vector<std::string> hostile_tokens = {
    "1e400", "1e-400", "5e-324", "1e308", "-1e308", "nan", "inf", "-inf", "\"1/0\"", "\"0/0\"", "0x1p3", "1_000",
    "\"", "'", "[", "]", "{", "}", "=", ",", "\n", "\r", "\r\n", std::string(1, '\0'), "\t", "#", "\\u0000",
    "\"\\n\"", "[[x]]", "true", "1979-05-27", "9999999999999999999999", "-0", "+.5", ".", "e5", "1e", "--1",
    std::string(5000, '9'), std::string(300, '['), "\xff\xfe", "θ"};

std::string mutate(std::string text, std::mt19937_64& random) {
  const int edits = 1 + static_cast<int>(random() % 4);
  for (int k = 0; k < edits; ++k) {
    const std::size_t at = text.empty() ? 0 : random() % (text.size() + 1);
    switch (random() % 7) {
      case 0:  // flip a byte
        if (!text.empty()) text[std::min(at, text.size() - 1)] ^= static_cast<char>(1 << (random() % 8));
        break;
      case 1:  // insert a random byte
        text.insert(at, 1, static_cast<char>(random() % 256));
        break;
      case 2:  // delete a run
        if (at < text.size()) text.erase(at, 1 + random() % 8);
        break;
      case 3:  // splice a hostile token
        text.insert(at, hostile_tokens[random() % hostile_tokens.size()]);
        break;
      case 4: {  // replace a number-looking run with a hostile token
        const std::size_t digit = text.find_first_of("0123456789", at);
        if (digit != std::string::npos) {
          const std::size_t end = text.find_first_not_of("0123456789.e-", digit);
          text.replace(digit, (end == std::string::npos ? text.size() : end) - digit,
                       hostile_tokens[random() % hostile_tokens.size()]);
        }
        break;
      }
      case 5: {  // duplicate a line
        const std::size_t begin = text.rfind('\n', at == 0 ? 0 : at - 1);
        const std::size_t from = begin == std::string::npos ? 0 : begin + 1;
        const std::size_t end = text.find('\n', from);
        if (end != std::string::npos) text.insert(end + 1, text.substr(from, end - from + 1));
        break;
      }
      default:  // truncate
        text.resize(at);
        break;
    }
  }
  return text;
}

std::string random_bytes(std::mt19937_64& random) {
  std::string text(random() % 200, '\0');
  for (char& c : text) c = static_cast<char>(random() % 4 == 0 ? "=\n\"[],.0123456789eK"[random() % 19] : random() % 256);
  return text;
}

void expect_one_line_naming(const std::string& message, const std::string& file, const std::string& input) {
  EXPECT_FALSE(message.empty());
  EXPECT_EQ(message.find('\n'), std::string::npos) << "returned a message of several lines instead of one: " << message;
  EXPECT_EQ(message.rfind(file, 0), 0u) << "returned '" << message << "' instead of a message starting with " << file
                                         << "\ninput: " << input;
}

TEST(FuzzCaseLoader, EveryInputIsAcceptedSoundlyOrRefusedInOneLine) {
  std::mt19937_64 random(20261123);
  long accepted = 0, refused = 0;
  for (int i = 0; i < fuzz_inputs; ++i) {
    const std::string input = i % 10 == 9 ? random_bytes(random) : mutate(valid_case, random);
    try {
      const model::CaseSpec spec = model::parse_case(input, "fuzz.toml");
      ++accepted;
      for (const model::Rational* positive : {&spec.Jm, &spec.JL, &spec.K})
        EXPECT_GT(*positive, 0) << "accepted a non-positive inertia or gain:\n" << input;
      for (const model::Rational* non_negative : {&spec.Fm, &spec.FL, &spec.backlash})
        EXPECT_GE(*non_negative, 0) << "accepted a negative friction or backlash:\n" << input;
      for (const model::Rational* number : {&spec.Jm, &spec.Fm, &spec.JL, &spec.FL, &spec.K, &spec.backlash, &spec.reference}) {
        const double value = model::to_double(*number);
        EXPECT_TRUE(std::isfinite(value) && (value == 0 || std::isnormal(value)))
            << "accepted a number double precision cannot hold:\n" << input;
      }
    } catch (const model::CaseFileError& e) {
      ++refused;
      expect_one_line_naming(e.what(), "fuzz.toml", input);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "returned " << typeid(e).name() << " (" << e.what() << ") instead of a CaseFileError\ninput: " << input;
    }
    if (HasFailure()) break;
  }
  std::printf("case loader: %d inputs, %ld accepted, %ld refused\n", fuzz_inputs, accepted, refused);
  EXPECT_GT(accepted, 0);
  EXPECT_GT(refused, 0);
}

TEST(FuzzMeasuredCsv, EveryInputIsAcceptedSoundlyOrRefusedInOneLine) {
  std::mt19937_64 random(4181);
  const std::string base = valid_csv();
  long accepted = 0, refused = 0;
  for (int i = 0; i < fuzz_inputs; ++i) {
    const std::string input = i % 10 == 9 ? random_bytes(random) : mutate(base, random);
    try {
      const measurements::MeasuredRecord r = measurements::parse_measured_csv(input, "fuzz.csv");
      ++accepted;
      ASSERT_GE(r.t.size(), 10u);
      for (std::size_t k = 0; k < r.t.size(); ++k) {
        EXPECT_TRUE(std::isfinite(r.t[k]));
        if (k > 0) {
          EXPECT_GT(r.t[k], r.t[k - 1]) << "accepted times not increasing:\n" << input;
        }
      }
      ASSERT_EQ(r.theta_out.size(), r.t.size());
      for (double v : r.theta_out) EXPECT_TRUE(std::isfinite(v)) << input;
    } catch (const measurements::MeasuredDataError& e) {
      ++refused;
      expect_one_line_naming(e.what(), "fuzz.csv", input);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "returned " << typeid(e).name() << " (" << e.what() << ") instead of a MeasuredDataError\ninput: " << input;
    }
    if (HasFailure()) break;
  }
  std::printf("measured CSV reader: %d inputs, %ld accepted, %ld refused\n", fuzz_inputs, accepted, refused);
  EXPECT_GT(accepted, 0);
  EXPECT_GT(refused, 0);
}

}  // namespace
