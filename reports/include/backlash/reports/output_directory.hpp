// backlash/reports/output_directory.hpp — an output folder written all at once.
//
// Everything goes into a fresh, uniquely named folder next to the target
// (".NAME.tmp-XXXXXX", mkdtemp), so the final rename stays on one file
// system; commit() then moves it into place (an existing report there is
// moved aside first and removed after).  If anything fails before commit, the
// destructor removes the temporary folder: nothing is left behind.
//
// An existing target is replaced only when it is an empty folder or a report
// written by this class (it holds the marker file ".backlash-report"): `--out
// $HOME` must never delete a home folder.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

namespace backlash::reports {

/// Bad user input (the command maps it to exit code 2).
class BadInput : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws BadInput when `target` cannot receive a report (empty path, missing
/// parent folder, a file in the way, a folder that is not a report).
void check_output_target(const std::filesystem::path& target);

class StagedDirectory {
 public:
  explicit StagedDirectory(const std::filesystem::path& target);
  ~StagedDirectory();
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;

  /// The temporary folder (write into it freely).
  const std::filesystem::path& path() const { return staging_; }
  /// Write one file (parents created); throws on failure.
  void write(const std::filesystem::path& relative, const std::string& content);
  /// Move the folder into place.
  void commit();

 private:
  std::filesystem::path target_, staging_;
  bool committed_ = false;
};

}  // namespace backlash::reports
