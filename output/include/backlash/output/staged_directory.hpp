// backlash/output/staged_directory.hpp — an output folder written all at once.
//
// Everything goes into a staging folder beside the target, so the final rename stays on one
// file system; commit() writes the marker file (target.hpp: folder_marker) and moves the
// folder into place (an existing output there is moved aside first and removed after, or put
// back if the move fails).  The target is checked first and again at commit (Target::folder).
//
// Two kinds of staging folder, each locked (flock on the folder) while its object lives:
//   temporary   ".NAME.tmp-PID-XXXXXX" (mkdtemp, unique): removed when the object is destroyed
//               without commit() — a failure leaves nothing behind (report, discrepancy) —
//               and on SIGINT/SIGTERM/SIGHUP; one left by a killed process (SIGKILL) is
//               removed by the next StagedDirectory onto the same target (signals.hpp).
//   partial     ".NAME.<tag>" (a fixed name, e.g. ".DIR.map-partial"): created if absent and
//               kept when destroyed without commit() (unless this object made it and it is
//               still empty), so a later run can find it and go on (`backlash map --resume`).
//               Its lock refuses a second run onto the same target while the first lives
//               (OutputError bad_target, Problem::busy: exit 2).  The caller decides what it
//               holds and whether it may be reused (the map's checkpoint); this class only
//               names, locks and moves it into place.
// Errors: OutputError (output_error.hpp).
#pragma once

#include "backlash/output/target.hpp"

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace backlash::output {

class StagedDirectory {
 public:
  /// A temporary staging folder for `target`; the marker will read "written by backlash <program>".
  explicit StagedDirectory(const std::filesystem::path& target, std::string program = "report",
                           FolderOwner owner = {});
  /// A partial staging folder ".NAME.<tag>" for `target` (see partial_path): created if absent,
  /// and locked; OutputError(bad_target, Problem::busy) when another process holds it.
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
  bool created_ = false;  ///< a partial folder this object made (removed again while empty)
  int lock_ = -1;         ///< the staging folder, open and locked (flock) while this object lives
  std::uint64_t tracked_ = 0;  ///< a temporary folder's ticket for the signal cleanup (signals.hpp)
};

}  // namespace backlash::output
