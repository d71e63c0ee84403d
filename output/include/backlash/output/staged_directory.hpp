// backlash/output/staged_directory.hpp — an output folder written all at once.
//
// Everything goes into a staging folder beside the target, so the final rename stays on one
// file system; commit() writes the marker file (target.hpp: folder_marker) and moves the
// folder into place (an existing output there is moved aside first and removed after, or put
// back if the move fails).  The target is checked first and again at commit (Target::folder).
//
// Two kinds of staging folder:
//   temporary   ".NAME.tmp-XXXXXX" (mkdtemp, unique): removed when the object is destroyed
//               without commit() — a failure leaves nothing behind (report, discrepancy).
//   partial     ".NAME.<tag>" (a fixed name, e.g. ".DIR.map-partial"): kept when destroyed
//               without commit(), so a later run can find it and go on (`backlash map
//               --resume`).  The caller decides what it holds and whether it may be reused
//               (the map's checkpoint); this class only names it and moves it into place.
// Errors: OutputError (output_error.hpp).
#pragma once

#include "backlash/output/target.hpp"

#include <filesystem>
#include <string>
#include <string_view>

namespace backlash::output {

class StagedDirectory {
 public:
  /// A temporary staging folder for `target`; the marker will read "written by backlash <program>".
  explicit StagedDirectory(const std::filesystem::path& target, std::string program = "report",
                           FolderOwner owner = {});
  /// A partial staging folder ".NAME.<tag>" for `target`: named, not created (see partial_path).
  static StagedDirectory partial(const std::filesystem::path& target, std::string_view tag, std::string program,
                                 FolderOwner owner = {});
  ~StagedDirectory();
  StagedDirectory(StagedDirectory&& other) noexcept;
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;
  StagedDirectory& operator=(StagedDirectory&&) = delete;

  /// The staging folder (write into it freely).
  const std::filesystem::path& path() const { return staging_; }
  /// The target, absolute and normal.
  const std::filesystem::path& target() const { return target_; }
  /// Writes one file (parents created); OutputError(write_failed) on failure.
  void write(const std::filesystem::path& relative, const std::string& content);
  /// Writes the marker and moves the folder into place.
  void commit();

  /// ".NAME.<tag>" beside the target (absolute, normal).
  static std::filesystem::path partial_path(const std::filesystem::path& target, std::string_view tag);

 private:
  struct Partial {};
  StagedDirectory(Partial, const std::filesystem::path& target, std::string_view tag, std::string program,
                  FolderOwner owner);
  std::filesystem::path target_, staging_;
  std::string program_;
  FolderOwner owner_;
  bool keep_ = false;  ///< a partial folder: kept when not committed
  bool committed_ = false;
};

}  // namespace backlash::output
