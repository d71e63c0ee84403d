// backlash/cli/output_files.hpp — all-or-nothing output.
//
// A command first computes every file it will write (in memory), then commits
// them: each is written to "<name>.partial" and renamed into place, so a
// failure never leaves a half-written file under its final name.
#pragma once

#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>

namespace backlash::cli {

class OutputFiles {
 public:
  void add(const std::filesystem::path& relative, std::string content) { files_[relative] = std::move(content); }

  void commit(const std::filesystem::path& directory) const {
    for (const auto& [relative, content] : files_) {
      const std::filesystem::path target = directory / relative;
      std::filesystem::create_directories(target.parent_path());
      const std::filesystem::path partial = target.string() + ".partial";
      {
        std::ofstream out(partial, std::ios::binary);
        out << content;
        out.close();
        if (!out) {
          std::filesystem::remove(partial);
          throw std::runtime_error("cannot write " + target.string());
        }
      }
      std::filesystem::rename(partial, target);
    }
  }

 private:
  std::map<std::filesystem::path, std::string> files_;
};

}  // namespace backlash::cli
