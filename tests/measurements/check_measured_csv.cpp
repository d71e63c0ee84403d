// check_measured_csv — properties of the project's CSV reader and writer.
//
// Random valid records (random sample rates and start times, random optional
// columns, values from the whole range of finite doubles including -0 and
// subnormals) round-trip bit for bit, through the writer and through text
// written by hand in a random column order and style.  Random bytes and
// mutated valid files never crash or hang the reader: each gives either a
// record that satisfies the contract or a one-line MeasuredDataError.
// Fixed seeds: every run checks the same inputs.
#include "backlash/measurements/measured_record.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <typeinfo>
#include <vector>

namespace {

using backlash::measurements::CsvReadOptions;
using backlash::measurements::MeasuredDataError;
using backlash::measurements::MeasuredRecord;
using backlash::measurements::format_measured_csv;
using backlash::measurements::parse_measured_csv;
using backlash::measurements::read_measured_csv;
using backlash::measurements::write_measured_csv;
using backlash::measurements::testing::TemporaryFolder;
using backlash::measurements::testing::expect_same_bits;
using backlash::measurements::testing::write_text;

using Random = std::mt19937_64;

double uniform(Random& random, double low, double high) { return std::uniform_real_distribution<double>(low, high)(random); }

std::size_t below(Random& random, std::size_t bound) { return static_cast<std::size_t>(random() % bound); }

/// A finite double from all over the range: random bit patterns, ±0,
/// subnormals, ordinary magnitudes, small integers.
double random_value(Random& random) {
  switch (below(random, 6)) {
    case 0:
      for (;;) {
        const double value = std::bit_cast<double>(static_cast<std::uint64_t>(random()));
        if (std::isfinite(value)) return value;
      }
    case 1: return below(random, 2) ? 0.0 : -0.0;
    case 2: return std::bit_cast<double>((static_cast<std::uint64_t>(random()) & 0x800FFFFFFFFFFFFFull));  // subnormal
    case 3: return uniform(random, -1, 1) * std::pow(10.0, static_cast<double>(below(random, 41)) - 20);
    case 4: return static_cast<double>(static_cast<long>(below(random, 2001)) - 1000);
    default: return uniform(random, -10, 10);
  }
}

/// A valid record: 10..300 samples at 0.1 Hz .. 1 MHz (jittered), random start,
/// each optional column present or not.
MeasuredRecord random_record(Random& random) {
  MeasuredRecord record;
  const std::size_t samples = 10 + below(random, 291);
  const double rate = std::pow(10.0, uniform(random, -1, 6));
  double time = below(random, 4) == 0 ? 0.0 : uniform(random, -1e3, 1e3);
  for (std::size_t index = 0; index < samples; ++index) {
    if (index > 0) {
      double next = time + (1.0 / rate) * uniform(random, 0.6, 1.4);
      if (!(next > time)) next = std::nextafter(time, HUGE_VAL);
      time = next;
    }
    record.t.push_back(time);
  }
  const auto column = [&] {
    std::vector<double> values(samples);
    for (double& value : values) value = random_value(random);
    return values;
  };
  record.theta_out = column();
  if (below(random, 2)) record.theta_motor = column();
  if (below(random, 2)) record.theta_load = column();
  if (below(random, 2)) record.drive = column();
  return record;
}

void expect_same_record(const MeasuredRecord& actual, const MeasuredRecord& expected) {
  expect_same_bits(actual.t, expected.t, "t");
  expect_same_bits(actual.theta_out, expected.theta_out, "theta_out");
  const auto optional_column = [](const std::optional<std::vector<double>>& got,
                                  const std::optional<std::vector<double>>& want, const char* name) {
    if (got.has_value() != want.has_value()) {
      ADD_FAILURE() << name << " returned " << (got ? "present" : "absent") << " instead of "
                    << (want ? "present" : "absent");
      return;
    }
    if (got) expect_same_bits(*got, *want, name);
  };
  optional_column(actual.theta_motor, expected.theta_motor, "theta_motor");
  optional_column(actual.theta_load, expected.theta_load, "theta_load");
  optional_column(actual.drive, expected.drive, "drive");
}

/// The record as CSV written "by hand": columns in a random order, numbers as
/// %.17g or shortest, random '+' signs, spaces, CRLF, BOM, trailing blank lines.
std::string hand_written_csv(const MeasuredRecord& record, Random& random) {
  std::vector<std::pair<std::string, const std::vector<double>*>> columns{{"t", &record.t},
                                                                          {"theta_out", &record.theta_out}};
  if (record.theta_motor) columns.emplace_back("theta_motor", &*record.theta_motor);
  if (record.theta_load) columns.emplace_back("theta_load", &*record.theta_load);
  if (record.drive) columns.emplace_back("drive", &*record.drive);
  std::shuffle(columns.begin(), columns.end(), random);
  const std::string newline = below(random, 2) ? "\r\n" : "\n";
  const bool spaces = below(random, 3) == 0;
  const bool percent_g = below(random, 2);
  std::string text = below(random, 3) == 0 ? "\xEF\xBB\xBF" : "";
  for (std::size_t position = 0; position < columns.size(); ++position)
    text += (position ? "," : "") + std::string(spaces ? " " : "") + columns[position].first;
  text += newline;
  char buffer[64];
  for (std::size_t row = 0; row < record.t.size(); ++row) {
    for (std::size_t position = 0; position < columns.size(); ++position) {
      const double value = (*columns[position].second)[row];
      if (position) text += ',';
      if (spaces) text += "\t";
      if (value > 0 && below(random, 8) == 0) text += '+';
      if (percent_g) {
        std::snprintf(buffer, sizeof buffer, "%.17g", value);
        text += buffer;
      } else {
        const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
        text.append(buffer, result.ptr);
      }
      if (spaces) text += ' ';
    }
    text += newline;
  }
  for (std::size_t blank = below(random, 3); blank > 0; --blank) text += newline;
  return text;
}

TEST(MeasuredCsvProperty, RandomRecordsRoundTripThroughTheWriter) {
  Random random(20240611);
  TemporaryFolder folder;
  for (int trial = 0; trial < 200; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const MeasuredRecord record = random_record(random);
    MeasuredRecord read;
    if (trial % 10 == 0) {
      const auto file = folder / "record.csv";
      write_measured_csv(record, file);
      read = read_measured_csv(file);
    } else {
      read = parse_measured_csv(format_measured_csv(record), "record.csv");
    }
    expect_same_record(read, record);
    if (HasFailure()) break;
  }
  EXPECT_EQ(folder.entries().size(), 1u);
}

TEST(MeasuredCsvProperty, RandomRecordsInAnyColumnOrderAndStyleReadExactly) {
  Random random(77031);
  for (int trial = 0; trial < 300; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const MeasuredRecord record = random_record(random);
    const std::string text = hand_written_csv(record, random);
    MeasuredRecord read;
    try {
      read = parse_measured_csv(text, "hand.csv");
    } catch (const MeasuredDataError& error) {
      ADD_FAILURE() << "returned the error \"" << error.what() << "\" instead of a record";
      break;
    }
    expect_same_record(read, record);
    if (HasFailure()) break;
  }
}

// ------------------------------------------------------------------ robustness

std::string random_bytes(Random& random) {
  static const std::string csv_alphabet = "0123456789,,,,\n\n\r..--+eEnaifNIt_ \t";
  std::string text;
  const std::size_t length = below(random, 400);
  const bool csv_like = below(random, 2);
  for (std::size_t index = 0; index < length; ++index)
    text += csv_like && below(random, 8) != 0 ? csv_alphabet[below(random, csv_alphabet.size())]
                                              : static_cast<char>(random() & 0xFF);
  return text;
}

std::string mutated(std::string text, Random& random) {
  static const std::vector<std::string> tokens{",", "\n", "\r\n", "\r", "nan", "inf", "-", "+", "e", "1e999", "1e-400",
                                               "\xEF\xBB\xBF", "0", " ", "t", "theta_out", "drive", "theta_motor",
                                               std::string(1, '\0'), "\xFF", "0x1p3", "..", "1,2"};
  for (std::size_t mutations = 1 + below(random, 4); mutations > 0; --mutations) {
    const std::size_t at = text.empty() ? 0 : below(random, text.size() + 1);
    switch (below(random, 6)) {
      case 0:
        if (!text.empty()) text[std::min(at, text.size() - 1)] = static_cast<char>(random() & 0xFF);
        break;
      case 1: text.insert(at, tokens[below(random, tokens.size())]); break;
      case 2: text.erase(at, below(random, 20)); break;
      case 3: text.resize(at); break;
      case 4: {  // duplicate a line
        const std::size_t start = text.rfind('\n', at == 0 ? 0 : at - 1);
        const std::size_t from = start == std::string::npos ? 0 : start + 1;
        const std::size_t end = text.find('\n', from);
        const std::string line = text.substr(from, end == std::string::npos ? std::string::npos : end - from + 1);
        text.insert(from, line);
        break;
      }
      default: {  // swap two characters
        if (text.size() >= 2) std::swap(text[below(random, text.size())], text[below(random, text.size())]);
        break;
      }
    }
  }
  return text;
}

std::string escaped(const std::string& text) {
  std::string out;
  char buffer[8];
  for (const char character : text) {
    const auto byte = static_cast<unsigned char>(character);
    if (byte >= 0x20 && byte < 0x7F && character != '\\') {
      out += character;
    } else {
      std::snprintf(buffer, sizeof buffer, "\\x%02X", byte);
      out += buffer;
    }
  }
  return out;
}

enum class Outcome { record, error, violation };

/// Checks one input: a record that satisfies the contract, or a one-line
/// MeasuredDataError naming the file and a line inside it (a violation is
/// reported as a test failure).
Outcome record_or_error(const std::string& text, const CsvReadOptions& options) {
  try {
    const MeasuredRecord record = parse_measured_csv(text, "fuzz.csv", options);
    bool fine = record.size() >= options.min_samples && record.theta_out.size() == record.size();
    for (const auto* column : {&record.theta_motor, &record.theta_load, &record.drive})
      if (*column) fine = fine && (*column)->size() == record.size();
    for (std::size_t index = 0; index < record.size(); ++index) {
      fine = fine && std::isfinite(record.t[index]) && std::isfinite(record.theta_out[index]);
      if (index > 0) fine = fine && record.t[index] > record.t[index - 1];
    }
    if (!fine) ADD_FAILURE() << "returned a record outside the contract instead of an error, for \"" << escaped(text) << "\"";
    return fine ? Outcome::record : Outcome::violation;
  } catch (const MeasuredDataError& error) {
    const std::string message = error.what();
    const long lines = static_cast<long>(std::count(text.begin(), text.end(), '\n')) + 1;
    const bool fine = message.rfind("fuzz.csv", 0) == 0 && message.find_first_of("\r\n") == std::string::npos &&
                      error.line() >= 0 && error.line() <= lines;
    if (!fine)
      ADD_FAILURE() << "returned the malformed error \"" << escaped(message) << "\" (line " << error.line()
                    << ") instead of one line naming fuzz.csv and a line <= " << lines << ", for \"" << escaped(text)
                    << "\"";
    return fine ? Outcome::error : Outcome::violation;
  } catch (const std::exception& other) {
    ADD_FAILURE() << "returned a " << typeid(other).name() << " (\"" << other.what()
                  << "\") instead of a record or a MeasuredDataError, for \"" << escaped(text) << "\"";
    return Outcome::violation;
  }
}

TEST(MeasuredCsvRobustness, RandomBytesAndMutatedFilesGiveARecordOrAnError) {
  Random random(1789);
  TemporaryFolder folder;
  const auto started = std::chrono::steady_clock::now();
  int records = 0, errors = 0;
  constexpr int inputs = 20000;
  for (int trial = 0; trial < inputs; ++trial) {
    std::string text;
    if (trial % 4 == 0) {
      text = random_bytes(random);
    } else {
      MeasuredRecord record = random_record(random);
      record.t.resize(std::min<std::size_t>(record.t.size(), 12));
      for (auto* column : {&record.theta_out})
        column->resize(record.t.size());
      for (auto* column : {&record.theta_motor, &record.theta_load, &record.drive})
        if (*column) (*column)->resize(record.t.size());
      text = mutated(trial % 2 ? format_measured_csv(record) : hand_written_csv(record, random), random);
    }
    CsvReadOptions options;
    options.min_samples = below(random, 12);
    const Outcome outcome = record_or_error(text, options);
    if (outcome == Outcome::violation) break;
    ++(outcome == Outcome::record ? records : errors);
    if (trial % 500 == 0) {  // the same through a file
      const auto file = folder / "fuzz.csv";
      write_text(file, text);
      std::string from_text, from_file;
      try {
        parse_measured_csv(text, file, options);
      } catch (const MeasuredDataError& error) {
        from_text = error.what();
      }
      try {
        read_measured_csv(file, options);
      } catch (const MeasuredDataError& error) {
        from_file = error.what();
      }
      EXPECT_EQ(from_file, from_text) << "reading the file returned \"" << from_file << "\" instead of \"" << from_text << "\"";
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  EXPECT_LT(seconds, 60.0) << inputs << " inputs took " << seconds << " s: something is far too slow";
  // Both outcomes must occur, or the generator tests only one side.
  EXPECT_GT(records, inputs / 50) << "returned " << records << " records instead of a fair share";
  EXPECT_GT(errors, inputs / 50) << "returned " << errors << " errors instead of a fair share";
  std::printf("robustness: %d inputs, %d records, %d errors, %.2f s\n", inputs, records, errors, seconds);
}

}  // namespace
