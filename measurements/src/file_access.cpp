// Guarded file access for backlash_measurements (POSIX: open/fstat; the writing through the
// output layer, backlash/output/atomic_file.hpp).  Every failure is a one-line
// MeasuredDataError naming the file.
#include "file_access.hpp"

#include "backlash/measurements/measured_record.hpp"
#include "backlash/output/atomic_file.hpp"
#include "backlash/output/output_error.hpp"
#include "backlash/output/target.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace backlash::measurements::detail {

namespace {

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& problem) {
  throw MeasuredDataError(file, 0, "", problem);
}

std::string errno_text(int error_number) { return std::strerror(error_number); }


void check_metadata(const std::filesystem::path& file, const struct stat& info, std::uintmax_t max_bytes) {
  if (S_ISDIR(info.st_mode)) fail(file, "cannot read: it is a directory");
  if (!S_ISREG(info.st_mode))
    fail(file, fmt::format("cannot read: not a regular file ({})", output::describe_file_type(info.st_mode)));
  const auto size = static_cast<std::uintmax_t>(info.st_size);
  if (size > max_bytes)
    fail(file, fmt::format("file too large: {} bytes (the limit is {} bytes)", size, max_bytes));
}

/// Closes a descriptor when it goes out of scope.
class Descriptor {
 public:
  explicit Descriptor(int fd) : fd_(fd) {}
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  ~Descriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

void require_readable_regular_file(const std::filesystem::path& file, std::uintmax_t max_bytes) {
  struct stat info {};
  if (::stat(file.c_str(), &info) != 0) {
    const int error_number = errno;
    if (error_number == ENOENT) fail(file, "cannot read: no such file");
    fail(file, "cannot read: " + errno_text(error_number));
  }
  check_metadata(file, info, max_bytes);
  if (::access(file.c_str(), R_OK) != 0) fail(file, "cannot read: " + errno_text(errno));
}

std::string read_regular_file(const std::filesystem::path& file, std::uintmax_t max_bytes) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer; fstat then refuses it.
  Descriptor fd(::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK));
  if (fd.get() < 0) {
    const int error_number = errno;
    if (error_number == ENOENT) fail(file, "cannot read: no such file");
    fail(file, "cannot read: " + errno_text(error_number));
  }
  struct stat info {};
  if (::fstat(fd.get(), &info) != 0) fail(file, "cannot read: " + errno_text(errno));
  check_metadata(file, info, max_bytes);

  std::string content;
  content.resize(static_cast<std::size_t>(info.st_size));
  std::size_t filled = 0;
  for (;;) {
    if (filled == content.size()) {
      // The file may have grown since fstat: keep reading, within the limit.
      if (content.size() >= max_bytes + 1) break;
      const std::uintmax_t grown = std::min<std::uintmax_t>(max_bytes + 1, content.size() + 65536);
      content.resize(static_cast<std::size_t>(grown));
    }
    const ssize_t count = ::read(fd.get(), content.data() + filled, content.size() - filled);
    if (count < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      fail(file, "cannot read: " + errno_text(errno));
    }
    if (count == 0) break;
    filled += static_cast<std::size_t>(count);
  }
  if (filled > max_bytes)
    fail(file, fmt::format("file too large: more than {} bytes (the limit)", max_bytes));
  content.resize(filled);
  return content;
}

namespace {

/// The output layer's refusal or failure in this library's words ("cannot write: …").
std::string write_problem(const output::OutputError& error) {
  const std::string& detail = error.detail();
  switch (error.problem()) {
    case output::Problem::empty_name: return "cannot write: empty file name";
    case output::Problem::not_a_name: return "cannot write: not a file name";
    case output::Problem::is_directory:
    case output::Problem::is_symlink:
    case output::Problem::not_regular: return "refusing to replace it: not a regular file (" + detail + ")";
    case output::Problem::folder_missing: return "cannot write: directory " + detail + " does not exist";
    case output::Problem::folder_not_directory: return "cannot write: " + detail + " is not a directory";
    case output::Problem::create_failed: return "cannot write: cannot create a temporary file: " + detail;
    case output::Problem::inspect_failed:
    case output::Problem::folder_unreadable:
    case output::Problem::write_failed:
    case output::Problem::move_failed: return "cannot write: " + detail;
    default: return std::string("cannot write: ") + error.what();
  }
}

}  // namespace

void write_file_atomically(const std::filesystem::path& target, std::string_view content) {
  try {
    output::write_atomically(target, content);
  } catch (const output::OutputError& error) {
    // A failed write (a full disk, a permission) is no bad input: it stays an OutputError of its
    // kind (exit 1), worded as this library words it; a bad target is bad input (exit 2).
    if (error.kind() == output::OutputError::Kind::write_failed)
      throw output::OutputError(error.kind(), error.problem(), target, error.detail(),
                                target.string() + ": " + write_problem(error));
    fail(target, write_problem(error));
  }
}

std::string printable(std::string_view text, std::size_t max_characters) {
  std::string out;
  std::size_t shown = 0;
  for (const char character : text) {
    if (shown == max_characters) {
      out += "...";
      break;
    }
    const auto byte = static_cast<unsigned char>(character);
    if (byte < 0x20 || byte >= 0x7F || character == '\'' || character == '\\')
      out += fmt::format("\\x{:02X}", byte);
    else
      out += character;
    ++shown;
  }
  return out;
}

std::string quoted(std::string_view text, std::size_t max_characters) {
  return fmt::format("'{}'", printable(text, max_characters));
}

std::string shortest(double value) { return fmt::format("{}", value); }

}  // namespace backlash::measurements::detail
