// data_dir.cpp — the data folder found at run time (model/data_dir.hpp).
#include "backlash/model/data_dir.hpp"

#include <link.h>

#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <system_error>

// Defined in a program built against the installed package: backlashConfig.cmake adds
// a one-line source returning PREFIX/share/backlash, the folder the package was found in
// (docs/design.md, "Library and package").  Absent in the project's own binaries.
extern "C" const char* backlash_package_data_dir() __attribute__((weak));

namespace backlash::model {

namespace {

struct Search {
  std::uintptr_t address = 0;
  bool found = false;
  std::string name;  ///< "" for the main executable
};

// The loaded object (executable or shared object) whose segments hold `address`.
int find_object(dl_phdr_info* info, std::size_t, void* data) {
  Search& search = *static_cast<Search*>(data);
  for (int i = 0; i < info->dlpi_phnum; ++i) {
    const ElfW(Phdr)& segment = info->dlpi_phdr[i];
    if (segment.p_type != PT_LOAD) continue;
    const std::uintptr_t start = info->dlpi_addr + segment.p_vaddr;
    if (search.address >= start && search.address < start + segment.p_memsz) {
      search.found = true;
      search.name = info->dlpi_name != nullptr ? info->dlpi_name : "";
      return 1;
    }
  }
  return 0;
}

bool is_data_dir(const std::filesystem::path& candidate) {
  std::error_code ignored;
  return std::filesystem::is_directory(candidate / "cases", ignored);
}

}  // namespace

std::filesystem::path this_binary() {
  Search search;
  search.address = reinterpret_cast<std::uintptr_t>(&this_binary);
  dl_iterate_phdr(&find_object, &search);
  // The main executable has no name in the loader's list: /proc/self/exe names it.
  const std::filesystem::path binary =
      search.found && !search.name.empty() ? std::filesystem::path(search.name) : std::filesystem::path("/proc/self/exe");
  std::error_code error;
  std::filesystem::path resolved = std::filesystem::canonical(binary, error);
  return error ? std::filesystem::path() : resolved;
}

std::filesystem::path data_dir() {
  if (const char* from_environment = std::getenv("BACKLASH_DATA_DIR");
      from_environment != nullptr && *from_environment != '\0')
    return std::filesystem::path(from_environment);
  if (backlash_package_data_dir != nullptr)
    if (const char* package = backlash_package_data_dir(); package != nullptr && is_data_dir(package))
      return std::filesystem::path(package);
  const std::filesystem::path binary = this_binary();
  if (binary.empty())
    throw std::runtime_error(
        "cannot tell which binary backlash is running from, so its data folder (share/backlash) is unknown: "
        "set BACKLASH_DATA_DIR");
  std::filesystem::path folder = binary.parent_path();
  for (int up = 0; up < 4; ++up) {
    folder = folder.parent_path();
    const std::filesystem::path candidate = folder / "share" / "backlash";
    if (is_data_dir(candidate)) return candidate;
    if (folder == folder.root_path()) break;
  }
  throw std::runtime_error("cannot find backlash's data folder (share/backlash with cases/) in the four folders above " +
                           binary.string() + ": an incomplete installation? set BACKLASH_DATA_DIR");
}

}  // namespace backlash::model
