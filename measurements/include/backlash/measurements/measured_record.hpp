// backlash/measurements/measured_record.hpp — the project's CSV of measured data.
//
// Contract (docs/design.md, "Measured data (CSV)"): a header row naming
// the columns; `t` and `theta_out` (the measured shaft) required, `theta_motor`,
// `theta_load` and `drive` optional, in any order (`theta_out` may be left out of a logged
// drive's record, one with `theta_motor` and `drive`: then theta_out is empty); `t` strictly increasing; every
// cell a finite number.  Anything else is a MeasuredDataError whose what() is
// one line, "FILE:LINE: COLUMN: problem" (LINE and COLUMN left out where they do
// not apply), in the spirit of the case-file loader (model/case_spec.hpp).
//
// Accepted on input: a UTF-8 byte order mark, CRLF line endings, blank lines
// at the end of the file, spaces or tabs around a cell, a leading '+' on a
// number.  Numbers are read with std::from_chars (correctly rounded) and
// written in the shortest form that reads back to the same double, so
// write → read returns the record bit for bit (also -0 and subnormals).
//
// Units are the record's own: the EMPS import (emps.hpp) writes metres and
// newtons, a rotary drive would have radians and N·m.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace backlash::measurements {

/// One measured record: a time series with the columns of the CSV contract.
struct MeasuredRecord {
  std::vector<double> t;                         ///< time [s], strictly increasing
  std::vector<double> theta_out;                 ///< the measured shaft (empty: left out of a logged drive's record)
  std::optional<std::vector<double>> theta_motor;
  std::optional<std::vector<double>> theta_load;
  std::optional<std::vector<double>> drive;      ///< drive torque/force applied to the mechanism
  std::filesystem::path source;                  ///< file it was read from (empty if built in memory)

  std::size_t size() const { return t.size(); }
};

/// Bad measured data (CSV or .mat).  what() is one line:
///   "FILE:LINE: COLUMN: problem"   (CSV; LINE 1-based)
///   "FILE: VARIABLE: problem"      (.mat records: line() is 0, column() the variable)
/// LINE is left out when line() is 0, COLUMN when column() is empty.
class MeasuredDataError : public std::runtime_error {
 public:
  MeasuredDataError(std::filesystem::path file, long line, std::string column, const std::string& problem);
  const std::filesystem::path& file() const { return file_; }
  long line() const { return line_; }
  const std::string& column() const { return column_; }
  const std::string& problem() const { return problem_; }

 private:
  std::filesystem::path file_;
  long line_;
  std::string column_;
  std::string problem_;
};

/// Input files larger than this are refused before they are read.
inline constexpr std::uintmax_t default_max_file_bytes = std::uintmax_t{1} << 30;  // 1 GiB

struct CsvReadOptions {
  std::size_t min_samples = 10;                         ///< fewer data rows → error naming the file
  std::uintmax_t max_file_bytes = default_max_file_bytes;
};

/// The largest size of a sample the workflows compute with (docs/design.md, "Measured data
/// (CSV)"): the case files' own bound (model/case_spec.hpp), so that sums of squares over a
/// record stay finite doubles.  The CSV contract itself holds any finite number.
inline constexpr double largest_computable_sample = 1e100;

/// The error naming sample `index` (0-based) of `column`: "FILE:LINE: COLUMN: problem" for a
/// record from CSV text (LINE = index + 2, the header being line 1), "FILE: COLUMN: sample
/// N: problem" (N 1-based) for one read from a .mat file.
MeasuredDataError sample_error(const MeasuredRecord& record, std::size_t index, const std::string& column,
                               const std::string& problem);

/// Throws sample_error for the first sample (any column, `t` included) larger in size than
/// largest_computable_sample: such a record is bad input to a workflow, not a computation.
void require_computable(const MeasuredRecord& record);

/// The column names of the contract, in the order the writer uses.
const std::vector<std::string>& measured_csv_columns();

/// Strict reader.  Errors (all MeasuredDataError): no such file, a directory or
/// anything but a regular file (e.g. /dev/zero, a FIFO — refused without reading),
/// a file larger than options.max_file_bytes, an empty file, no header row
/// (line 1 blank or numeric), an unknown, empty or duplicate column name, a
/// missing `t` or `theta_out`, a row with too few or too many cells, an empty
/// or non-numeric cell, NaN or an infinity, a number beyond the range of a
/// double, a time not after the previous one, a blank line followed by more
/// data, fewer than options.min_samples rows.
MeasuredRecord read_measured_csv(const std::filesystem::path& file, const CsvReadOptions& options = {});

/// The same reader on text already in memory; `file` only names it in messages
/// and becomes the record's source (max_file_bytes is not applied).
MeasuredRecord parse_measured_csv(std::string_view text, const std::filesystem::path& file,
                                  const CsvReadOptions& options = {});

/// The record as CSV text: header, then one row per sample, columns in the
/// order of measured_csv_columns() (absent optional columns left out), '\n'
/// line endings, numbers in their shortest round-trip form.  The record must
/// satisfy the contract apart from the minimum number of samples: every column
/// as long as `t`, all values finite, `t` strictly increasing — otherwise
/// MeasuredDataError (file empty, line 0, the column named).
std::string format_measured_csv(const MeasuredRecord& record);

/// Writes format_measured_csv(record) to `target` atomically: into a unique
/// temporary file in target's directory, flushed to disk, then renamed over
/// `target`.  Refuses (MeasuredDataError naming `target`) to replace anything
/// that is not a regular file — a directory, a device such as /dev/null, a
/// symbolic link — and a directory that does not exist.  A write that fails (a full disk,
/// a folder it may not write in) is output::OutputError (write_failed: exit 1, not bad
/// input), what() "TARGET: cannot write: …".  On any failure the
/// temporary file is removed and an existing `target` is left untouched.
/// A new file gets mode 0644, a replaced one keeps its permission bits.
void write_measured_csv(const MeasuredRecord& record, const std::filesystem::path& target);

}  // namespace backlash::measurements
