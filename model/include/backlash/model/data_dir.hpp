// backlash/model/data_dir.hpp — where the library and the CLI find the files they
// read at run time.
//
// An installation keeps them in PREFIX/share/backlash (docs/design.md, "Library and
// package"):
//   cases/I.toml … VIII.toml              the thesis's cases (load_case("V"))
//   errata/*.toml                         the errata ledger (the report)
//   data/*.toml                           the thesis's printed numbers (the report)
// The build tree has the same layout in build/share/backlash (links into the source
// tree, made by CMake), so a build-tree run and an installed one find their files
// the same way.  No path is compiled into the project's binaries (the CLI, the
// libraries, the Python module): the folder is found at run time,
//   1. $BACKLASH_DATA_DIR, if set and not empty;
//   2. else, in a program built against the installed package (find_package(backlash)),
//      the share/backlash of the prefix the package was found in, when it is there
//      (backlashConfig.cmake gives such programs a one-line source naming it: a program
//      of one's own need not live inside the prefix);
//   3. else share/backlash beside the binary this library is linked into — the
//      executable, a shared library, or the Python module — looked for in each of
//      the four folders above the binary's own (PREFIX/bin/backlash and
//      PREFIX/lib/libbacklash_model.so are one folder below PREFIX,
//      PREFIX/lib/python3/dist-packages/backlash/_core.so four);
// the first folder holding share/backlash/cases wins.  (The thesis's cases alone
// can also be redirected with $BACKLASH_CASES_DIR: case_spec.hpp, thesis_cases_dir().)
#pragma once

#include <filesystem>

namespace backlash::model {

/// The data folder (share/backlash) as found by the rules above.  Throws
/// std::runtime_error with one line naming the binary it searched from when there is
/// none (an incomplete installation: set BACKLASH_DATA_DIR).
std::filesystem::path data_dir();

/// The binary (executable, shared library or Python module) this library's code
/// was loaded from, symbolic links resolved; empty when it cannot be told.
std::filesystem::path this_binary();

}  // namespace backlash::model
