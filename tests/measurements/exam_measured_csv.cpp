// exam_measured_csv — the project's CSV of measured data (docs/design.md, "Measured data (CSV)"), known answers.
//
// A valid file round-trips bit for bit; the accepted variations (BOM, CRLF,
// any column order, trailing blank lines, spaces) read as expected; every bad
// input gives exactly the expected one-line message naming line and column;
// the writer refuses what is not a regular file and leaves nothing behind.
#include "backlash/measurements/measured_record.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

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
using backlash::measurements::testing::read_text;
using backlash::measurements::testing::write_text;

/// The what() of the MeasuredDataError `action` throws, or a description of
/// what happened instead.
template <class Action>
std::string error_of(Action&& action) {
  try {
    action();
  } catch (const MeasuredDataError& error) {
    return error.what();
  } catch (const std::exception& error) {
    return std::string("<not a MeasuredDataError: ") + error.what() + ">";
  }
  return "<no error>";
}

void expect_error(const std::string& actual, const std::string& expected) {
  EXPECT_EQ(actual, expected) << "returned \"" << actual << "\" instead of \"" << expected << "\"";
}

/// A record whose values need all 17 digits, plus -0, subnormals and extremes.
MeasuredRecord tricky_record() {
  const double tiny = std::numeric_limits<double>::denorm_min();
  const double huge = std::numeric_limits<double>::max();
  MeasuredRecord record;
  record.t = {-1e300, -1.0 / 3.0, 0.0, tiny, 2 * tiny, 1e-300, 0.1, 1.0 / 3.0, 1.0, 1.5, 1e22, huge};
  record.theta_out = {0.1, -0.0, tiny, -tiny, std::numeric_limits<double>::min(), huge, -huge, 1.0 / 7.0, std::numbers::pi, 1e-5,
                      123456789.12345678, -2.5e-310};
  record.drive = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, -0.0};
  record.theta_load = std::vector<double>(record.t.size());
  for (std::size_t index = 0; index < record.t.size(); ++index)
    record.theta_load->at(index) = std::nextafter(static_cast<double>(index), 100.0);
  return record;
}

// ------------------------------------------------------------------ valid files

TEST(MeasuredCsv, ValidFileRoundTripsBitForBit) {
  TemporaryFolder folder;
  const MeasuredRecord written = tricky_record();
  const auto file = folder / "record.csv";
  write_measured_csv(written, file);
  const MeasuredRecord read = read_measured_csv(file);
  EXPECT_EQ(read.source, file);
  expect_same_bits(read.t, written.t, "t");
  expect_same_bits(read.theta_out, written.theta_out, "theta_out");
  ASSERT_TRUE(read.drive.has_value()) << "drive returned absent instead of present";
  expect_same_bits(*read.drive, *written.drive, "drive");
  ASSERT_TRUE(read.theta_load.has_value()) << "theta_load returned absent instead of present";
  expect_same_bits(*read.theta_load, *written.theta_load, "theta_load");
  EXPECT_FALSE(read.theta_motor.has_value()) << "theta_motor returned present instead of absent";
  // Writing what was read gives the same bytes again.
  EXPECT_EQ(format_measured_csv(read), read_text(file));
  EXPECT_EQ(folder.entries(), std::vector<std::string>{"record.csv"}) << "the writer left other files behind";
}

TEST(MeasuredCsv, WriterTextIsShortestRoundTripInContractOrder) {
  MeasuredRecord record;
  record.t = {0, 0.001, 0.002};
  record.theta_out = {0.1, -0.0, 1.0 / 3.0};
  record.drive = {1e-7, 2.5, -1e300};
  record.theta_motor = {1, 2, 3};
  const std::string expected =
      "t,theta_out,theta_motor,drive\n"
      "0,0.1,1,1e-07\n"
      "0.001,-0,2,2.5\n"
      "0.002,0.3333333333333333,3,-1e+300\n";
  const std::string actual = format_measured_csv(record);
  EXPECT_EQ(actual, expected) << "returned\n" << actual << "instead of\n" << expected;
}

TEST(MeasuredCsv, AcceptsBomCrlfAnyColumnOrderSpacesAndTrailingBlankLines) {
  std::string text = "\xEF\xBB\xBF" "drive, theta_out ,t\r\n";
  for (int row = 0; row < 10; ++row)
    text += std::to_string(row * 10) + " ,\t+" + std::to_string(row) + ".5, " + std::to_string(row) + "e-3\r\n";
  text += "\r\n\r\n  \r\n";
  const MeasuredRecord record = parse_measured_csv(text, "in-memory.csv");
  ASSERT_EQ(record.size(), 10u) << "returned " << record.size() << " samples instead of 10";
  std::vector<double> t, theta_out, drive;
  for (int row = 0; row < 10; ++row) {
    t.push_back(row / 1000.0);  // what "ROWe-3" reads as: the double nearest to ROW/1000
    theta_out.push_back(row + 0.5);
    drive.push_back(row * 10.0);
  }
  expect_same_bits(record.t, t, "t");
  expect_same_bits(record.theta_out, theta_out, "theta_out");
  ASSERT_TRUE(record.drive.has_value());
  expect_same_bits(*record.drive, drive, "drive");
  EXPECT_FALSE(record.theta_motor || record.theta_load) << "returned optional columns the file does not have";
  EXPECT_EQ(record.source, "in-memory.csv");
}

TEST(MeasuredCsv, MinimumSamplesIsAParameter) {
  const std::string three_rows = "t,theta_out\n0,1\n1,2\n2,3\n";
  CsvReadOptions options;
  options.min_samples = 3;
  EXPECT_EQ(parse_measured_csv(three_rows, "f.csv", options).size(), 3u);
  options.min_samples = 0;
  EXPECT_EQ(parse_measured_csv("t,theta_out\n", "f.csv", options).size(), 0u);
  expect_error(error_of([&] { parse_measured_csv(three_rows, "f.csv"); }),
               "f.csv: too few samples: 3 data rows, at least 10 required");
  options.min_samples = 4;
  expect_error(error_of([&] { parse_measured_csv("t,theta_out\n0,1\n", "f.csv", options); }),
               "f.csv: too few samples: 1 data row, at least 4 required");
}

// ------------------------------------------------------------------ bad files

struct BadInput {
  std::string name;
  std::string text;
  std::string expected;  ///< the message after "FILE"
};

/// Ten valid rows after the header, each "t,theta_out" (t = row/10).
std::string ten_rows(const std::string& header = "t,theta_out") {
  std::string text = header + "\n";
  for (int row = 0; row < 10; ++row) text += std::to_string(row) + "e-1," + std::to_string(row * 2) + "\n";
  return text;
}

/// Ten valid rows (each ending in `more_cells`) with `replacement` as line `line` (2..11).
std::string ten_rows_with(int line, const std::string& replacement, const std::string& header = "t,theta_out",
                          const std::string& more_cells = "") {
  std::string text = header + "\n";
  for (int row = 0; row < 10; ++row)
    text += (row + 2 == line ? replacement : std::to_string(row) + "e-1," + std::to_string(row * 2) + more_cells) + "\n";
  return text;
}

std::vector<BadInput> bad_inputs() {
  const std::string known = "(expected t, theta_out, theta_motor, theta_load, drive)";
  return {
      {"empty file", "", ": empty file: expected a header row naming the columns, e.g. t,theta_out"},
      {"only a BOM and blank lines", "\xEF\xBB\xBF\r\n\n  \n",
       ": empty file: expected a header row naming the columns, e.g. t,theta_out"},
      {"no header", ten_rows("0,1"),
       ":1: no header row: line 1 holds numbers (expected the column names, e.g. t,theta_out)"},
      {"blank first line", ten_rows("\nt,theta_out"),
       ":1: no header row: line 1 is blank (expected the column names, e.g. t,theta_out)"},
      {"missing theta_out", ten_rows("t,drive"), ":1: theta_out: missing required column"},
      {"missing t", ten_rows("theta_out,drive"), ":1: t: missing required column"},
      {"unknown column", ten_rows("t,theta_out,speed"), ":1: speed: unknown column " + known},
      {"semicolons", ten_rows("t;theta_out"), ":1: t;theta_out: unknown column " + known},
      {"control byte in a name", ten_rows("t,theta_out,\x01x"), ":1: \\x01x: unknown column " + known},
      {"duplicate column", ten_rows("t,theta_out,t"), ":1: t: duplicate column (columns 1 and 3)"},
      {"empty column name", ten_rows("t,,theta_out"), ":1: column 2: empty column name"},
      {"too few cells", ten_rows_with(5, "0.3"), ":5: theta_out: missing cell: the row has 1 cell, the header 2"},
      {"too many cells", ten_rows_with(5, "0.3,1,2"), ":5: too many cells: the row has 3 cells, the header 2"},
      {"decimal comma", ten_rows_with(7, "0.5,1,5"), ":7: too many cells: the row has 3 cells, the header 2"},
      {"non-numeric cell", ten_rows_with(4, "0.2,abc"), ":4: theta_out: not a number: 'abc'"},
      {"number with a unit", ten_rows_with(4, "0.2s,1"), ":4: t: not a number: '0.2s'"},
      {"hexadecimal", ten_rows_with(4, "0.2,0x10"), ":4: theta_out: not a number: '0x10'"},
      {"empty cell", ten_rows_with(4, "0.2,"), ":4: theta_out: empty cell"},
      {"NaN", ten_rows_with(4, "0.2,nan"), ":4: theta_out: not finite: 'nan' (NaN and infinities are not allowed)"},
      {"NaN time", ten_rows_with(3, "NaN,1"), ":3: t: not finite: 'NaN' (NaN and infinities are not allowed)"},
      {"infinity", ten_rows_with(6, "0.4,1,-inf", "t,theta_out,drive", ",0"),
       ":6: drive: not finite: '-inf' (NaN and infinities are not allowed)"},
      {"beyond a double", ten_rows_with(6, "0.4,1e999"), ":6: theta_out: number out of the range of a double: '1e999'"},
      {"duplicate time", ten_rows_with(6, "0.3,1"), ":6: t: duplicate time 0.3 (also on line 5); t must be strictly increasing"},
      {"time going back", ten_rows_with(6, "0.25,1"),
       ":6: t: time 0.25 is before 0.3 on line 5; t must be strictly increasing"},
      {"blank line inside", ten_rows_with(4, ""), ":4: blank line inside the data (only blank lines at the end are allowed)"},
      {"too few samples", "t,theta_out\n0,1\n1,2\n2,3\n", ": too few samples: 3 data rows, at least 10 required"},
      {"header only", "t,theta_out\r\n", ": too few samples: 0 data rows, at least 10 required"},
      {"lone carriage returns", "t,theta_out\r0,1\r1,2\r", ":1: theta_out\\x0D0: unknown column " + known},
  };
}

TEST(MeasuredCsv, EachBadInputGivesItsOneLineMessage) {
  TemporaryFolder folder;
  int index = 0;
  for (const BadInput& bad : bad_inputs()) {
    SCOPED_TRACE(bad.name);
    const auto file = folder / ("bad-" + std::to_string(index++) + ".csv");
    write_text(file, bad.text);
    const std::string actual = error_of([&] { read_measured_csv(file); });
    expect_error(actual, file.string() + bad.expected);
    EXPECT_EQ(actual.find_first_of("\r\n"), std::string::npos) << "the message is not one line";
  }
}

TEST(MeasuredCsv, ErrorCarriesFileLineAndColumn) {
  try {
    parse_measured_csv(ten_rows_with(4, "0.2,abc"), "data.csv");
    FAIL() << "returned a record instead of an error";
  } catch (const MeasuredDataError& error) {
    EXPECT_EQ(error.file(), "data.csv");
    EXPECT_EQ(error.line(), 4) << "line() returned " << error.line() << " instead of 4";
    EXPECT_EQ(error.column(), "theta_out") << "column() returned " << error.column() << " instead of theta_out";
    EXPECT_EQ(error.problem(), "not a number: 'abc'");
  }
}

// ------------------------------------------------------------------ files that are not CSV files

TEST(MeasuredCsv, RefusesMissingFilesDirectoriesAndDevices) {
  TemporaryFolder folder;
  expect_error(error_of([&] { read_measured_csv(folder / "absent.csv"); }),
               (folder / "absent.csv").string() + ": cannot read: no such file");
  expect_error(error_of([&] { read_measured_csv(folder.path()); }), folder.path().string() + ": cannot read: it is a directory");

  const auto started = std::chrono::steady_clock::now();
  expect_error(error_of([&] { read_measured_csv("/dev/zero"); }),
               "/dev/zero: cannot read: not a regular file (a character device)");
  const auto fifo = folder / "fifo.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  expect_error(error_of([&] { read_measured_csv(fifo); }), fifo.string() + ": cannot read: not a regular file (a FIFO)");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  EXPECT_LT(seconds, 1.0) << "refusing /dev/zero and a FIFO took " << seconds << " s instead of well under 1 s";
}

TEST(MeasuredCsv, RefusesAFileLargerThanTheCapBeforeReadingIt) {
  TemporaryFolder folder;
  const auto file = folder / "huge.csv";
  {
    // A sparse file one byte over 1 GiB: no disk space used, nothing to read.
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::ftruncate(fd, (off_t{1} << 30) + 1), 0);
    ::close(fd);
  }
  const auto started = std::chrono::steady_clock::now();
  expect_error(error_of([&] { read_measured_csv(file); }),
               file.string() + ": file too large: 1073741825 bytes (the limit is 1073741824 bytes)");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  EXPECT_LT(seconds, 1.0) << "refusing a 1 GiB file took " << seconds << " s: it was read";

  const auto small = folder / "small.csv";
  write_text(small, ten_rows());
  CsvReadOptions options;
  options.max_file_bytes = 20;
  expect_error(error_of([&] { read_measured_csv(small, options); }),
               small.string() + ": file too large: " + std::to_string(ten_rows().size()) + " bytes (the limit is 20 bytes)");
}

// ------------------------------------------------------------------ the writer

MeasuredRecord small_record() {
  MeasuredRecord record;
  for (int index = 0; index < 10; ++index) {
    record.t.push_back(index * 0.5);
    record.theta_out.push_back(index * index);
  }
  return record;
}

TEST(MeasuredCsvWriter, RefusesToReplaceWhatIsNotARegularFile) {
  TemporaryFolder folder;
  const MeasuredRecord record = small_record();
  expect_error(error_of([&] { write_measured_csv(record, "/dev/null"); }),
               "/dev/null: refusing to replace it: not a regular file (a character device)");
  std::filesystem::create_directory(folder / "subfolder");
  expect_error(error_of([&] { write_measured_csv(record, folder / "subfolder"); }),
               (folder / "subfolder").string() + ": refusing to replace it: not a regular file (a directory)");
  write_text(folder / "real.csv", "keep me");
  std::filesystem::create_symlink(folder / "real.csv", folder / "link.csv");
  expect_error(error_of([&] { write_measured_csv(record, folder / "link.csv"); }),
               (folder / "link.csv").string() + ": refusing to replace it: not a regular file (a symbolic link)");
  expect_error(error_of([&] { write_measured_csv(record, folder / "absent" / "out.csv"); }),
               (folder / "absent" / "out.csv").string() + ": cannot write: directory " + (folder / "absent").string() +
                   " does not exist");
  EXPECT_EQ(read_text(folder / "real.csv"), "keep me");
  const std::vector<std::string> expected{"link.csv", "real.csv", "subfolder"};
  EXPECT_EQ(folder.entries(), expected) << "the writer left something behind";
  EXPECT_TRUE(std::filesystem::is_empty(folder / "subfolder"));
}

TEST(MeasuredCsvWriter, RefusesRecordsOutsideTheContractAndWritesNothing) {
  TemporaryFolder folder;
  const auto file = folder / "out.csv";
  MeasuredRecord short_column = small_record();
  short_column.drive = std::vector<double>(9, 1.0);
  expect_error(error_of([&] { write_measured_csv(short_column, file); }),
               file.string() + ": drive: cannot write: has 9 values but t has 10");
  MeasuredRecord not_a_number = small_record();
  not_a_number.theta_out[3] = std::nan("");
  expect_error(error_of([&] { write_measured_csv(not_a_number, file); }),
               file.string() + ": theta_out: cannot write: theta_out[3] is nan, not a finite number");
  MeasuredRecord backwards = small_record();
  backwards.t[4] = backwards.t[3];
  expect_error(error_of([&] { write_measured_csv(backwards, file); }),
               file.string() + ": t: cannot write: not strictly increasing: t[4] = 1.5 after t[3] = 1.5");
  EXPECT_TRUE(folder.entries().empty()) << "the writer left something behind";
}

TEST(MeasuredCsvWriter, ReplacesARegularFileAtomicallyKeepingItsMode) {
  TemporaryFolder folder;
  const auto file = folder / "out.csv";
  write_text(file, "old content");
  ::chmod(file.c_str(), 0640);
  write_measured_csv(small_record(), file);
  EXPECT_EQ(read_text(file), format_measured_csv(small_record()));
  struct stat info {};
  ASSERT_EQ(::stat(file.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0640u) << "mode returned " << std::oct << (info.st_mode & 0777) << " instead of 640";
  EXPECT_EQ(folder.entries(), std::vector<std::string>{"out.csv"});

  const auto fresh = folder / "fresh.csv";
  write_measured_csv(small_record(), fresh);
  ASSERT_EQ(::stat(fresh.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0644u) << "mode returned " << std::oct << (info.st_mode & 0777) << " instead of 644";
}

TEST(MeasuredCsvWriter, WritesIntoTheCurrentFolderForABareName) {
  TemporaryFolder folder;
  const auto previous = std::filesystem::current_path();
  std::filesystem::current_path(folder.path());
  write_measured_csv(small_record(), "bare.csv");
  std::filesystem::current_path(previous);
  EXPECT_EQ(read_measured_csv(folder / "bare.csv").size(), 10u);
}

}  // namespace
