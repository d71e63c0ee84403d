// Case V's limit cycle through the installed facade, where its data came from (the
// installed prefix's share/backlash, named by backlashConfig.cmake: this program lives
// outside the prefix), and whether GiNaC came along.
#include <backlash/api/backlash.hpp>
#include <backlash/model/data_dir.hpp>

#include <cstdio>
#include <fstream>
#include <sstream>

int main() {
  const backlash::api::Model v(backlash::api::load("V"));
  const backlash::api::Cycle cycle = v.limit_cycle();
  std::printf("%s %s %.12f\n", cycle.case_id.c_str(), cycle.status().c_str(), cycle.cycle.peak_to_peak);
  std::printf("data: %s\n", backlash::model::data_dir().c_str());
  std::ifstream maps("/proc/self/maps");
  std::stringstream text;
  text << maps.rdbuf();
  std::printf("ginac mapped: %s\n", text.str().find("libginac") == std::string::npos ? "no" : "yes");
  return 0;
}
