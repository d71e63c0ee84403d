// Case V's limit cycle with backlash::numeric alone (no facade): the case file read by
// backlash::model, its evaluator through the odeint gate, the half-cycle return map — and
// whether GiNaC came along.
#include <backlash/model/case_spec.hpp>
#include <backlash/numeric/limit_cycle.hpp>
#include <backlash/numeric/validation.hpp>

#include <cstdio>
#include <fstream>
#include <sstream>

int main() {
  namespace numeric = backlash::numeric;
  const numeric::ValidationResult gate = numeric::validate(numeric::case_evaluator(backlash::model::load_case("V")));
  if (!gate.passed()) return 1;
  const numeric::LimitCycle cycle = numeric::find_limit_cycle(gate.evaluator());
  std::printf("V %.12f\n", cycle.peak_to_peak);
  std::ifstream maps("/proc/self/maps");
  std::stringstream text;
  text << maps.rdbuf();
  std::printf("ginac mapped: %s\n", text.str().find("libginac") == std::string::npos ? "no" : "yes");
  return 0;
}
