// backlash/output/atomic_file.hpp — all-or-nothing output files.
//
// A file is written to a uniquely named temporary file next to its target (mkstemp:
// ".NAME.tmp-PID-XXXXXX", so parallel runs onto one target never collide and the rename stays
// on one file system; removed on SIGINT/SIGTERM and by a later run if its writer was killed:
// signals.hpp), flushed to the disk (fsync) and renamed into place; a failure or a
// destruction without commit() removes the temporary file, so nothing half-written is ever
// left under any name.  The target is checked first and again just before the rename
// (target.hpp, Target::file): only a regular file is ever replaced.  The new file has the
// replaced file's permissions, or those open() would give (0666 less the umask).
// Errors: OutputError (output_error.hpp) — bad_target before anything is written,
// write_failed when the writing or the rename fails.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>

namespace backlash::output {

/// One output file, streamed into a unique temporary sibling and renamed into place by
/// commit(); destroyed uncommitted, it removes the temporary file.
class AtomicFile {
 public:
  /// Checks `target` (Target::file) and creates the temporary file.
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// Appends `text` (buffered; written out in 64 KiB pieces).
  void write(std::string_view text);
  /// Writes out, fsyncs, closes and renames into place.
  void commit();
  const std::filesystem::path& target() const { return target_; }

 private:
  void flush();
  std::filesystem::path target_, temporary_;
  std::string buffer_;
  int fd_ = -1;
  bool committed_ = false;
  std::uint64_t tracked_ = 0;  ///< the temporary's ticket for the signal cleanup (signals.hpp)
};

/// `content` written to `target` through an AtomicFile.
void write_atomically(const std::filesystem::path& target, std::string_view content);

/// Several files computed in memory first, then committed one by one (each atomically) into a
/// folder that is kept (Target::file_folder; codegen's case_<ID>.hpp and case_<ID>.tex).
class OutputFiles {
 public:
  void add(const std::filesystem::path& relative, std::string content) { files_[relative] = std::move(content); }

  /// Checks the folder and every target first (nothing is written if one is refused), then
  /// creates the folder if needed and writes the files.  A failed write removes the folder
  /// again when this call created it (a full disk leaves no empty folder).
  void commit(const std::filesystem::path& directory) const;

 private:
  std::map<std::filesystem::path, std::string> files_;
};

}  // namespace backlash::output
