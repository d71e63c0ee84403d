// tests/reliability/scratch_folder.hpp — the per-process scratch folder of a reliability test
// file (created on first use, removed when the test program ends) and a whole-file reader.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>

namespace backlash::testing {

/// `$TMPDIR/backlash-<name>-<pid>`: created on first call, removed at the program's end.
inline std::filesystem::path scratch_folder(const std::string& name) {
  namespace fs = std::filesystem;
  struct Folder {
    fs::path path;
    explicit Folder(fs::path p) : path(std::move(p)) { fs::create_directories(path); }
    ~Folder() {
      std::error_code ignored;
      fs::remove_all(path, ignored);
    }
  };
  static const Folder folder(fs::temp_directory_path() / ("backlash-" + name + "-" + std::to_string(::getpid())));
  return folder.path;
}

/// The bytes of `file` ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace backlash::testing
