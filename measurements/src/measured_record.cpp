// The project's CSV of measured data: strict reader, exact writer
// (backlash/measurements/measured_record.hpp).
#include "backlash/measurements/measured_record.hpp"

#include "file_access.hpp"

#include "backlash/output/text.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <system_error>
#include <utility>

namespace backlash::measurements {

namespace {

using detail::printable;
using detail::quoted;
using detail::shortest;

// ------------------------------------------------------------------ columns

constexpr std::size_t column_count = 5;
constexpr std::array<std::string_view, column_count> column_names{"t", "theta_out", "theta_motor", "theta_load",
                                                                   "drive"};
constexpr std::size_t t_index = 0;
constexpr std::size_t theta_out_index = 1;

constexpr std::string_view known_columns_text = "t, theta_out, theta_motor, theta_load, drive";

std::optional<std::size_t> column_index(std::string_view name) {
  for (std::size_t index = 0; index < column_count; ++index)
    if (column_names[index] == name) return index;
  return std::nullopt;
}

/// The record's vector for column `index` (creating an optional one).
std::vector<double>& column_values(MeasuredRecord& record, std::size_t index) {
  switch (index) {
    case 0: return record.t;
    case 1: return record.theta_out;
    case 2: return record.theta_motor.emplace();
    case 3: return record.theta_load.emplace();
    default: return record.drive.emplace();
  }
}

/// The record's columns present, in writing order, with their names.
std::vector<std::pair<std::string_view, const std::vector<double>*>> present_columns(const MeasuredRecord& record) {
  std::vector<std::pair<std::string_view, const std::vector<double>*>> columns{{column_names[0], &record.t}};
  if (!record.theta_out.empty() || !record.theta_motor || !record.drive)  // left out only in a logged drive's record
    columns.emplace_back(column_names[1], &record.theta_out);
  if (record.theta_motor) columns.emplace_back(column_names[2], &*record.theta_motor);
  if (record.theta_load) columns.emplace_back(column_names[3], &*record.theta_load);
  if (record.drive) columns.emplace_back(column_names[4], &*record.drive);
  return columns;
}

// ------------------------------------------------------------------ text

std::string_view trim(std::string_view text) {
  const auto is_space = [](char character) { return character == ' ' || character == '\t'; };
  while (!text.empty() && is_space(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_space(text.back())) text.remove_suffix(1);
  return text;
}

/// The cells of one line, split at every comma and trimmed.
void split_cells(std::string_view line, std::vector<std::string_view>& cells) {
  cells.clear();
  for (;;) {
    const std::size_t comma = line.find(',');
    cells.push_back(trim(line.substr(0, comma)));
    if (comma == std::string_view::npos) return;
    line.remove_prefix(comma + 1);
  }
}

/// Walks the text line by line ('\n', a trailing '\r' dropped), counting from 1.
class Lines {
 public:
  explicit Lines(std::string_view text) : rest_(text) {}

  /// The next line, or false at the end.  A final '\n' ends the last line
  /// (it does not start an empty one).
  bool next(std::string_view& line) {
    if (finished_) return false;
    const std::size_t newline = rest_.find('\n');
    if (newline == std::string_view::npos) {
      line = rest_;
      finished_ = true;
      if (line.empty()) return false;
    } else {
      line = rest_.substr(0, newline);
      rest_.remove_prefix(newline + 1);
      if (rest_.empty()) finished_ = true;
    }
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    ++number_;
    return true;
  }

  long number() const { return number_; }

 private:
  std::string_view rest_;
  long number_ = 0;
  bool finished_ = false;
};

std::string count_of_cells(std::size_t count) { return fmt::format("{} cell{}", count, count == 1 ? "" : "s"); }

// ------------------------------------------------------------------ numbers

enum class NumberStatus { ok, empty, not_a_number, out_of_range, not_finite };

/// A whole (trimmed) cell as a double, correctly rounded (backlash/output/text.hpp).
NumberStatus parse_number(std::string_view cell, double& value) {
  switch (output::read_number(cell, value)) {
    case output::NumberText::ok: return NumberStatus::ok;
    case output::NumberText::empty: return NumberStatus::empty;
    case output::NumberText::not_a_number: return NumberStatus::not_a_number;
    case output::NumberText::too_large:
    case output::NumberText::too_small: return NumberStatus::out_of_range;
    case output::NumberText::not_finite: return NumberStatus::not_finite;
  }
  return NumberStatus::not_a_number;
}

bool looks_numeric(std::string_view cell) {
  double ignored = 0;
  const NumberStatus status = parse_number(cell, ignored);
  return status == NumberStatus::ok || status == NumberStatus::out_of_range || status == NumberStatus::not_finite;
}

void append_number(std::string& out, double value) {
  char buffer[32];
  const std::to_chars_result result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

// ------------------------------------------------------------------ reader

class CsvReader {
 public:
  CsvReader(std::string_view text, std::filesystem::path file, const CsvReadOptions& options)
      : text_(text), file_(std::move(file)), options_(options) {}

  MeasuredRecord read() {
    constexpr std::string_view byte_order_mark = "\xEF\xBB\xBF";
    if (text_.substr(0, byte_order_mark.size()) == byte_order_mark) text_.remove_prefix(byte_order_mark.size());
    if (trim_all_blank(text_).empty())
      fail(0, "", "empty file: expected a header row naming the columns, e.g. t,theta_out");

    Lines lines(text_);
    std::string_view line;
    lines.next(line);
    read_header(line);

    MeasuredRecord record;
    record.source = file_;
    std::vector<std::vector<double>*> destination;  // per file column
    for (const std::size_t index : header_) destination.push_back(&column_values(record, index));

    std::vector<std::string_view> cells;
    long first_blank_line = 0;
    long previous_time_line = 0;
    while (lines.next(line)) {
      if (trim(line).empty()) {
        if (first_blank_line == 0) first_blank_line = lines.number();
        continue;
      }
      if (first_blank_line != 0)
        fail(first_blank_line, "", "blank line inside the data (only blank lines at the end are allowed)");
      const long number = lines.number();
      split_cells(line, cells);
      if (cells.size() < header_.size())
        fail(number, std::string(column_names[header_[cells.size()]]),
             fmt::format("missing cell: the row has {}, the header {}", count_of_cells(cells.size()), header_.size()));
      if (cells.size() > header_.size())
        fail(number, "",
             fmt::format("too many cells: the row has {}, the header {}", count_of_cells(cells.size()), header_.size()));
      for (std::size_t position = 0; position < cells.size(); ++position) {
        double value = 0;
        const std::string name(column_names[header_[position]]);
        switch (parse_number(cells[position], value)) {
          case NumberStatus::ok: break;
          case NumberStatus::empty: fail(number, name, "empty cell");
          case NumberStatus::not_a_number: fail(number, name, "not a number: " + quoted(cells[position]));
          case NumberStatus::out_of_range:
            fail(number, name, "number out of the range of a double: " + quoted(cells[position]));
          case NumberStatus::not_finite:
            fail(number, name, "not finite: " + quoted(cells[position]) + " (NaN and infinities are not allowed)");
        }
        destination[position]->push_back(value);
      }
      const std::vector<double>& times = record.t;
      if (times.size() >= 2) {
        const double now = times[times.size() - 1];
        const double before = times[times.size() - 2];
        if (now == before)
          fail(number, "t",
               fmt::format("duplicate time {} (also on line {}); t must be strictly increasing", shortest(now),
                           previous_time_line));
        if (now < before)
          fail(number, "t",
               fmt::format("time {} is before {} on line {}; t must be strictly increasing", shortest(now),
                           shortest(before), previous_time_line));
      }
      previous_time_line = number;
    }
    if (record.t.size() < options_.min_samples)
      fail(0, "",
           fmt::format("too few samples: {} data row{}, at least {} required", record.t.size(),
                       record.t.size() == 1 ? "" : "s", options_.min_samples));
    return record;
  }

 private:
  [[noreturn]] void fail(long line, std::string column, const std::string& problem) const {
    throw MeasuredDataError(file_, line, std::move(column), problem);
  }

  static std::string_view trim_all_blank(std::string_view text) {
    const std::size_t first = text.find_first_not_of(" \t\r\n");
    return first == std::string_view::npos ? std::string_view{} : text.substr(first);
  }

  void read_header(std::string_view line) {
    if (trim(line).empty())
      fail(1, "", "no header row: line 1 is blank (expected the column names, e.g. t,theta_out)");
    std::vector<std::string_view> cells;
    split_cells(line, cells);
    if (std::all_of(cells.begin(), cells.end(), looks_numeric))
      fail(1, "", "no header row: line 1 holds numbers (expected the column names, e.g. t,theta_out)");
    std::array<std::size_t, column_count> position_of{};  // 1-based position in the file, 0 = absent
    for (std::size_t position = 0; position < cells.size(); ++position) {
      const std::string_view name = cells[position];
      if (name.empty()) fail(1, fmt::format("column {}", position + 1), "empty column name");
      const std::optional<std::size_t> index = column_index(name);
      if (!index) fail(1, printable(name), fmt::format("unknown column (expected {})", known_columns_text));
      if (position_of[*index] != 0)
        fail(1, std::string(name), fmt::format("duplicate column (columns {} and {})", position_of[*index], position + 1));
      position_of[*index] = position + 1;
      header_.push_back(*index);
    }
    // theta_out may be left out of a logged drive's record (theta_motor and drive present): the
    // measured-drive workflow on a drive with a gap reads the encoders themselves.
    const bool logged_drive = position_of[2] != 0 && position_of[4] != 0;
    for (const std::size_t required : {t_index, theta_out_index})
      if (position_of[required] == 0 && !(required == theta_out_index && logged_drive))
        fail(1, std::string(column_names[required]), "missing required column");
  }

  std::string_view text_;
  std::filesystem::path file_;
  CsvReadOptions options_;
  std::vector<std::size_t> header_;  // column index of each file column, in file order
};

// ------------------------------------------------------------------ writer checks

void check_writable(const MeasuredRecord& record, const std::filesystem::path& file) {
  const auto fail = [&](std::string_view column, const std::string& problem) {
    throw MeasuredDataError(file, 0, std::string(column), "cannot write: " + problem);
  };
  for (const auto& [name, values] : present_columns(record)) {
    if (values->size() != record.t.size())
      fail(name, fmt::format("has {} values but t has {}", values->size(), record.t.size()));
    for (std::size_t index = 0; index < values->size(); ++index)
      if (!std::isfinite((*values)[index]))
        fail(name, fmt::format("{}[{}] is {}, not a finite number", name, index, shortest((*values)[index])));
  }
  for (std::size_t index = 1; index < record.t.size(); ++index)
    if (!(record.t[index] > record.t[index - 1]))
      fail("t", fmt::format("not strictly increasing: t[{}] = {} after t[{}] = {}", index, shortest(record.t[index]),
                            index - 1, shortest(record.t[index - 1])));
}

std::string format_error(const std::filesystem::path& file, long line, const std::string& column,
                         const std::string& problem) {
  std::string message;
  if (!file.empty()) {
    message += file.string();
    if (line > 0) message += fmt::format(":{}", line);
    message += ": ";
  } else if (line > 0) {
    message += fmt::format("line {}: ", line);
  }
  if (!column.empty()) message += column + ": ";
  message += problem;
  std::replace(message.begin(), message.end(), '\n', ' ');
  std::replace(message.begin(), message.end(), '\r', ' ');
  return message;
}

}  // namespace

// ------------------------------------------------------------------ public API

MeasuredDataError::MeasuredDataError(std::filesystem::path file, long line, std::string column,
                                     const std::string& problem)
    : std::runtime_error(format_error(file, line, column, problem)),
      file_(std::move(file)),
      line_(line),
      column_(std::move(column)),
      problem_(problem) {}

const std::vector<std::string>& measured_csv_columns() {
  static const std::vector<std::string> names(column_names.begin(), column_names.end());
  return names;
}

MeasuredRecord parse_measured_csv(std::string_view text, const std::filesystem::path& file,
                                  const CsvReadOptions& options) {
  return CsvReader(text, file, options).read();
}

MeasuredRecord read_measured_csv(const std::filesystem::path& file, const CsvReadOptions& options) {
  const std::string text = detail::read_regular_file(file, options.max_file_bytes);
  return parse_measured_csv(text, file, options);
}

std::string format_measured_csv(const MeasuredRecord& record) {
  check_writable(record, {});
  const auto columns = present_columns(record);
  std::string out;
  out.reserve(32 + record.t.size() * columns.size() * 24);
  for (std::size_t position = 0; position < columns.size(); ++position) {
    if (position > 0) out += ',';
    out += columns[position].first;
  }
  out += '\n';
  for (std::size_t row = 0; row < record.t.size(); ++row) {
    for (std::size_t position = 0; position < columns.size(); ++position) {
      if (position > 0) out += ',';
      append_number(out, (*columns[position].second)[row]);
    }
    out += '\n';
  }
  return out;
}

void write_measured_csv(const MeasuredRecord& record, const std::filesystem::path& target) {
  check_writable(record, target);
  detail::write_file_atomically(target, format_measured_csv(record));
}

MeasuredDataError sample_error(const MeasuredRecord& record, std::size_t index, const std::string& column,
                               const std::string& problem) {
  if (record.source.extension() == ".mat")
    return MeasuredDataError(record.source, 0, column, fmt::format("sample {}: {}", index + 1, problem));
  return MeasuredDataError(record.source, static_cast<long>(index) + 2, column, problem);
}

void require_computable(const MeasuredRecord& record) {
  for (const auto& [name, values] : present_columns(record))
    for (std::size_t index = 0; index < values->size(); ++index)
      if (!(std::fabs((*values)[index]) <= largest_computable_sample))
        throw sample_error(record, index, std::string(name),
                           fmt::format("{} is larger in size than {}, the largest sample the workflows compute with",
                                       shortest((*values)[index]), shortest(largest_computable_sample)));
}

}  // namespace backlash::measurements
