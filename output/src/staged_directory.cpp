// An output folder written all at once (backlash/output/staged_directory.hpp).
#include "backlash/output/staged_directory.hpp"

#include "backlash/output/output_error.hpp"
#include "backlash/output/signals.hpp"

#include "temporaries.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

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

// A new, uniquely named folder: `pattern` ends in "XXXXXX" (mkdtemp).
fs::path unique_folder(const std::string& pattern, const fs::path& target) {
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  if (!::mkdtemp(buffer.data())) {
    const std::string system = std::strerror(errno);
    fail(Problem::create_failed, target, system, "cannot create a folder next to " + target.string() + ": " + system);
  }
  return fs::path(buffer.data());
}

int open_folder(const fs::path& folder) { return ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC | O_NOFOLLOW); }

bool same_file(int fd, const fs::path& path) {
  struct stat held {}, named {};
  return ::fstat(fd, &held) == 0 && ::lstat(path.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
         held.st_ino == named.st_ino;
}

// The partial folder `staging` of `target`, created if absent (`created` says so) and locked
// (flock, held while the returned descriptor is open): a second run onto the target is refused.
int lock_partial(const fs::path& staging, const fs::path& target, bool& created) {
  const std::string out = "--out " + target.string();
  for (int attempt = 0; attempt < 3; ++attempt) {
    created = ::mkdir(staging.c_str(), 0777) == 0;
    if (!created && errno != EEXIST) {
      const std::string system = std::strerror(errno);
      fail(Problem::create_failed, target, system, "cannot create " + staging.string() + ": " + system);
    }
    const int fd = open_folder(staging);
    if (fd < 0 && errno == ENOENT) continue;  // removed meanwhile (a run that just finished): again
    if (fd < 0) refuse(Problem::not_a_folder, target, "", out + ": " + staging.string() + " exists and is not a folder; remove it");
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd);
      refuse(Problem::busy, target, staging.string(),
             out + ": another backlash run is writing it (" + staging.string() + " is locked); wait for it or choose another folder");
    }
    if (same_file(fd, staging)) return fd;
    ::close(fd);  // renamed into place or replaced meanwhile: again
  }
  fail(Problem::create_failed, target, "", "cannot lock " + staging.string() + ": it keeps changing");
}

}  // namespace

StagedDirectory::StagedDirectory(const fs::path& target, std::string program, FolderOwner owner)
    : program_(std::move(program)), owner_(std::move(owner)) {
  check_target(target, Target::folder, owner_);
  target_ = absolute_folder(target);
  remove_stale_temporaries(target_);  // what a killed run onto the same target left (signals.hpp)
  staging_ = unique_folder(detail::temporary_prefix(target_) + "XXXXXX", target_);
  lock_ = open_folder(staging_);
  detail::lock_temporary(lock_);
  tracked_ = detail::track_temporary(staging_);
}

StagedDirectory::StagedDirectory(Partial, const fs::path& target, std::string_view tag, std::string program,
                                 FolderOwner owner)
    : program_(std::move(program)), owner_(std::move(owner)), keep_(true) {
  check_target(target, Target::folder, owner_);
  target_ = absolute_folder(target);
  staging_ = sibling(target_, tag);
  lock_ = lock_partial(staging_, target_, created_);
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
      owner_(std::move(other.owner_)), keep_(other.keep_), committed_(other.committed_), created_(other.created_),
      lock_(other.lock_), tracked_(other.tracked_) {
  other.committed_ = true;  // the moved-from object removes nothing
  other.lock_ = -1, other.tracked_ = 0;
}

StagedDirectory::~StagedDirectory() {
  if (!committed_ && !keep_) {
    std::error_code ignored;
    fs::remove_all(staging_, ignored);
  } else if (!committed_ && created_) {
    ::rmdir(staging_.c_str());  // a partial folder made by this run and still empty: not kept
  }
  if (lock_ >= 0) ::close(lock_);
  detail::forget_temporary(tracked_);
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
  const auto held = detail::hold_temporaries();  // a signal's cleanup waits for the swap
  if (fs::exists(fs::symlink_status(target_, error))) {
    check_target(target_, Target::folder, owner_);  // still empty or the project's
    std::string name = ".";  // built by appending: GCC 12's -Wrestrict misreads the chained operator+
    name += target_.filename().string();
    name += ".old-XXXXXX";
    old = unique_folder((target_.parent_path() / name).string(), target_);
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
  detail::forget_temporary(tracked_);
  if (!old.empty()) fs::remove_all(old, error);
}

}  // namespace backlash::output
