// backlash_codegen — the build-time generator (run by ONE add_custom_command in
// codegen/CMakeLists.txt).
//
//   backlash_codegen --cases-dir DIR --out DIR
//
// writes, under DIR/backlash/generated/:
//   case_<ID>.hpp, case_<ID>.tex  for each thesis case I..VIII (from DIR/<ID>.toml)
//   branches.hpp, branches.tex    the direct per-branch parametric evaluators
//   cases.hpp                     umbrella header + X-macro over the cases
// Each file is written only if its content changed (a no-op rebuild recompiles
// nothing).  Exit status 0 on success, 1 (one line on stderr) on any failure,
// 2 on bad arguments.
#include "backlash/codegen/emit.hpp"
#include "backlash/model/case_spec.hpp"
#include "backlash/symbolic/general_derivation.hpp"

#include <exception>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

namespace {

int usage(const std::string& problem) {
  std::cerr << "backlash_codegen: error: " << problem << " (usage: backlash_codegen --cases-dir DIR --out DIR)\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path cases_dir, out_dir;
  bool verbose = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if ((arg == "--cases-dir" || arg == "--out") && i + 1 < argc) {
      (arg == "--out" ? out_dir : cases_dir) = argv[++i];
    } else if (arg == "--verbose") {
      verbose = true;
    } else {
      return usage("unexpected argument '" + arg + "'");
    }
  }
  if (cases_dir.empty() || out_dir.empty()) return usage("--cases-dir and --out are required");
  try {
    namespace codegen = backlash::codegen;
    const std::filesystem::path target = out_dir / "backlash" / "generated";
    std::vector<codegen::GeneratedFile> files;
    const std::vector<std::string>& ids = backlash::model::thesis_case_ids();
    for (const std::string& id : ids) {
      backlash::model::CaseSpec spec = backlash::model::load_case_file(cases_dir / (id + ".toml"));
      spec.id = id;
      for (auto& file : codegen::emit_case_files(spec)) files.push_back(std::move(file));
    }
    const auto branches = backlash::symbolic::derive_general_branches();
    files.push_back({"branches.hpp", codegen::emit_branches_header(branches)});
    files.push_back({"branches.tex", codegen::emit_branches_latex(branches)});
    files.push_back({"cases.hpp", codegen::emit_cases_umbrella(ids)});
    int written = 0;
    for (const auto& file : files) {
      const bool changed = codegen::write_if_changed(target / file.relative, file.content);
      written += changed;
      if (verbose) std::cout << (changed ? "wrote     " : "unchanged ") << (target / file.relative).string() << "\n";
    }
    std::cout << "backlash_codegen: " << files.size() << " files, " << written << " rewritten\n";
  } catch (const std::exception& error) {
    std::string message = error.what();
    for (char& c : message)
      if (c == '\n') c = ' ';
    std::cerr << "backlash_codegen: error: " << message << "\n";
    return 1;
  }
  return 0;
}
