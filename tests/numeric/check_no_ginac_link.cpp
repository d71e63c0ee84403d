// check_no_ginac_link — numeric/ never links GiNaC: the configure-time link
// closure of backlash_numeric (written by cmake/BacklashLinkRules.cmake) names
// no GiNaC/CLN or symbolic target, and this test binary — which links
// backlash_numeric and nothing symbolic — has neither library mapped.
#include "backlash/numeric/evaluator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>
#include <string>

#ifndef BACKLASH_NUMERIC_LINK_CLOSURE
#error "BACKLASH_NUMERIC_LINK_CLOSURE must be defined by CMake"
#endif

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

TEST(NoGinacLink, link_closure_of_backlash_numeric_has_no_ginac) {
  std::ifstream in(BACKLASH_NUMERIC_LINK_CLOSURE);
  ASSERT_TRUE(in) << "missing " << BACKLASH_NUMERIC_LINK_CLOSURE;
  std::string entry;
  bool has_numeric = false;
  while (std::getline(in, entry)) {
    has_numeric |= entry == "backlash_numeric";
    EXPECT_EQ(lower(entry).find("ginac"), std::string::npos) << "backlash_numeric links " << entry;
    EXPECT_EQ(lower(entry).find("cln"), std::string::npos) << "backlash_numeric links " << entry;
    EXPECT_NE(entry, "backlash_symbolic");
    EXPECT_NE(entry, "backlash_codegen_lib");
  }
  EXPECT_TRUE(has_numeric);
}

TEST(NoGinacLink, no_ginac_library_is_loaded_in_a_numeric_program) {
  // use the library so that it is really linked
  ASSERT_NE(backlash::numeric::generated_case_evaluator("V"), nullptr);
  std::ifstream maps("/proc/self/maps");
  if (!maps) GTEST_SKIP() << "/proc/self/maps is not available";
  std::stringstream content;
  content << maps.rdbuf();
  const std::string text = content.str();
  EXPECT_EQ(text.find("libginac"), std::string::npos) << "libginac is mapped into a numeric-only program";
  EXPECT_EQ(text.find("libcln"), std::string::npos) << "libcln is mapped into a numeric-only program";
}

}  // namespace
