// `backlash explorer --out DIR` — writes the explorer page (DIR/index.html): the phase plane of
// the exact hybrid system in the browser, one self-contained file (explorer/README.md) that the
// build makes with Emscripten and keeps in the data folder (share/backlash/explorer/index.html,
// model/data_dir.hpp).  A build without emcc has no page: said, exit 1.
#include "commands.hpp"

#include "backlash/model/data_dir.hpp"
#include "backlash/output/atomic_file.hpp"
#include "backlash/output/target.hpp"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace backlash::cli {

namespace {

void run_explorer(const std::string& out_text) {
  const std::filesystem::path out(out_text);
  output::check_target(out, output::Target::file_folder);
  const std::filesystem::path page = model::data_dir() / "explorer" / "index.html";
  std::ifstream in(page, std::ios::binary);
  if (!in)
    throw std::runtime_error("the explorer page " + page.string() +
                             " is missing: this build had no emcc (Debian package emscripten; explorer/README.md)");
  std::ostringstream content;
  content << in.rdbuf();
  output::OutputFiles files;
  files.add("index.html", content.str());
  files.commit(out);
  std::cout << "wrote " << (out / "index.html").string() << "\n";
}

}  // namespace

void register_explorer_command(CLI::App& app) {
  auto out = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand("explorer", "Write the explorer page (the phase plane in the browser, one file)");
  command->add_option("--out", *out, "folder to write index.html into")->required();
  command->callback([out] { run_explorer(*out); });
}

}  // namespace backlash::cli
