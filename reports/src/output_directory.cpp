#include "backlash/reports/output_directory.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <vector>

namespace backlash::reports {

namespace fs = std::filesystem;

namespace {

constexpr const char* marker = ".backlash-report";

fs::path absolute_target(const fs::path& target) {
  std::error_code error;
  fs::path absolute = fs::absolute(target, error);
  if (error) throw BadInput("--out " + target.string() + ": " + error.message());
  absolute = absolute.lexically_normal();
  if (!absolute.has_filename()) absolute = absolute.parent_path();  // "dir/" → "dir"
  return absolute;
}

fs::path unique_sibling(const fs::path& target, const std::string& tag) {
  std::string name = ".";  // built by appending: GCC 12's -Wrestrict misreads the chained operator+
  name += target.filename().string();
  name += '.';
  name += tag;
  name += "-XXXXXX";
  const std::string pattern = (target.parent_path() / name).string();
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  if (!::mkdtemp(buffer.data()))
    throw std::runtime_error("cannot create a folder next to " + target.string() + ": " + std::strerror(errno));
  return fs::path(buffer.data());
}

}  // namespace

void check_output_target(const fs::path& target) {
  if (target.empty()) throw BadInput("--out: empty path");
  const fs::path absolute = absolute_target(target);
  if (absolute.filename() == "." || absolute.filename() == ".." || absolute == absolute.root_path())
    throw BadInput("--out " + target.string() + ": not a folder name");
  std::error_code error;
  const fs::path parent = absolute.parent_path();
  if (!fs::is_directory(parent, error))
    throw BadInput("--out " + target.string() + ": the folder " + parent.string() + " does not exist");
  const fs::file_status status = fs::symlink_status(absolute, error);
  if (!fs::exists(status)) return;
  if (!fs::is_directory(status))
    throw BadInput("--out " + target.string() + ": exists and is not a folder");
  if (fs::is_empty(absolute, error) || fs::exists(absolute / marker)) return;
  throw BadInput("--out " + target.string() + ": the folder exists and is not a backlash report; choose a new folder");
}

StagedDirectory::StagedDirectory(const fs::path& target) : target_(absolute_target(target)) {
  check_output_target(target_);
  staging_ = unique_sibling(target_, "tmp");
  write(marker, "written by backlash report\n");
}

StagedDirectory::~StagedDirectory() {
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
}

void StagedDirectory::write(const fs::path& relative, const std::string& content) {
  const fs::path file = staging_ / relative;
  fs::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << content;
  out.close();
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

void StagedDirectory::commit() {
  std::error_code error;
  fs::path old;
  if (fs::exists(fs::symlink_status(target_, error))) {
    check_output_target(target_);  // still empty or a report
    old = unique_sibling(target_, "old");
    fs::remove(old);  // rename needs the name free
    fs::rename(target_, old, error);
    if (error) throw std::runtime_error("cannot move the old " + target_.string() + " aside: " + error.message());
  }
  fs::permissions(staging_, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                                fs::perms::others_read | fs::perms::others_exec, error);
  fs::rename(staging_, target_, error);
  if (error) {
    if (!old.empty()) fs::rename(old, target_);  // put the old report back
    throw std::runtime_error("cannot move the report into " + target_.string() + ": " + error.message());
  }
  committed_ = true;
  if (!old.empty()) fs::remove_all(old, error);
}

}  // namespace backlash::reports
