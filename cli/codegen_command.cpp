// `backlash codegen CASE --out DIR` — writes the self-contained evaluator
// header for a case (case_<ID>.hpp, depends only on <cmath>) and the LaTeX of
// its expressions (case_<ID>.tex) into DIR.  CASE = I…VIII or a case file.
// The files come from the GiNaC facade (api/derive.hpp: api::generate_code).
#include "commands.hpp"

#include "backlash/api/derive.hpp"
#include "backlash/output/atomic_file.hpp"
#include "backlash/output/target.hpp"

#include <iostream>
#include <memory>

namespace backlash::cli {

namespace {

struct CodegenOptions {
  std::string case_name;
  std::string out;
};

void run_codegen(const CodegenOptions& options) {
  if (options.out.empty()) throw UsageError("codegen: --out DIR is required");
  const std::filesystem::path out(options.out);
  output::check_target(out, output::Target::file_folder);
  const api::Case source = api::load(options.case_name);  // the one route to a case
  output::OutputFiles files;
  std::vector<std::filesystem::path> names;
  for (api::GeneratedFile& file : api::generate_code(source)) {
    names.push_back(out / file.name);
    files.add(file.name, std::move(file.content));
  }
  files.commit(out);
  for (const auto& name : names) std::cout << "wrote " << name.string() << "\n";
}

}  // namespace

void register_codegen_command(CLI::App& app) {
  auto options = std::make_shared<CodegenOptions>();
  CLI::App* command = app.add_subcommand(
      "codegen", "Write the C++ evaluator header of a case (depends only on <cmath>) and its LaTeX, for embedding");
  command->add_option("CASE", options->case_name, "I..VIII or a case file path")->required();
  command->add_option("--out", options->out, "folder to write case_<ID>.hpp and case_<ID>.tex into")->required();
  command->callback([options] { run_codegen(*options); });
}

}  // namespace backlash::cli
