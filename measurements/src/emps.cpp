// EMPS benchmark records through matio (backlash/measurements/emps.hpp).
#include "backlash/measurements/emps.hpp"

#include "file_access.hpp"

#include <fmt/format.h>

#include <matio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <memory>
#include <mutex>
#include <string>

namespace backlash::measurements {

namespace {

using detail::shortest;

/// Largest number of elements of one variable (2^27 doubles = 1 GiB): a
/// compressed variable cannot make the reader allocate without bound.
constexpr std::size_t largest_variable_elements = std::size_t{1} << 27;

// ------------------------------------------------------------------ matio's log

/// matio's diagnostics since the last take_matio_messages(), this thread.
thread_local std::string matio_messages;

void capture_matio_message(int log_level, char* message) {
  if ((log_level & (MATIO_LOG_LEVEL_ERROR | MATIO_LOG_LEVEL_CRITICAL | MATIO_LOG_LEVEL_WARNING)) == 0) return;
  if (message == nullptr) return;
  if (!matio_messages.empty()) matio_messages += "; ";
  matio_messages += message;
}

/// Routes matio's log to capture_matio_message (matio prints to stderr by default).
void install_quiet_matio_log() {
  static std::once_flag installed;
  std::call_once(installed, [] { Mat_LogInitFunc("backlash", capture_matio_message); });
}

std::string take_matio_messages() {
  std::string taken = detail::printable(matio_messages, 160);
  matio_messages.clear();
  return taken;
}

// ------------------------------------------------------------------ matio handles

struct MatCloser {
  void operator()(mat_t* mat) const { Mat_Close(mat); }
};
struct VarFreer {
  void operator()(matvar_t* variable) const { Mat_VarFree(variable); }
};
using MatFile = std::unique_ptr<mat_t, MatCloser>;
using MatVariable = std::unique_ptr<matvar_t, VarFreer>;

const char* describe_class(matio_classes class_type) {
  switch (class_type) {
    case MAT_C_EMPTY: return "an empty array";
    case MAT_C_CELL: return "a cell array";
    case MAT_C_STRUCT: return "a struct";
    case MAT_C_OBJECT: return "an object";
    case MAT_C_CHAR: return "a char array";
    case MAT_C_SPARSE: return "a sparse matrix";
    case MAT_C_FUNCTION: return "a function handle";
    case MAT_C_OPAQUE: return "an opaque object";
    default: return "of an unknown class";
  }
}

bool is_numeric_class(matio_classes class_type) {
  switch (class_type) {
    case MAT_C_DOUBLE: case MAT_C_SINGLE:
    case MAT_C_INT8: case MAT_C_UINT8: case MAT_C_INT16: case MAT_C_UINT16:
    case MAT_C_INT32: case MAT_C_UINT32: case MAT_C_INT64: case MAT_C_UINT64:
      return true;
    default:
      return false;
  }
}

template <class Element>
void convert(const void* data, std::size_t count, std::vector<double>& out) {
  const auto* elements = static_cast<const Element*>(data);
  out.resize(count);
  for (std::size_t index = 0; index < count; ++index) out[index] = static_cast<double>(elements[index]);
}

/// Reads the EMPS variables of one open file, checking each.
class EmpsReader {
 public:
  EmpsReader(mat_t* mat, std::filesystem::path file) : mat_(mat), file_(std::move(file)) {}

  EmpsRecord read() {
    EmpsRecord record;
    record.source = file_;
    record.t = series("t", 0);
    if (record.t.size() < 2) fail("t", fmt::format("{} sample{}, at least 2 required", record.t.size(),
                                                   record.t.size() == 1 ? "" : "s"));
    for (std::size_t index = 1; index < record.t.size(); ++index)
      if (!(record.t[index] > record.t[index - 1]))
        fail("t", fmt::format("not strictly increasing: t({}) = {} after t({}) = {}", index + 1,
                              shortest(record.t[index]), index, shortest(record.t[index - 1])));
    const std::size_t count = record.t.size();
    record.qm = series("qm", count, &record.t);
    record.qg = series("qg", count, &record.t);
    record.vir = series("vir", count, &record.t);
    if (has_variable("pulses_N")) record.pulses_N = series("pulses_N", count, &record.t);
    record.gtau = scalar("gtau");
    if (record.gtau == 0) fail("gtau", "is 0: the drive force gtau*vir would vanish");
    record.kp = scalar("kp");
    record.kv = scalar("kv");
    return record;
  }

 private:
  [[noreturn]] void fail(const std::string& variable, const std::string& problem) const {
    throw MeasuredDataError(file_, 0, variable, problem);
  }

  bool has_variable(const char* name) {
    MatVariable info(Mat_VarReadInfo(mat_, name));
    take_matio_messages();
    return info != nullptr;
  }

  /// The variable's header, checked: present, numeric, real, at most
  /// largest_variable_elements elements.  Returns the element count.
  std::size_t checked_info(const char* name, std::size_t& rows, std::size_t& columns, int& rank) {
    MatVariable info(Mat_VarReadInfo(mat_, name));
    if (!info) {
      const std::string messages = take_matio_messages();
      if (!messages.empty()) fail("", "cannot read: the file is truncated or corrupt (matio: " + messages + ")");
      fail(name, "missing variable (the file has: " + variable_names() + ")");
    }
    if (info->isLogical) fail(name, "logical, expected numeric values");
    if (!is_numeric_class(info->class_type))
      fail(name, fmt::format("not numeric: it is {}", describe_class(info->class_type)));
    if (info->isComplex) fail(name, "complex, expected real numbers");
    rank = info->rank;
    std::size_t elements = 1;
    for (int axis = 0; axis < info->rank; ++axis) {
      const std::size_t extent = info->dims[axis];
      if (extent != 0 && elements > largest_variable_elements / extent)
        fail(name, fmt::format("too large: more than {} elements", largest_variable_elements));
      elements *= extent;
    }
    if (elements > largest_variable_elements)
      fail(name, fmt::format("too large: {} elements, at most {}", elements, largest_variable_elements));
    rows = info->rank >= 1 ? info->dims[0] : 0;
    columns = info->rank >= 2 ? info->dims[1] : 1;
    return elements;
  }

  std::string shape(const char* name) {
    MatVariable info(Mat_VarReadInfo(mat_, name));
    take_matio_messages();
    if (!info) return "?";
    std::string text;
    for (int axis = 0; axis < info->rank; ++axis) {
      if (axis > 0) text += 'x';
      text += std::to_string(info->dims[axis]);
    }
    return text;
  }

  std::vector<double> values(const char* name, std::size_t elements) {
    MatVariable variable(Mat_VarRead(mat_, name));
    if (!variable || (elements > 0 && variable->data == nullptr)) {
      const std::string messages = take_matio_messages();
      fail(name, "cannot read its data" + (messages.empty() ? std::string() : " (matio: " + messages + ")"));
    }
    take_matio_messages();
    if (variable->data_size <= 0 || variable->nbytes / static_cast<std::size_t>(variable->data_size) < elements)
      fail(name, "cannot read its data (matio returned fewer values than its dimensions)");
    std::vector<double> out;
    const void* data = variable->data;
    switch (variable->data_type) {
      case MAT_T_DOUBLE: convert<double>(data, elements, out); break;
      case MAT_T_SINGLE: convert<float>(data, elements, out); break;
      case MAT_T_INT8: convert<std::int8_t>(data, elements, out); break;
      case MAT_T_UINT8: convert<std::uint8_t>(data, elements, out); break;
      case MAT_T_INT16: convert<std::int16_t>(data, elements, out); break;
      case MAT_T_UINT16: convert<std::uint16_t>(data, elements, out); break;
      case MAT_T_INT32: convert<std::int32_t>(data, elements, out); break;
      case MAT_T_UINT32: convert<std::uint32_t>(data, elements, out); break;
      case MAT_T_INT64: convert<std::int64_t>(data, elements, out); break;
      case MAT_T_UINT64: convert<std::uint64_t>(data, elements, out); break;
      default: fail(name, fmt::format("unsupported element type {} in matio", static_cast<int>(variable->data_type)));
    }
    return out;
  }

  /// A vector variable (N×1 or 1×N); `expected` > 0 demands that many samples.
  std::vector<double> series(const char* name, std::size_t expected, const std::vector<double>* times = nullptr) {
    std::size_t rows = 0, columns = 0;
    int rank = 0;
    const std::size_t elements = checked_info(name, rows, columns, rank);
    if (rank > 2 || (rows != 1 && columns != 1))
      fail(name, "not a vector: it is " + shape(name) + " (expected Nx1 or 1xN)");
    if (expected > 0 && elements != expected)
      fail(name, fmt::format("{} samples, but t has {}", elements, expected));
    std::vector<double> out = values(name, elements);
    for (std::size_t index = 0; index < out.size(); ++index)
      if (!std::isfinite(out[index]))
        fail(name, fmt::format("{}({}) is {}{}: not finite", name, index + 1, std::isnan(out[index]) ? "NaN" : shortest(out[index]),
                               times ? " (t = " + shortest((*times)[index]) + " s)" : std::string()));
    return out;
  }

  double scalar(const char* name) {
    std::size_t rows = 0, columns = 0;
    int rank = 0;
    const std::size_t elements = checked_info(name, rows, columns, rank);
    if (elements != 1) fail(name, "not a scalar: it is " + shape(name));
    const double value = values(name, 1).front();
    if (!std::isfinite(value)) fail(name, fmt::format("is {}: not finite", std::isnan(value) ? "NaN" : shortest(value)));
    return value;
  }

  std::string variable_names() {
    std::size_t count = 0;
    char** names = Mat_GetDir(mat_, &count);
    take_matio_messages();
    if (names == nullptr || count == 0) return "no variables";
    std::vector<std::string> sorted;
    for (std::size_t index = 0; index < count && index < 20; ++index)
      if (names[index] != nullptr) sorted.push_back(detail::printable(names[index], 30));
    std::sort(sorted.begin(), sorted.end());
    std::string text;
    for (const std::string& one : sorted) text += (text.empty() ? "" : ", ") + one;
    if (count > 20) text += ", ...";
    return text;
  }

  mat_t* mat_;
  std::filesystem::path file_;
};

// ------------------------------------------------------------------ the v5 file's extent

std::uint32_t read_u32(const unsigned char* bytes, bool swapped) {
  const std::uint32_t value = static_cast<std::uint32_t>(bytes[0]) | static_cast<std::uint32_t>(bytes[1]) << 8 |
                              static_cast<std::uint32_t>(bytes[2]) << 16 | static_cast<std::uint32_t>(bytes[3]) << 24;
  return swapped ? __builtin_bswap32(value) : value;
}

/// A MATLAB v5 file is a 128-byte header and a sequence of data elements, each an 8-byte tag
/// (type, byte count) and that many bytes (a compressed variable is one element).  matio reads
/// a variable cut short by the end of the file as zeros (a truncated zlib stream inflates
/// without complaint), so every element's extent is checked against the file first: an
/// element reaching past the end is a truncated file, refused.
void require_whole_v5_elements(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  in.seekg(0, std::ios::end);
  const auto size = static_cast<std::uint64_t>(std::max<std::streamoff>(0, in.tellg()));
  unsigned char header[128];
  in.seekg(0);
  if (size < 128 || !in.read(reinterpret_cast<char*>(header), 128)) return;  // matio has refused such a file already
  const bool swapped = header[126] == 'M' && header[127] == 'I';
  std::uint64_t at = 128;
  for (int element = 1; at + 8 <= size; ++element) {
    unsigned char tag[8];
    in.seekg(static_cast<std::streamoff>(at));
    if (!in.read(reinterpret_cast<char*>(tag), 8)) break;
    const std::uint32_t type = read_u32(tag, swapped), bytes = read_u32(tag + 4, swapped);
    if ((type >> 16) != 0) {  // the small-element form: type and up to 4 bytes in the tag itself
      at += 8;
      continue;
    }
    if (bytes > size - at - 8)
      throw MeasuredDataError(file, 0, "",
                              fmt::format("cannot read: the file is truncated or corrupt (data element {} at byte {} "
                                          "declares {} bytes, the file ends {} bytes short of it)",
                                          element, at, bytes, bytes - (size - at - 8)));
    at += 8 + bytes;
  }
}

}  // namespace

EmpsRecord read_emps(const std::filesystem::path& file, std::uintmax_t max_file_bytes) {
  detail::require_readable_regular_file(file, max_file_bytes);
  install_quiet_matio_log();
  take_matio_messages();
  MatFile mat(Mat_Open(file.c_str(), MAT_ACC_RDONLY));
  take_matio_messages();
  if (!mat) throw MeasuredDataError(file, 0, "", "not a MATLAB .mat file");
  const mat_ft version = Mat_GetVersion(mat.get());
  if (version != MAT_FT_MAT5 && version != MAT_FT_MAT73)
    throw MeasuredDataError(file, 0, "", "not a MATLAB v5 or v7.3 .mat file (EMPS records are v5)");
  if (version == MAT_FT_MAT5) require_whole_v5_elements(file);
  return EmpsReader(mat.get(), file).read();
}

EmpsPulses emps_pulses_in_vir(const EmpsRecord& record) {
  if (!record.pulses_N) return EmpsPulses::none;
  const std::vector<double>& pulses = *record.pulses_N;
  const std::vector<double>& vir = record.vir;
  if (pulses.size() != vir.size())
    throw MeasuredDataError(record.source, 0, "pulses_N",
                            fmt::format("{} samples, but vir has {}", pulses.size(), vir.size()));
  std::size_t edges = 0, contained = 0, added = 0;
  for (std::size_t k = 1; k < pulses.size(); ++k) {
    const double step = pulses[k] - pulses[k - 1];
    if (step == 0) continue;
    ++edges;
    const double vir_step = vir[k] - vir[k - 1];
    if (std::abs(vir_step - step) <= std::abs(step) / 4) ++contained;
    if (std::abs(record.gtau * vir_step) <= std::abs(step) / 4) ++added;
  }
  const bool all_zero = std::all_of(pulses.begin(), pulses.end(), [](double value) { return value == 0; });
  if (edges == 0 && all_zero) return EmpsPulses::none;
  if (edges == 0)
    throw MeasuredDataError(record.source, 0, "pulses_N",
                            "constant and not zero: without an edge the data cannot tell whether it is already in vir");
  if (edges > 0 && contained == edges && added == 0) return EmpsPulses::contained;
  if (edges > 0 && added == edges && contained == 0) return EmpsPulses::added;
  throw MeasuredDataError(
      record.source, 0, "pulses_N",
      fmt::format("cannot tell from the data whether the pulses are already in vir: of {} edges, vir steps with {} "
                  "(as contained) and stays put at {} (as added on top)",
                  edges, contained, added));
}

std::vector<double> emps_drive_force(const EmpsRecord& record) {
  const EmpsPulses pulses = emps_pulses_in_vir(record);
  std::vector<double> force(record.vir.size());
  for (std::size_t index = 0; index < force.size(); ++index) force[index] = record.gtau * record.vir[index];
  if (pulses == EmpsPulses::added)
    for (std::size_t index = 0; index < force.size(); ++index) force[index] += (*record.pulses_N)[index];
  return force;
}

MeasuredRecord to_measured_record(const EmpsRecord& record) {
  MeasuredRecord measured;
  measured.t = record.t;
  measured.theta_out = record.qm;
  measured.drive = emps_drive_force(record);
  measured.source = record.source;
  return measured;
}

const char* to_string(EmpsPulses pulses) {
  switch (pulses) {
    case EmpsPulses::none: return "none";
    case EmpsPulses::contained: return "contained";
    case EmpsPulses::added: return "added";
  }
  return "?";
}

}  // namespace backlash::measurements
