// Text from outside — a case file's `name` — made safe for every output language:
// C++ (the generated header must compile, the literal must hold the name), LaTeX
// (`derive --latex` must compile with pdflatex), Markdown, CSV and JSON.
#include "backlash/codegen/emit.hpp"
#include "backlash/model/case_spec.hpp"
#include "backlash/symbolic/case_derivation.hpp"
#include "backlash/symbolic/escape.hpp"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;
namespace escape = backlash::symbolic::escape;

// A name with everything that broke an output: a line break, quotes, a backslash,
// LaTeX's specials and a command, Markdown's table bar, a trigraph, a comment end.
const std::string hostile_name = "Case \"X\" \\ % _ # & $ ^ ~ { } < > | \\input{x} ?\?= */ // line one\nline two\tend";

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("backlash-escaping-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

// The scratch folder goes when the test process ends.
struct ScratchCleanup {
  ~ScratchCleanup() {
    std::error_code ignored;
    fs::remove_all(fs::temp_directory_path() / ("backlash-escaping-" + std::to_string(::getpid())), ignored);
  }
} scratch_cleanup;

// A case file whose TOML basic string holds `name` (escaped for TOML).
fs::path case_file(const std::string& stem, const std::string& toml_name) {
  const fs::path file = scratch(stem + ".toml");
  std::ofstream(file) << "name = \"" << toml_name << "\"\nmeasured_at = \"load\"\nK = 1\nbacklash = 0.3\nreference = 1\n"
                      << "[motor]\nJ = 0.5\nF = 0.1\n[load]\nJ = 0.5\nF = 0.3\n";
  return file;
}

std::string toml_escaped(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\', out += c;
    else if (c == '\n') out += "\\n";
    else if (c == '\t') out += "\\t";
    else out += c;
  }
  return out;
}

int run(const std::string& command, std::string* output = nullptr) {
  FILE* pipe = popen(command.c_str(), "r");
  std::string out;
  std::array<char, 4096> buffer;
  while (std::size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe)) out.append(buffer.data(), n);
  const int status = pclose(pipe);
  if (output) *output = out;
  return WEXITSTATUS(status);
}

TEST(Escaping, LatexText) {
  EXPECT_EQ(escape::latex_text("a%b_c#d&e$f"), "a\\%b\\_c\\#d\\&e\\$f");
  EXPECT_EQ(escape::latex_text("\\input{x}"), "\\textbackslash{}input\\{x\\}");
  EXPECT_EQ(escape::latex_text("^~<>"), "\\textasciicircum{}\\textasciitilde{}\\textless{}\\textgreater{}");
  EXPECT_EQ(escape::latex_text(std::string("a\nb\0c", 5)), "a bc");
  EXPECT_EQ(escape::latex_text("θ̇o ≤ 1"), "\\ensuremath{\\dot\\theta}o \\ensuremath{\\le} 1");
  EXPECT_EQ(escape::latex_text("\xff"), "?");
}

TEST(Escaping, MarkdownText) {
  EXPECT_EQ(escape::markdown_text("a|b*c_d"), "a\\|b\\*c\\_d");
  EXPECT_EQ(escape::markdown_text("line one\nline two"), "line one line two");
  EXPECT_EQ(escape::markdown_text("[x](y) <b> `c` $m$"), "\\[x\\](y) \\<b\\> \\`c\\` \\$m\\$");
}

TEST(Escaping, CsvField) {
  EXPECT_EQ(escape::csv_field("plain"), "plain");
  EXPECT_EQ(escape::csv_field("a,b"), "\"a,b\"");
  EXPECT_EQ(escape::csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(escape::csv_field("two\nlines"), "\"two\nlines\"");
}

TEST(Escaping, CppStringLiteral) {
  EXPECT_EQ(escape::cpp_string_literal("a\"b\\c"), "\"a\\\"b\\\\c\"");
  EXPECT_EQ(escape::cpp_string_literal("a\nb"), "\"a\\nb\"");
  EXPECT_EQ(escape::cpp_string_literal(std::string("a\0b", 3)), "\"a\\000b\"");
  EXPECT_EQ(escape::cpp_string_literal("?\?="), "\"\\?\\?=\"");
  EXPECT_EQ(escape::cpp_comment("one\ntwo\\"), "one two");
}

TEST(Escaping, JsonRepairsInvalidUtf8) {
  EXPECT_EQ(escape::valid_utf8("ok θ"), "ok θ");
  EXPECT_EQ(escape::valid_utf8("a\xff" "b"), "a\xEF\xBF\xBD" "b");
}

TEST(Escaping, GeneratedHeaderWithAHostileNameCompilesAndHoldsTheName) {
  const fs::path file = case_file("hostile", toml_escaped(hostile_name));
  const backlash::model::CaseSpec spec = backlash::model::load_case_file(file);
  ASSERT_EQ(spec.name, hostile_name);
  const std::string header = backlash::codegen::emit_case_header(spec, backlash::symbolic::derive_case(spec));
  const fs::path hpp = scratch("hostile.hpp"), cpp = scratch("main.cpp"), exe = scratch("main");
  std::ofstream(hpp) << header;
  std::ofstream(cpp) << "#include \"hostile.hpp\"\n#include <cstdio>\n"
                        "int main() { std::fputs(backlash::generated::" << backlash::codegen::case_namespace(spec.id)
                     << "::metadata::case_name, stdout); return 0; }\n";
  const std::string compile = std::string(BACKLASH_CXX_COMPILER) + " -std=c++20 -trigraphs -Werror=trigraphs -o " + exe.string() +
                              " " + cpp.string() + " 2>&1";
  std::string diagnostics;
  ASSERT_EQ(run(compile, &diagnostics), 0) << "the generated header does not compile:\n" << diagnostics;
  std::string printed;
  ASSERT_EQ(run(exe.string(), &printed), 0);
  EXPECT_EQ(printed, hostile_name) << "the literal holds '" << printed << "'";
}

TEST(Escaping, GeneratedHeaderKeepsANulVisible) {
  const fs::path file = case_file("nul", "before\\u0000after");
  backlash::model::CaseSpec spec;
  try {
    spec = backlash::model::load_case_file(file);
  } catch (const std::exception& e) {
    GTEST_SKIP() << "the loader rejects a NUL in a name: " << e.what();
  }
  const std::string header = backlash::codegen::emit_case_header(spec, backlash::symbolic::derive_case(spec));
  EXPECT_EQ(header.find('\0'), std::string::npos) << "a raw NUL byte in the header";
  EXPECT_NE(header.find("before\\000after"), std::string::npos);
}

TEST(Escaping, DeriveLatexWithAHostileNameCompiles) {
  if (std::system("command -v pdflatex > /dev/null 2>&1") != 0) GTEST_SKIP() << "pdflatex is not installed";
  const fs::path file = case_file("hostile_latex", toml_escaped(hostile_name));
  std::string latex;
  ASSERT_EQ(run(std::string(BACKLASH_CLI) + " derive " + file.string() + " --latex", &latex), 0);
  const fs::path dir = scratch("latex");
  fs::create_directories(dir);
  std::ofstream(dir / "doc.tex") << "\\documentclass{article}\\usepackage[utf8]{inputenc}\\usepackage{amsmath,amssymb,longtable,booktabs,array}"
                                    "\\usepackage[margin=1.5cm]{geometry}\\begin{document}\n"
                                 << latex << "\\end{document}\n";
  std::string log;
  const int status = run("cd " + dir.string() + " && pdflatex -interaction=nonstopmode -halt-on-error doc.tex 2>&1", &log);
  EXPECT_EQ(status, 0) << log.substr(log.size() > 3000 ? log.size() - 3000 : 0);
  EXPECT_FALSE(fs::exists(dir / "x.tex")) << "\\input{x} was executed";
}

TEST(Escaping, DeriveJsonWithAHostileNameIsValidJson) {
  const fs::path file = case_file("hostile_json", toml_escaped(hostile_name));
  std::string out;
  ASSERT_EQ(run(std::string(BACKLASH_CLI) + " derive " + file.string() + " --json", &out), 0);
  const nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_EQ(j["name"], hostile_name);
}

}  // namespace
