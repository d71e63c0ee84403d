// check_emitted_header — what the emitter writes:
//  * `backlash codegen CASE --out DIR` writes a header that compiles stand-alone
//    with -std=c++20 -Wall -Wextra -Werror -pedantic (the compiler CMake uses)
//    and whose values equal the exact expressions (thesis case V and a custom
//    case file with an over-damped contact mode, output at the motor, FL = 0);
//  * the header includes only <cmath>, carries the banner and the input hash,
//    never writes C integer division, and is identical from run to run;
//  * backlash_codegen rewrites nothing on a second run (write-if-changed) and
//    fails with a non-zero status when it cannot write;
//  * the CLI rejects bad input with exit code 2 and one line.
#include "exact_reference.hpp"

#include "backlash/codegen/emit.hpp"
#include "backlash/model/case_spec.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <cctype>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#ifndef BACKLASH_CXX_COMPILER
#error "BACKLASH_CXX_COMPILER must be defined by CMake"
#endif

namespace fs = std::filesystem;

namespace {

struct CommandResult {
  int status = -1;
  std::string output;
};

CommandResult run(const std::string& command) {
  CommandResult r;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return r;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe)) r.output += buffer;
  const int raw = pclose(pipe);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

fs::path fresh_directory(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("backlash_" + name + std::string("_") + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string quote(const fs::path& p) { return std::string("'") + p.string() + "'"; }

const char* custom_case = R"toml(# An over-damped case measured at the motor, load without friction.
name = "Custom overdamped"
measured_at = "motor"
K = 1
backlash = 0.25
reference = "-1/3"
[motor]
J = 0.25
F = 1.5
[load]
J = 0.5
F = 0
)toml";

// Compile a program that includes the emitted header and prints the states.
std::vector<double> compile_and_run(const fs::path& dir, const std::string& ns, const std::string& header,
                                    const std::vector<std::pair<double, double>>& free_points,
                                    const std::vector<std::tuple<double, double, double>>& contact_points) {
  std::ostringstream program;
  program << "#include \"" << header << "\"\n#include <cstdio>\n";
  program << "int main() {\n  namespace g = backlash::generated::" << ns << ";\n";
  for (auto [t, v] : free_points) {
    program << "  { const double t = " << std::hexfloat << t << ", v = " << v << std::defaultfloat << ";\n"
            << "    std::printf(\"%a %a %a %a %a\\n\", g::theta_m(t, v), g::dtheta_m(t, v), g::theta_L(t, v), "
               "g::dtheta_L(t, v), g::gap(t, v)); }\n";
  }
  for (auto [t, x, v] : contact_points) {
    program << "  { const double t = " << std::hexfloat << t << ", x = " << x << ", v = " << v << std::defaultfloat
            << ";\n    std::printf(\"%a %a\\n\", g::theta_o(t, x, v), g::dtheta_o(t, x, v)); }\n";
  }
  program << "  std::printf(\"%a\\n\", g::cot_phi);\n  return 0;\n}\n";
  std::ofstream(dir / "main.cpp") << program.str();
  const std::string compile = std::string(BACKLASH_CXX_COMPILER) + " -std=c++20 -Wall -Wextra -Werror -pedantic -O2 -I" +
                              quote(dir) + std::string(" ") + quote(dir / "main.cpp") + std::string(" -o ") + quote(dir / "program");
  const CommandResult compiled = run(compile);
  EXPECT_EQ(compiled.status, 0) << "the emitted header does not compile stand-alone:\n" << compiled.output;
  if (compiled.status != 0) return {};
  const CommandResult ran = run(quote(dir / "program"));
  EXPECT_EQ(ran.status, 0) << ran.output;
  std::vector<double> values;
  std::istringstream in(ran.output);
  for (std::string word; in >> word;) values.push_back(std::strtod(word.c_str(), nullptr));
  return values;
}

void expect_values(const backlash::model::CaseSpec& spec, const std::vector<double>& values,
                   const std::vector<std::pair<double, double>>& free_points,
                   const std::vector<std::tuple<double, double, double>>& contact_points) {
  const auto exact = backlash::testing::exact_case(spec);
  ASSERT_EQ(values.size(), free_points.size() * 5 + contact_points.size() * 2 + 1);
  std::size_t i = 0;
  const char* free_names[] = {"theta_m", "dtheta_m", "theta_L", "dtheta_L", "gap"};
  const GiNaC::ex* free_exact[] = {&exact.theta_m, &exact.dtheta_m, &exact.theta_L, &exact.dtheta_L, &exact.gap};
  for (auto [t, v] : free_points)
    for (int k = 0; k < 5; ++k, ++i) {
      const double expected = backlash::testing::free_value(*free_exact[k], t, v);
      EXPECT_LE(backlash::testing::scaled_error(values[i], expected), 1e-12)
          << spec.id << ": emitted " << free_names[k] << "(" << t << ", " << v << ") returned " << values[i]
          << " instead of " << expected;
    }
  for (auto [t, x, v] : contact_points) {
    const double eo = backlash::testing::contact_value(exact.theta_o, t, x, v);
    const double ed = backlash::testing::contact_value(exact.dtheta_o, t, x, v);
    EXPECT_LE(backlash::testing::scaled_error(values[i], eo), 1e-12)
        << spec.id << ": emitted theta_o returned " << values[i] << " instead of " << eo;
    EXPECT_LE(backlash::testing::scaled_error(values[i + 1], ed), 1e-12)
        << spec.id << ": emitted dtheta_o returned " << values[i + 1] << " instead of " << ed;
    i += 2;
  }
  const double cot = backlash::symbolic::to_double(exact.cot_phi, {});
  EXPECT_EQ(values[i], cot) << "emitted cot_phi returned " << values[i] << " instead of " << cot;
}

// "p/q" with integer literals p, q (C integer division), e.g. "5/12" but not "5.0/12.0".
bool has_integer_division(const std::string& code) {
  auto digit = [](char c) { return c >= '0' && c <= '9'; };
  auto word = [&](char c) { return digit(c) || std::isalpha(static_cast<unsigned char>(c)) || c == '_' || c == '.'; };
  for (std::size_t slash = code.find('/'); slash != std::string::npos; slash = code.find('/', slash + 1)) {
    std::size_t left = slash;
    while (left > 0 && code[left - 1] == ' ') --left;
    std::size_t begin = left;
    while (begin > 0 && digit(code[begin - 1])) --begin;
    if (begin == left || (begin > 0 && word(code[begin - 1]))) continue;  // no integer on the left
    std::size_t right = slash + 1;
    while (right < code.size() && code[right] == ' ') ++right;
    std::size_t end = right;
    while (end < code.size() && digit(code[end])) ++end;
    if (end == right || (end < code.size() && (code[end] == '.' || word(code[end])))) continue;
    return true;
  }
  return false;
}

const std::vector<std::pair<double, double>> free_points{{0.0, 0.5}, {0.25, -1.0}, {2.0, 0.01}, {7.5, 1.5}};
const std::vector<std::tuple<double, double, double>> contact_points{{0.0, 0.2, 0.0}, {1.5, -0.4, 0.3}, {9.0, 1.3, -1.0}};

TEST(EmittedHeader, thesis_case_compiles_stand_alone_and_gives_the_exact_values) {
  const fs::path dir = fresh_directory("codegen_V");
  const CommandResult cli = run(std::string(BACKLASH_CLI) + std::string(" codegen V --out ") + quote(dir));
  ASSERT_EQ(cli.status, 0) << cli.output;
  ASSERT_TRUE(fs::exists(dir / "case_V.hpp")) << cli.output;
  ASSERT_TRUE(fs::exists(dir / "case_V.tex")) << cli.output;
  const std::vector<double> values = compile_and_run(dir, "case_V", "case_V.hpp", free_points, contact_points);
  expect_values(backlash::model::load_case("V"), values, free_points, contact_points);
  fs::remove_all(dir);
}

TEST(EmittedHeader, custom_case_file_compiles_stand_alone_and_gives_the_exact_values) {
  const fs::path dir = fresh_directory("codegen_custom");
  const fs::path file = dir / "custom-over.toml";
  std::ofstream(file) << custom_case;
  const CommandResult cli = run(std::string(BACKLASH_CLI) + std::string(" codegen ") + quote(file) + std::string(" --out ") + quote(dir / "out"));
  ASSERT_EQ(cli.status, 0) << cli.output;
  const std::vector<double> values =
      compile_and_run(dir / "out", "case_custom_over", "case_custom_over.hpp", free_points, contact_points);
  expect_values(backlash::model::load_case(file.string()), values, free_points, contact_points);
  fs::remove_all(dir);
}

TEST(GeneratedHeaders, build_time_headers_compile_stand_alone_with_pedantic_warnings) {
  // every header backlash_codegen wrote at build time, together: the eight cases and the branches
  const fs::path dir = fresh_directory("generated_headers");
  std::ofstream(dir / "main.cpp") << R"cpp(#include "backlash/generated/cases.hpp"
#include "backlash/generated/branches.hpp"
#include <cstdio>
int main() {
  namespace g = backlash::generated;
  const g::branches::Parameters p{g::case_V::Jm, g::case_V::Fm, g::case_V::JL, g::case_V::FL, g::case_V::K, g::case_V::theta_R};
  const auto a = g::case_V::free_state(2.5, 0.3);
  const auto b = g::branches::load_generic::free_state(p, 2.5, 0.3);
  std::printf("%a %a %a %a\n", a.theta_m, b.theta_m, a.gap, b.gap);
  return 0;
}
)cpp";
  const CommandResult compiled =
      run(std::string(BACKLASH_CXX_COMPILER) + " -std=c++20 -Wall -Wextra -Werror -pedantic -O2 -I" +
          quote(BACKLASH_GENERATED_DIR) + " " + quote(dir / "main.cpp") + " -o " + quote(dir / "program"));
  ASSERT_EQ(compiled.status, 0) << "the generated headers do not compile stand-alone:\n" << compiled.output;
  const CommandResult ran = run(quote(dir / "program"));
  ASSERT_EQ(ran.status, 0) << ran.output;
  std::istringstream in(ran.output);
  std::string w[4];
  in >> w[0] >> w[1] >> w[2] >> w[3];
  const double case_theta = std::strtod(w[0].c_str(), nullptr), branch_theta = std::strtod(w[1].c_str(), nullptr);
  const double case_gap = std::strtod(w[2].c_str(), nullptr), branch_gap = std::strtod(w[3].c_str(), nullptr);
  EXPECT_NEAR(branch_theta, case_theta, 1e-12) << "load_generic theta_m returned " << branch_theta << " instead of "
                                               << case_theta;
  EXPECT_NEAR(branch_gap, case_gap, 1e-12) << "load_generic gap returned " << branch_gap << " instead of " << case_gap;
  fs::remove_all(dir);
}

TEST(EmittedHeader, depends_only_on_cmath_and_carries_banner_and_hash) {
  const auto spec = backlash::model::load_case("VII");
  const std::string header = backlash::codegen::emit_case_files(spec).front().content;
  std::vector<std::string> includes;
  std::istringstream lines(header);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("#include", 0) == 0) includes.push_back(line);
  EXPECT_EQ(includes, std::vector<std::string>{"#include <cmath>"});
  const std::string hash = backlash::codegen::describe_source(spec).input_hash;
  const std::string banner = std::string("// generated by ") + backlash::codegen::generator_name() + std::string(" from cases/VII.toml (") + hash +
                             ") \u2014 do not edit";
  EXPECT_EQ(header.substr(0, banner.size()), banner) << "the header starts with " << header.substr(0, banner.size())
                                                     << " instead of " << banner;
  EXPECT_NE(header.find("const double e_m3_8 = std::exp((-3.0/8.0)*t);"), std::string::npos)
      << "exp(-3t/8) of case VII's load is not hoisted into a named constant";
}

TEST(EmittedHeader, never_writes_integer_division) {
  EXPECT_TRUE(has_integer_division("x = 5/12;"));
  EXPECT_TRUE(has_integer_division("(1 / 3)"));
  EXPECT_FALSE(has_integer_division("(5.0/12.0)*t"));
  EXPECT_FALSE(has_integer_division("e_m1_5/2.0"));
  for (const std::string& id : backlash::model::thesis_case_ids()) {
    const std::string header = backlash::codegen::emit_case_files(backlash::model::load_case(id)).front().content;
    std::istringstream lines(header);
    bool in_latex = false;
    for (std::string line; std::getline(lines, line);) {
      if (line.find("struct latex {") != std::string::npos) in_latex = true;
      if (in_latex) {
        if (line == "};") in_latex = false;
        continue;
      }
      const std::string code = line.substr(0, line.find("//"));
      if (code.find('"') != std::string::npos) continue;  // metadata strings
      EXPECT_FALSE(has_integer_division(code)) << "case " << id << ": integer division in: " << line;
    }
  }
  std::ifstream branches(fs::path(BACKLASH_GENERATED_DIR) / "backlash" / "generated" / "branches.hpp");
  ASSERT_TRUE(branches) << "no generated branches.hpp";
  long code_lines = 0;
  for (std::string line; std::getline(branches, line);) {
    const std::string code = line.substr(0, line.find("//"));
    if (code.find('"') != std::string::npos) continue;
    code_lines += !code.empty();
    EXPECT_FALSE(has_integer_division(code)) << "branches.hpp: integer division in: " << line;
  }
  EXPECT_GT(code_lines, 100);
}

TEST(EmittedHeader, is_identical_from_run_to_run) {
  for (const char* id : {"I", "IV", "VIII"}) {
    const auto spec = backlash::model::load_case(id);
    const std::string first = backlash::codegen::emit_case_files(spec).front().content;
    const std::string second = backlash::codegen::emit_case_files(spec).front().content;
    EXPECT_EQ(first, second) << "case " << id << " emitted differently on a second run";
  }
}

TEST(EmittedLatex, has_every_state) {
  const auto derivation = backlash::symbolic::derive_case(backlash::model::load_case("III"));
  const auto latex = backlash::codegen::case_latex(derivation);
  for (const char* key :
       {"theta_m", "dtheta_m", "theta_L", "dtheta_L", "gap", "theta_o", "dtheta_o", "cot_phi", "separation_theta"}) {
    ASSERT_TRUE(latex.count(key)) << "no LaTeX for " << key;
    EXPECT_FALSE(latex.at(key).empty()) << "empty LaTeX for " << key;
  }
  EXPECT_NE(latex.at("theta_o").find("\\sqrt{"), std::string::npos) << latex.at("theta_o");
}

TEST(Generator, rewrites_nothing_on_a_second_run) {
  const fs::path dir = fresh_directory("generator");
  const std::string command = std::string(BACKLASH_CODEGEN) + std::string(" --cases-dir ") + quote(BACKLASH_SOURCE_CASES) +
                              std::string(" --out ") + quote(dir);
  const CommandResult first = run(command);
  ASSERT_EQ(first.status, 0) << first.output;
  const fs::path header = dir / "backlash" / "generated" / "case_V.hpp";
  ASSERT_TRUE(fs::exists(header));
  const auto stamp = fs::last_write_time(header);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const CommandResult second = run(command);
  ASSERT_EQ(second.status, 0) << second.output;
  EXPECT_NE(second.output.find(", 0 rewritten"), std::string::npos) << second.output;
  EXPECT_EQ(fs::last_write_time(header), stamp) << "a no-op run touched case_V.hpp";
  fs::remove_all(dir);
}

TEST(Generator, fails_when_it_cannot_write) {
  const fs::path dir = fresh_directory("generator_blocked");
  std::ofstream(dir / "backlash") << "a file where the output folder should be";
  const CommandResult blocked = run(std::string(BACKLASH_CODEGEN) + std::string(" --cases-dir ") + quote(BACKLASH_SOURCE_CASES) + " --out " +
                          quote(dir));
  EXPECT_NE(blocked.status, 0) << "backlash_codegen returned 0 although it could not write:\n" << blocked.output;
  EXPECT_NE(blocked.output.find("error"), std::string::npos) << blocked.output;
  fs::remove_all(dir);
}

TEST(Cli, codegen_and_validate_reject_bad_input_with_exit_code_2) {
  const CommandResult unknown = run(std::string(BACKLASH_CLI) + " codegen NOPE --out /tmp/nowhere");
  EXPECT_EQ(unknown.status, 2) << unknown.output;
  EXPECT_EQ(std::count(unknown.output.begin(), unknown.output.end(), '\n'), 1) << unknown.output;
  const CommandResult missing_out = run(std::string(BACKLASH_CLI) + " codegen V");
  EXPECT_EQ(missing_out.status, 2) << missing_out.output;
  const CommandResult nothing = run(std::string(BACKLASH_CLI) + " validate");
  EXPECT_EQ(nothing.status, 2) << nothing.output;
  const CommandResult bad_case = run(std::string(BACKLASH_CLI) + " validate NOPE");
  EXPECT_EQ(bad_case.status, 2) << bad_case.output;
}

}  // namespace
