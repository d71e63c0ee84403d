// check_api_no_ginac — the facade's numeric part never links GiNaC: the configure-time
// link closure of backlash_api (cmake/BacklashLinkRules.cmake) names no GiNaC/CLN or
// symbolic target, and this program — backlash::api and nothing symbolic — runs a limit
// cycle with neither library mapped.
#include "backlash/api/backlash.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>
#include <string>

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

TEST(ApiNoGinacLink, LinkClosureOfBacklashApiHasNoGinac) {
  std::ifstream in(BACKLASH_API_LINK_CLOSURE);
  ASSERT_TRUE(in) << "missing " << BACKLASH_API_LINK_CLOSURE;
  bool has_api = false;
  for (std::string entry; std::getline(in, entry);) {
    has_api |= entry == "backlash_api";
    EXPECT_EQ(lower(entry).find("ginac"), std::string::npos) << "backlash_api links " << entry;
    EXPECT_EQ(lower(entry).find("cln"), std::string::npos) << "backlash_api links " << entry;
    EXPECT_NE(entry, "backlash_symbolic") << "backlash_api links backlash_symbolic";
    EXPECT_NE(entry, "backlash_api_derive") << "backlash_api links backlash_api_derive";
  }
  EXPECT_TRUE(has_api);
}

TEST(ApiNoGinacLink, NoGinacLibraryIsLoadedWhileComputingALimitCycle) {
  const backlash::api::Cycle cycle = backlash::api::Model(backlash::api::load("V")).limit_cycle();
  ASSERT_TRUE(cycle.found());
  std::ifstream maps("/proc/self/maps");
  if (!maps) GTEST_SKIP() << "/proc/self/maps is not available";
  std::stringstream content;
  content << maps.rdbuf();
  EXPECT_EQ(content.str().find("libginac"), std::string::npos) << "libginac is mapped into a program using backlash::api";
  EXPECT_EQ(content.str().find("libcln"), std::string::npos) << "libcln is mapped into a program using backlash::api";
}

}  // namespace
