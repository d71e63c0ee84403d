// All-or-nothing output files (backlash/output/atomic_file.hpp): POSIX mkstemp, write, fsync,
// rename.
#include "backlash/output/atomic_file.hpp"

#include "backlash/output/output_error.hpp"
#include "backlash/output/signals.hpp"
#include "backlash/output/target.hpp"

#include "temporaries.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

namespace backlash::output {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t buffer_limit = 65536;

std::string system_message(int error_number) { return std::strerror(error_number); }

[[noreturn]] void write_failed(const fs::path& target, int error_number) {
  fail(Problem::write_failed, target, system_message(error_number),
       "cannot write " + target.string() + ": " + system_message(error_number));
}

/// The permissions of the new file: the replaced file's, else those open() would give.
mode_t new_file_mode(const fs::path& target) {
  struct stat existing {};
  if (::lstat(target.c_str(), &existing) == 0 && S_ISREG(existing.st_mode)) return existing.st_mode & 07777;
  const mode_t mask = ::umask(0);
  ::umask(mask);
  return 0666 & ~mask;
}

}  // namespace

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  check_target(target_, Target::file);
  remove_stale_temporaries(target_);  // what a killed run onto the same target left (signals.hpp)
  const std::string pattern = detail::temporary_prefix(target_) + "XXXXXX";
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  fd_ = ::mkostemp(buffer.data(), O_CLOEXEC);
  if (fd_ < 0) {
    const int error_number = errno;
    fail(Problem::create_failed, target_, system_message(error_number),
         "cannot create a file next to " + target_.string() + ": " + system_message(error_number));
  }
  temporary_ = buffer.data();
  detail::lock_temporary(fd_);
  tracked_ = detail::track_temporary(temporary_);
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_ && !temporary_.empty()) ::unlink(temporary_.c_str());
  detail::forget_temporary(tracked_);
}

void AtomicFile::write(std::string_view text) {
  buffer_ += text;
  if (buffer_.size() >= buffer_limit) flush();
}

void AtomicFile::flush() {
  std::size_t written = 0;
  while (written < buffer_.size()) {
    const ssize_t count = ::write(fd_, buffer_.data() + written, buffer_.size() - written);
    if (count < 0) {
      if (errno == EINTR) continue;
      write_failed(target_, errno);
    }
    written += static_cast<std::size_t>(count);
  }
  buffer_.clear();
}

void AtomicFile::commit() {
  flush();
  if (::fchmod(fd_, new_file_mode(target_)) != 0 || ::fsync(fd_) != 0) write_failed(target_, errno);
  const int closed = ::close(fd_);
  fd_ = -1;
  if (closed != 0) write_failed(target_, errno);
  check_target(target_, Target::file);  // nothing but a regular file may have appeared there meanwhile
  const auto held = detail::hold_temporaries();  // a signal's cleanup waits for the rename
  if (::rename(temporary_.c_str(), target_.c_str()) != 0) {
    const int error_number = errno;
    fail(Problem::move_failed, target_, system_message(error_number),
         "cannot move the output into " + target_.string() + ": " + system_message(error_number));
  }
  committed_ = true;
  detail::forget_temporary(tracked_);
}

void write_atomically(const fs::path& target, std::string_view content) {
  AtomicFile file(target);
  file.write(content);
  file.commit();
}

void OutputFiles::commit(const fs::path& directory) const {
  check_target(directory, Target::file_folder);
  std::error_code error;
  for (const auto& [relative, content] : files_) {
    const fs::path target = directory / relative;
    if (fs::is_directory(target.parent_path(), error)) check_target(target, Target::file);
  }
  const bool created = !fs::exists(fs::symlink_status(directory, error));
  try {
    for (const auto& [relative, content] : files_) {
      const fs::path target = directory / relative;
      fs::create_directories(target.parent_path());
      write_atomically(target, content);
    }
  } catch (...) {
    if (created) fs::remove_all(directory, error);  // a folder made here (and all in it): nothing stays
    throw;
  }
}

}  // namespace backlash::output
