// backlash/cli/output_files.hpp — all-or-nothing output files.
//
// A file is written to a uniquely named temporary file next to its target (mkstemp:
// ".NAME.partial-XXXXXX", so parallel runs onto one target never collide and the rename
// stays on one file system), then renamed into place; a failure removes the temporary
// file, so nothing half-written is ever left under any name.
// The rename only ever replaces a regular file: a target that exists and is anything else —
// a directory, a device such as /dev/null, a pipe, a socket, a symbolic link — is refused
// (UsageError, exit 2) before anything is written.
#pragma once

#include "commands.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace backlash::cli {

/// Throws UsageError when `target` cannot be (re)placed by a regular file: an existing
/// target must be a regular file (not followed through a symbolic link), and its folder must exist.
inline void check_output_file(const std::filesystem::path& target) {
  if (target.empty() || !target.has_filename() || target.filename() == "." || target.filename() == "..")
    throw UsageError("--out '" + target.string() + "': not a file name");
  struct stat info {};
  if (::lstat(target.c_str(), &info) == 0) {
    if (S_ISDIR(info.st_mode)) throw UsageError("--out " + target.string() + ": is a directory; give a file name");
    if (S_ISLNK(info.st_mode))
      throw UsageError("--out " + target.string() + ": is a symbolic link; refusing to replace it (give the file itself)");
    if (!S_ISREG(info.st_mode))
      throw UsageError("--out " + target.string() +
                       ": is not a regular file (a device, a pipe or a socket); refusing to replace it");
  } else if (errno != ENOENT) {
    throw UsageError("--out " + target.string() + ": " + std::strerror(errno));
  }
  const std::filesystem::path folder = target.parent_path().empty() ? "." : target.parent_path();
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error))
    throw UsageError("--out " + target.string() + ": the folder " + folder.string() + " does not exist");
}

/// One output file, streamed into a unique temporary sibling and renamed into place by
/// commit(); destroyed uncommitted, it removes the temporary file.
class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
    check_output_file(target_);
    const std::filesystem::path folder = target_.parent_path().empty() ? "." : target_.parent_path();
    std::string name = ".";
    name += target_.filename().string();
    name += ".partial-XXXXXX";
    std::string pattern = (folder / name).string();
    std::vector<char> buffer(pattern.begin(), pattern.end());
    buffer.push_back('\0');
    const int fd = ::mkstemp(buffer.data());
    if (fd < 0) throw std::runtime_error("cannot create a file next to " + target_.string() + ": " + std::strerror(errno));
    temporary_ = buffer.data();
    stream_ = ::fdopen(fd, "wb");
    if (!stream_) {
      ::close(fd);
      ::unlink(temporary_.c_str());
      throw std::runtime_error("cannot write " + temporary_.string());
    }
  }
  ~AtomicFile() {
    if (stream_) std::fclose(stream_);
    if (!committed_ && !temporary_.empty()) ::unlink(temporary_.c_str());
  }
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  FILE* stream() const { return stream_; }
  void write(std::string_view text) {
    if (std::fwrite(text.data(), 1, text.size(), stream_) != text.size())
      throw std::runtime_error("cannot write " + target_.string() + ": " + std::strerror(errno));
  }

  void commit() {
    const bool flushed = std::fflush(stream_) == 0 && !std::ferror(stream_);
    const int mode_fd = ::fileno(stream_);
    const mode_t mask = ::umask(0);  // mkstemp's 0600 is not what a written result should have:
    ::umask(mask);                   // the permissions of a file made by open(), 0666 less the umask
    (void)::fchmod(mode_fd, 0666 & ~mask);
    const bool closed = std::fclose(stream_) == 0;
    stream_ = nullptr;
    if (!flushed || !closed) throw std::runtime_error("cannot write " + target_.string() + ": " + std::strerror(errno));
    check_output_file(target_);  // nothing but a regular file may have appeared there meanwhile
    if (::rename(temporary_.c_str(), target_.c_str()) != 0)
      throw std::runtime_error("cannot move the output into " + target_.string() + ": " + std::strerror(errno));
    committed_ = true;
  }

 private:
  std::filesystem::path target_, temporary_;
  FILE* stream_ = nullptr;
  bool committed_ = false;
};

/// Several files computed in memory first, then committed one by one (each atomically).
class OutputFiles {
 public:
  void add(const std::filesystem::path& relative, std::string content) { files_[relative] = std::move(content); }

  /// Checks every target first (nothing is written if one is refused), then writes them.
  void commit(const std::filesystem::path& directory) const {
    std::error_code error;
    if (std::filesystem::exists(std::filesystem::symlink_status(directory, error)) &&
        !std::filesystem::is_directory(directory, error))
      throw UsageError("--out " + directory.string() + ": exists and is not a folder");
    for (const auto& [relative, content] : files_) {
      const std::filesystem::path target = directory / relative;
      if (std::filesystem::is_directory(target.parent_path(), error)) check_output_file(target);
    }
    for (const auto& [relative, content] : files_) {
      const std::filesystem::path target = directory / relative;
      std::filesystem::create_directories(target.parent_path());
      AtomicFile file(target);
      file.write(content);
      file.commit();
    }
  }

 private:
  std::map<std::filesystem::path, std::string> files_;
};

}  // namespace backlash::cli
