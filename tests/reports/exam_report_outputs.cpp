// `backlash report` as a user runs it (the built CLI, separate processes): the
// output is byte-reproducible (two runs, same bytes — and `derive` too), the PDF's
// pages render and are not blank, every figure is drawn, the output appears all
// at once (no temporary folder left, an old report replaced as a whole), and a
// bad --out is a one-line error with exit code 2 and nothing written.
#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;

struct CommandRun {
  int exit_code;
  std::string out, err;
};

CommandRun run(const std::string& command_line) {
  const fs::path err_file = fs::temp_directory_path() / ("backlash-report-test-" + std::to_string(::getpid()) + ".err");
  FILE* pipe = popen((command_line + " 2> " + err_file.string()).c_str(), "r");
  std::string out;
  std::array<char, 4096> buffer;
  while (std::size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe)) out.append(buffer.data(), n);
  const int status = pclose(pipe);
  std::ifstream in(err_file);
  std::string err((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  fs::remove(err_file);
  return {WEXITSTATUS(status), out, err};
}

CommandRun backlash(const std::string& arguments) { return run(std::string(BACKLASH_CLI) + " " + arguments); }

std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::map<std::string, std::string> tree(const fs::path& root) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(root))
    if (entry.is_regular_file()) files[fs::relative(entry.path(), root).string()] = read(entry.path());
  return files;
}

bool pdflatex_installed() { return std::system("command -v pdflatex > /dev/null 2>&1") == 0; }

// The reports are written once per test process, when a test first needs them (ctest runs
// each test in its own process).
class ReportRuns : public ::testing::Test {
 protected:
  static const fs::path& base() {
    static const fs::path path = [] {
      const fs::path p = fs::temp_directory_path() / ("backlash-report-runs-" + std::to_string(::getpid()));
      fs::remove_all(p);
      fs::create_directories(p);
      return p;
    }();
    return path;
  }
  static const fs::path first, second;
  static const CommandRun& first_run() {
    static const CommandRun r = backlash("report --out " + (base() / "first").string());
    return r;
  }
  static const CommandRun& second_run() {
    static const CommandRun r = backlash("report --out " + (base() / "second").string());
    return r;
  }
  static void TearDownTestSuite() { fs::remove_all(base()); }
};
const fs::path ReportRuns::first = "first", ReportRuns::second = "second";

TEST_F(ReportRuns, TwoRunsWriteTheSameBytes) {
  ASSERT_EQ(first_run().exit_code, 0) << first_run().err;
  ASSERT_EQ(second_run().exit_code, 0) << second_run().err;
  const auto a = tree(base() / first), b = tree(base() / second);
  ASSERT_EQ(a.size(), b.size()) << "returned " << a.size() << " and " << b.size() << " files";
  int differing = 0;
  for (const auto& [path, bytes] : a) {
    const auto other = b.find(path);
    ASSERT_NE(other, b.end()) << path << " is missing from the second run";
    if (other->second != bytes && ++differing <= 5) ADD_FAILURE() << path << " differs between two runs";
  }
  EXPECT_EQ(differing, 0) << differing << " files differ";
}

TEST_F(ReportRuns, LeavesThePagesTheFiguresAndThePdf) {
  ASSERT_EQ(first_run().exit_code, 0) << first_run().err;
  const fs::path first = base() / ReportRuns::first;
  for (const char* id : {"I", "II", "III", "IV", "V", "VI", "VII", "VIII"})
    EXPECT_TRUE(fs::exists(first / "cases" / (std::string(id) + ".md"))) << "no page for case " << id;
  for (const char* page : {"README.md", "general.md", "errata.md", "report.tex"}) EXPECT_TRUE(fs::exists(first / page)) << page;
  int figures = 0;
  for (const auto& entry : fs::directory_iterator(first / "figures")) {
    if (entry.path().extension() != ".csv") continue;
    ++figures;
    fs::path svg = entry.path(), pdf = entry.path();
    svg.replace_extension(".svg");
    pdf.replace_extension(".pdf");
    ASSERT_TRUE(fs::exists(svg)) << svg;
    const std::string svg_text = read(svg);
    EXPECT_NE(svg_text.find("<svg"), std::string::npos) << svg;
    // gnuplot splits "θ_{m} and θ_{L}" into tspans; without xml:space="preserve" renderers
    // drop the space that starts one ("θmand θL")
    EXPECT_EQ(svg_text.find("<text>"), std::string::npos) << svg << ": a <text> that collapses its spaces";
    EXPECT_NE(svg_text.find("<text xml:space=\"preserve\">"), std::string::npos) << svg;
    ASSERT_TRUE(fs::exists(pdf)) << pdf;
    EXPECT_EQ(read(pdf).rfind("%PDF", 0), 0u) << pdf;
  }
  EXPECT_GE(figures, 23) << "returned " << figures << " figures";
  const std::string index = read(first / "README.md");
  if (pdflatex_installed()) {
    EXPECT_TRUE(fs::exists(first / "report.pdf"));
    EXPECT_NE(index.find("report.pdf: compiled with pdflatex"), std::string::npos);
  } else {
    EXPECT_NE(index.find("pdflatex is not installed"), std::string::npos);
    EXPECT_NE(first_run().err.find("pdflatex is not installed"), std::string::npos);
  }
}

TEST_F(ReportRuns, EveryPdfPageRendersAndIsNotBlank) {
  ASSERT_EQ(first_run().exit_code, 0) << first_run().err;
  const fs::path first = base() / ReportRuns::first;
  if (!fs::exists(first / "report.pdf")) GTEST_SKIP() << "no report.pdf (pdflatex not installed)";
  const fs::path pages = base() / "pages";
  fs::create_directories(pages);
  const CommandRun r = run("pdftoppm -r 30 -gray " + (first / "report.pdf").string() + " " + (pages / "p").string());
  ASSERT_EQ(r.exit_code, 0) << "pdftoppm failed: " << r.err;
  const CommandRun info = run("pdfinfo " + (first / "report.pdf").string());
  const auto at = info.out.find("Pages:");
  ASSERT_NE(at, std::string::npos);
  const int page_count = std::atoi(info.out.c_str() + at + 6);
  EXPECT_GT(page_count, 50) << "returned " << page_count << " pages";
  int rendered = 0;
  for (const auto& entry : fs::directory_iterator(pages)) {
    const std::string pgm = read(entry.path());
    // P5 header: "P5\n<w> <h>\n255\n"
    std::istringstream header(pgm);
    std::string magic;
    int w = 0, h = 0, max = 0;
    header >> magic >> w >> h >> max;
    ASSERT_EQ(magic, "P5") << entry.path();
    const std::size_t offset = static_cast<std::size_t>(header.tellg()) + 1;
    ASSERT_EQ(pgm.size(), offset + static_cast<std::size_t>(w * h)) << entry.path();
    // dark pixels above the footer (the page number alone does not make a page)
    long dark = 0;
    for (int y = 0; y < h * 9 / 10; ++y)
      for (int x = 0; x < w; ++x) dark += static_cast<unsigned char>(pgm[offset + static_cast<std::size_t>(y * w + x)]) < 220;
    EXPECT_GT(dark, 10) << entry.path() << " is blank";
    ++rendered;
  }
  EXPECT_EQ(rendered, page_count);
}

TEST_F(ReportRuns, NothingInThePdfRunsIntoTheMargin) {
  // pdflatex reports every line it could not fit ("Overfull \hbox (47.5pt too wide)"): an
  // equation, a table or a word running past the text into the margin or off the page.
  // report.tex is compiled again here (the report removes the log) and no line may
  // stick out by more than 5 pt.
  ASSERT_EQ(first_run().exit_code, 0) << first_run().err;
  if (!pdflatex_installed()) GTEST_SKIP() << "pdflatex is not installed";
  const fs::path source = base() / ReportRuns::first, build = base() / "latex";
  fs::create_directories(build);
  fs::copy_file(source / "report.tex", build / "report.tex");
  fs::copy(source / "figures", build / "figures", fs::copy_options::recursive);
  const CommandRun latex = run("cd " + build.string() + " && pdflatex -interaction=nonstopmode -halt-on-error -draftmode report.tex > /dev/null");
  const std::string log = read(build / "report.log");
  ASSERT_EQ(latex.exit_code, 0) << "report.tex did not compile: " << log.substr(log.size() > 2000 ? log.size() - 2000 : 0);
  int over = 0;
  for (std::size_t at = log.find("Overfull \\hbox ("); at != std::string::npos; at = log.find("Overfull \\hbox (", at + 1)) {
    const double points = std::atof(log.c_str() + at + 16);
    if (points > 5 && ++over <= 5)
      ADD_FAILURE() << "returned a line " << points << " pt too wide: " << log.substr(at, log.find('\n', log.find('\n', at) + 1) - at);
  }
  EXPECT_EQ(over, 0) << over << " lines run into the margin";
}

TEST_F(ReportRuns, NoTemporaryFolderIsLeftAndAnOldReportIsReplacedWhole) {
  ASSERT_EQ(first_run().exit_code, 0) << first_run().err;
  const fs::path first = base() / ReportRuns::first;
  std::ofstream(first / "stale.txt") << "from an older report";
  const CommandRun again = backlash("report --no-pdf --out " + first.string());
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_FALSE(fs::exists(first / "stale.txt")) << "the old report was merged, not replaced";
  for (const auto& entry : fs::directory_iterator(base()))
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << "left behind: " << entry.path();
}

TEST(ReportWithoutPdflatex, SaysSoInTheIndexAndOnStderrAndStillSucceeds) {
  // A PATH with gnuplot but no pdflatex.
  const fs::path base = fs::temp_directory_path() / ("backlash-report-nopdf-" + std::to_string(::getpid()));
  fs::remove_all(base);
  fs::create_directories(base / "bin");
  const CommandRun which = run("command -v gnuplot");
  if (which.exit_code != 0) GTEST_SKIP() << "gnuplot is not installed";
  std::string gnuplot = which.out;
  while (!gnuplot.empty() && gnuplot.back() == '\n') gnuplot.pop_back();
  fs::create_symlink(gnuplot, base / "bin" / "gnuplot");
  const CommandRun r = run("PATH=" + (base / "bin").string() + " " + BACKLASH_CLI + " report --out " + (base / "report").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("pdflatex is not installed"), std::string::npos) << "stderr: " << r.err;
  EXPECT_NE(read(base / "report" / "README.md").find("pdflatex is not installed"), std::string::npos);
  EXPECT_FALSE(fs::exists(base / "report" / "report.pdf"));
  EXPECT_TRUE(fs::exists(base / "report" / "report.tex"));
  fs::remove_all(base);
}

TEST(ReportBadInput, BadOutIsAOneLineErrorWithExitCode2AndNothingWritten) {
  const fs::path base = fs::temp_directory_path() / ("backlash-report-bad-" + std::to_string(::getpid()));
  fs::remove_all(base);
  fs::create_directories(base / "not_a_report");
  std::ofstream(base / "not_a_report" / "keep.txt") << "mine";
  std::ofstream(base / "a_file") << "mine";
  for (const std::string& out : {(base / "missing" / "report").string(), (base / "a_file").string(), (base / "not_a_report").string(),
                                 std::string("''")}) {
    const CommandRun r = backlash("report --out " + out);
    EXPECT_EQ(r.exit_code, 2) << out << ": returned " << r.exit_code << " instead of 2: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << out << ": not one line: " << r.err;
    EXPECT_TRUE(r.out.empty()) << out << ": printed " << r.out;
  }
  EXPECT_FALSE(fs::exists(base / "missing"));
  EXPECT_EQ(read(base / "a_file"), "mine");
  EXPECT_EQ(read(base / "not_a_report" / "keep.txt"), "mine");
  int entries = 0;
  for (const auto& entry : fs::directory_iterator(base)) {
    (void)entry;
    ++entries;
  }
  EXPECT_EQ(entries, 2) << "something was written next to the targets";
  fs::remove_all(base);
}

TEST(DeriveReproducible, TwoRunsPrintTheSameBytes) {
  for (const char* arguments : {"derive I --json", "derive V --json", "derive V --latex", "derive III", "derive general --json",
                                "derive general"}) {
    const CommandRun a = backlash(arguments), b = backlash(arguments);
    ASSERT_EQ(a.exit_code, 0) << arguments << ": " << a.err;
    EXPECT_EQ(a.out, b.out) << arguments << ": two runs differ";
  }
}

}  // namespace
