// Issue 22, the two-body drive's text output: its first line names the status and the cut-off,
// not a count of least-squares solves the two-body fits do not keep (it printed "0 least-squares
// solves, 0.00 s").  The README's example (examples/two_body_drive.*) through the command line.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <string>

namespace {

std::string run(const std::string& arguments) {
  FILE* pipe = popen((std::string(BACKLASH_CLI) + " " + arguments + " 2>/dev/null").c_str(), "r");
  std::string out;
  std::array<char, 4096> buffer;
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) out.append(buffer.data(), n);
  pclose(pipe);
  return out;
}

TEST(TwoBodyDriveText, item3_no_empty_solve_count) {
  const std::string dir = BACKLASH_SOURCE_DIR "/examples/";
  const std::string out = run("discrepancy --no-progress --model " + dir + "two_body_drive.toml --data " + dir + "two_body_drive.csv");
  const std::string first = out.substr(0, out.find('\n'));
  EXPECT_NE(first.find("(measured drive): "), std::string::npos) << out;
  EXPECT_NE(first.find("(cut-off "), std::string::npos) << first;
  EXPECT_EQ(first.find("least-squares solves"), std::string::npos) << first;
}

}  // namespace
