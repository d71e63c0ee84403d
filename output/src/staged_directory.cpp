// An output folder written all at once (backlash/output/staged_directory.hpp).
#include "backlash/output/staged_directory.hpp"

#include "backlash/output/output_error.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <utility>
#include <vector>

namespace backlash::output {

namespace fs = std::filesystem;

namespace {

// ".NAME.<tag>" beside `target` (already absolute and normal).
fs::path sibling(const fs::path& target, std::string_view tag) {
  std::string name = ".";  // built by appending: GCC 12's -Wrestrict misreads the chained operator+
  name += target.filename().string();
  name += '.';
  name += tag;
  return target.parent_path() / name;
}

// A new, uniquely named folder ".NAME.<tag>-XXXXXX" beside `target`.
fs::path unique_sibling(const fs::path& target, const std::string& tag) {
  const std::string pattern = sibling(target, tag + "-XXXXXX").string();
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  if (!::mkdtemp(buffer.data())) {
    const std::string system = std::strerror(errno);
    fail(Problem::create_failed, target, system, "cannot create a folder next to " + target.string() + ": " + system);
  }
  return fs::path(buffer.data());
}

}  // namespace

StagedDirectory::StagedDirectory(const fs::path& target, std::string program, FolderOwner owner)
    : program_(std::move(program)), owner_(std::move(owner)) {
  check_target(target, Target::folder, owner_);
  target_ = absolute_folder(target);
  staging_ = unique_sibling(target_, "tmp");
}

StagedDirectory::StagedDirectory(Partial, const fs::path& target, std::string_view tag, std::string program,
                                 FolderOwner owner)
    : program_(std::move(program)), owner_(std::move(owner)), keep_(true) {
  check_target(target, Target::folder, owner_);
  target_ = absolute_folder(target);
  staging_ = sibling(target_, tag);
}

StagedDirectory StagedDirectory::partial(const fs::path& target, std::string_view tag, std::string program,
                                         FolderOwner owner) {
  return StagedDirectory(Partial{}, target, tag, std::move(program), std::move(owner));
}

fs::path StagedDirectory::partial_path(const fs::path& target, std::string_view tag) {
  return sibling(absolute_folder(target), tag);
}

StagedDirectory::StagedDirectory(StagedDirectory&& other) noexcept
    : target_(std::move(other.target_)), staging_(std::move(other.staging_)), program_(std::move(other.program_)),
      owner_(std::move(other.owner_)), keep_(other.keep_), committed_(other.committed_) {
  other.committed_ = true;  // the moved-from object removes nothing
}

StagedDirectory::~StagedDirectory() {
  if (committed_ || keep_) return;
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
}

void StagedDirectory::write(const fs::path& relative, const std::string& content) {
  const fs::path file = staging_ / relative;
  std::error_code error;
  fs::create_directories(file.parent_path(), error);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << content;
  out.close();
  if (!out) fail(Problem::write_failed, file, "", "cannot write " + file.string());
}

void StagedDirectory::commit() {
  write(folder_marker, "written by backlash " + program_ + "\n");
  std::error_code error;
  fs::path old;
  if (fs::exists(fs::symlink_status(target_, error))) {
    check_target(target_, Target::folder, owner_);  // still empty or the project's
    old = unique_sibling(target_, "old");
    fs::remove(old);  // rename needs the name free
    fs::rename(target_, old, error);
    if (error)
      fail(Problem::move_failed, target_, error.message(),
           "cannot move the old " + target_.string() + " aside: " + error.message());
  }
  fs::permissions(staging_, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                                fs::perms::others_read | fs::perms::others_exec, error);
  fs::rename(staging_, target_, error);
  if (error) {
    if (!old.empty()) fs::rename(old, target_);  // put the old output back
    fail(Problem::move_failed, target_, error.message(),
         "cannot move the " + program_ + " into " + target_.string() + ": " + error.message());
  }
  committed_ = true;
  if (!old.empty()) fs::remove_all(old, error);
}

}  // namespace backlash::output
