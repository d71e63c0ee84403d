// backlash/output/target.hpp — the checks of an output target (the --out of every command),
// in one place.  Each check throws a bad_target OutputError (exit 2) before anything is
// written, with the message a command prints.
//
//   file          a file replaced as a whole (atomic_file.hpp): a new name in an existing
//                 folder, or an existing regular file.  A directory, a symbolic link (not
//                 followed), a device such as /dev/null, a FIFO or a socket is refused:
//                 the rename would replace the link or fail on the device.
//   folder        a folder replaced as a whole (staged_directory.hpp): a new name in an
//                 existing folder, an empty folder, or a folder the project wrote (it holds
//                 the marker file .backlash-report).  `--out $HOME` must never delete a home.
//   file_folder   a folder that receives several files and is kept (OutputFiles): a new name
//                 (created) or an existing folder.
#pragma once

#include <filesystem>
#include <string>

#include <sys/types.h>

namespace backlash::output {

enum class Target { file, folder, file_folder };

/// The marker file a replaceable output folder holds (its content: "written by backlash …").
inline constexpr const char* folder_marker = ".backlash-report";

/// Whose folders a `folder` target may replace, in the words of the refusal:
/// "the folder exists and is not a <owner>; choose a new folder".
struct FolderOwner {
  std::string owner = "backlash report";
};

/// Throws OutputError(bad_target) when `target` cannot receive an output of this kind.
void check_target(const std::filesystem::path& target, Target kind, const FolderOwner& owner = {});

/// What a file that is not a regular file is ("a directory", "a FIFO", ...), from lstat's st_mode.
std::string describe_file_type(mode_t mode);

/// The absolute, normal form of a folder target ("dir/" → "/…/dir"); OutputError when the
/// path cannot be made absolute.
std::filesystem::path absolute_folder(const std::filesystem::path& target);

}  // namespace backlash::output
