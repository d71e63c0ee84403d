// Helpers shared by the measurements tests: a private temporary folder, whole
// files as strings, bit-for-bit comparison of doubles.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

namespace backlash::measurements::testing {

/// A fresh folder under the system's temporary folder, removed with everything
/// in it when the object goes out of scope.
class TemporaryFolder {
 public:
  TemporaryFolder() {
    std::random_device entropy;
    const std::filesystem::path base = std::filesystem::temp_directory_path();
    for (int attempt = 0; attempt < 100; ++attempt) {
      path_ = base / ("backlash-measurements-" + std::to_string(::getpid()) + "-" + std::to_string(entropy()));
      if (std::filesystem::create_directory(path_)) return;
    }
    throw std::runtime_error("cannot create a temporary folder");
  }
  TemporaryFolder(const TemporaryFolder&) = delete;
  TemporaryFolder& operator=(const TemporaryFolder&) = delete;
  ~TemporaryFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

  /// Names of the entries in the folder, sorted.
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(path_)) names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  std::filesystem::path path_;
};

inline void write_text(const std::filesystem::path& file, const std::string& content) {
  std::ofstream out(file, std::ios::binary);
  out << content;
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

inline std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline std::uint64_t bits(double value) { return std::bit_cast<std::uint64_t>(value); }

/// Index of the first value whose bits differ, or -1 when both are identical
/// (also in length).
inline long first_bit_difference(const std::vector<double>& actual, const std::vector<double>& expected) {
  if (actual.size() != expected.size()) return static_cast<long>(std::min(actual.size(), expected.size()));
  for (std::size_t index = 0; index < actual.size(); ++index)
    if (bits(actual[index]) != bits(expected[index])) return static_cast<long>(index);
  return -1;
}

/// EXPECTs `actual` to equal `expected` bit for bit, printing the first
/// difference as "returned X instead of Y".
inline void expect_same_bits(const std::vector<double>& actual, const std::vector<double>& expected,
                             const std::string& what) {
  const long index = first_bit_difference(actual, expected);
  if (index < 0) return;
  if (actual.size() != expected.size()) {
    ADD_FAILURE() << what << " returned " << actual.size() << " values instead of " << expected.size();
    return;
  }
  const auto at = static_cast<std::size_t>(index);
  char got[64], want[64];
  std::snprintf(got, sizeof got, "%.17g (bits %016llx)", actual[at], static_cast<unsigned long long>(bits(actual[at])));
  std::snprintf(want, sizeof want, "%.17g (bits %016llx)", expected[at],
                static_cast<unsigned long long>(bits(expected[at])));
  ADD_FAILURE() << what << "[" << at << "] returned " << got << " instead of " << want;
}

}  // namespace backlash::measurements::testing
