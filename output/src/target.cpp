// The checks of an output target (backlash/output/target.hpp).  The messages are the ones the
// commands have always printed: "--out TARGET: <what is wrong>".
#include "backlash/output/target.hpp"

#include "backlash/output/output_error.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

namespace backlash::output {

namespace fs = std::filesystem;

namespace {


std::string out(const fs::path& target) { return "--out " + target.string(); }

// The target itself: absent, or a regular file (a symbolic link is not followed).
void check_file_itself(const fs::path& target) {
  struct stat info {};
  if (::lstat(target.c_str(), &info) != 0) {
    if (errno == ENOENT) return;
    const std::string system = std::strerror(errno);
    refuse(Problem::inspect_failed, target, system, out(target) + ": " + system);
  }
  const std::string type = describe_file_type(info.st_mode);
  if (S_ISDIR(info.st_mode)) refuse(Problem::is_directory, target, type, out(target) + ": is a directory; give a file name");
  if (S_ISLNK(info.st_mode))
    refuse(Problem::is_symlink, target, type,
           out(target) + ": is a symbolic link; refusing to replace it (give the file itself)");
  if (!S_ISREG(info.st_mode))
    refuse(Problem::not_regular, target, type,
           out(target) + ": is not a regular file (a device, a pipe or a socket); refusing to replace it");
}

// The folder a file target goes into must exist.
void check_file_folder(const fs::path& target) {
  const fs::path folder = target.parent_path().empty() ? "." : target.parent_path();
  const std::string message = out(target) + ": the folder " + folder.string() + " does not exist";
  struct stat info {};
  if (::stat(folder.c_str(), &info) != 0) {
    if (errno == ENOENT) refuse(Problem::folder_missing, target, folder.string(), message);
    refuse(Problem::folder_unreadable, target, std::strerror(errno), message);
  }
  if (!S_ISDIR(info.st_mode)) refuse(Problem::folder_not_directory, target, folder.string(), message);
}

void check_file(const fs::path& target) {
  if (target.empty()) refuse(Problem::empty_name, target, "", "--out '': not a file name");
  if (!target.has_filename() || target.filename() == "." || target.filename() == "..")
    refuse(Problem::not_a_name, target, "", "--out '" + target.string() + "': not a file name");
  check_file_itself(target);
  check_file_folder(target);
}

void check_folder(const fs::path& target, const FolderOwner& owner) {
  if (target.empty()) refuse(Problem::empty_name, target, "", "--out: empty path");
  const fs::path absolute = absolute_folder(target);
  if (absolute.filename() == "." || absolute.filename() == ".." || absolute == absolute.root_path())
    refuse(Problem::not_a_name, target, "", out(target) + ": not a folder name");
  std::error_code error;
  const fs::path parent = absolute.parent_path();
  if (!fs::is_directory(parent, error))
    refuse(Problem::folder_missing, target, parent.string(),
           out(target) + ": the folder " + parent.string() + " does not exist");
  const fs::file_status status = fs::symlink_status(absolute, error);
  if (!fs::exists(status)) return;
  if (!fs::is_directory(status)) refuse(Problem::not_a_folder, target, "", out(target) + ": exists and is not a folder");
  if (fs::is_empty(absolute, error) || fs::exists(absolute / folder_marker)) return;
  refuse(Problem::foreign_folder, target, owner.owner,
         out(target) + ": the folder exists and is not a " + owner.owner + "; choose a new folder");
}

void check_file_folder_target(const fs::path& target) {
  std::error_code error;
  if (fs::exists(fs::symlink_status(target, error)) && !fs::is_directory(target, error))
    refuse(Problem::not_a_folder, target, "", out(target) + ": exists and is not a folder");
}

}  // namespace

fs::path absolute_folder(const fs::path& target) {
  std::error_code error;
  fs::path absolute = fs::absolute(target, error);
  if (error) refuse(Problem::inspect_failed, target, error.message(), out(target) + ": " + error.message());
  absolute = absolute.lexically_normal();
  if (!absolute.has_filename()) absolute = absolute.parent_path();  // "dir/" → "dir"
  return absolute;
}

void check_target(const fs::path& target, Target kind, const FolderOwner& owner) {
  switch (kind) {
    case Target::file: return check_file(target);
    case Target::folder: return check_folder(target, owner);
    case Target::file_folder: return check_file_folder_target(target);
  }
}

std::string describe_file_type(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "not a regular file";
}

}  // namespace backlash::output
