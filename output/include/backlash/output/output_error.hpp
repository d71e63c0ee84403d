// backlash/output/output_error.hpp — the one error type of every output the project writes
// (files and folders: target.hpp, atomic_file.hpp, staged_directory.hpp).
//
// An OutputError is one of two kinds, and the kind is the command's exit code:
//   bad_target    the target cannot receive the output (a directory where a file goes, a
//                 missing folder, a folder that is not the project's, …): bad usage, exit 2;
//                 nothing has been written.
//   write_failed  the output could not be written or moved into place (a full disk, a
//                 permission, …): exit 1; nothing half-written is left behind.
// what() is the one-line message a command prints ("--out FILE: is a directory; give a file
// name").  problem(), target() and detail() say the same in parts, for a caller that words it
// its own way (measurements' "FILE: refusing to replace it: not a regular file (a directory)").
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

namespace backlash::output {

/// What exactly is wrong; detail() completes it where a noun or a system message is needed.
enum class Problem {
  empty_name,            ///< the target path is empty
  not_a_name,            ///< ".", "..", a root folder: no name to write under
  inspect_failed,        ///< the target could not be looked at (detail: the system's message)
  is_directory,          ///< a file target that is a directory (detail: "a directory")
  is_symlink,            ///< a file target that is a symbolic link (detail: "a symbolic link")
  not_regular,           ///< a device, a FIFO or a socket (detail: "a character device", …)
  folder_missing,        ///< the target's folder does not exist (detail: that folder)
  folder_not_directory,  ///< the target's "folder" is something else (detail: that path)
  folder_unreadable,     ///< the target's folder could not be looked at (detail: the system's message)
  not_a_folder,          ///< a folder target that exists and is not a folder
  foreign_folder,        ///< a folder target that is neither empty nor written by the project
  busy,                  ///< another process is writing the target (its staging folder is locked; detail: that folder)
  create_failed,         ///< the temporary file or folder could not be made (detail: the system's message)
  write_failed,          ///< writing, flushing or closing failed (detail: the system's message)
  move_failed,           ///< the rename into place failed (detail: the system's message)
};

class OutputError : public std::runtime_error {
 public:
  enum class Kind { bad_target, write_failed };

  OutputError(Kind kind, Problem problem, std::filesystem::path target, std::string detail,
              const std::string& message);

  Kind kind() const { return kind_; }
  Problem problem() const { return problem_; }
  /// The path the caller named (as given), or the file being written for write failures.
  const std::filesystem::path& target() const { return target_; }
  /// The noun or system message that completes problem() (may be empty).
  const std::string& detail() const { return detail_; }
  /// 2 for a bad target (bad usage), 1 for a failed write (cli/main.cpp).
  int exit_code() const { return kind_ == Kind::bad_target ? 2 : 1; }

 private:
  Kind kind_;
  Problem problem_;
  std::filesystem::path target_;
  std::string detail_;
};

/// Throws a bad_target OutputError.
[[noreturn]] void refuse(Problem problem, const std::filesystem::path& target, std::string detail,
                         const std::string& message);
/// Throws a write_failed OutputError.
[[noreturn]] void fail(Problem problem, const std::filesystem::path& target, std::string detail,
                       const std::string& message);

}  // namespace backlash::output
