// Two misses of the real-records matrix with a delay (bench/discrepancy_real_records.sh, issue
// 21 item 2), each on its record from the INDEPENDENT odeint generator (generator.hpp) — the
// matrix's seed — with the candidates cut to those that made the miss (docs/discrepancy.md,
// "Pairs — the best single plus one"):
//   item2_delay_and_motor_coulomb*  neither half is among the best five singles (the delay alone
//           fits worse than the nominal model); the best single K screens the delay as its best
//           partner, and the pair is found from the delay's side;
//   item2_delay_and_restitution*    the pair, fitted on the whole record at once, ends in a valley
//           beside the truth; refitted on the growing horizons it meets the noise.
#include "generator.hpp"

#include "backlash/discrepancy/discrepancy.hpp"
#include "backlash/model/case_spec.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>
#include <vector>

namespace {

using namespace backlash;

constexpr double kStep = 0.62;  // case V's experiment

/// The matrix's record (check_discrepancy_real_records.cpp: sizes on case V's scale, 0.1 % noise).
generated_data::RecordSpec matrix_record(const std::vector<std::string>& effects, std::uint64_t seed) {
  generated_data::RecordSpec r;
  r.parameters = numeric::parameters_of(model::load_case("V"));
  const double torque = r.parameters.K * kStep;
  for (const std::string& e : effects) {
    if (e == "coulomb_motor") r.effects.coulomb_motor = 0.05 * torque;
    if (e == "delay") r.effects.delay = 0.03 * numeric::servo_period(r.parameters);
    if (e == "restitution") r.effects.restitution = 0.6;
  }
  r.step = kStep;
  r.seed = seed;
  return r;
}

std::set<std::string> effects_named(const discrepancy::DiscrepancyResult& r) {
  std::set<std::string> out;
  for (const discrepancy::Candidate& c : r.effects)
    if (!discrepancy::is_parameter_correction(c.effect)) out.insert(c.effect);
  return out;
}

void show(const discrepancy::DiscrepancyResult& r) {
  if (!std::getenv("BACKLASH_DEBUG_ROUNDS")) return;
  for (std::size_t k = 0; k < r.rounds.size(); ++k)
    for (const discrepancy::Candidate& c : r.rounds[k]) {
      std::printf("  round %zu %-28s dBIC %10.1f held %.3g %s%s %d sims %s |", k + 1, c.effect.c_str(), c.delta_bic, c.rms_holdout,
                  c.decisive ? "decisive" : "", c.at_range_edge ? " edge" : "", c.simulations, c.failure.c_str());
      for (const auto& p : c.parameters) std::printf(" %s=%.4g", p.name.c_str(), p.value);
      std::printf("\n");
    }
  for (const discrepancy::Candidate& c : r.effects) {
    std::printf("  named %s:", c.effect.c_str());
    for (const auto& p : c.parameters) std::printf(" %s=%.4g±%.2g", p.name.c_str(), p.value, p.uncertainty);
    std::printf("\n");
  }
  std::printf("  status %s; gap %.3g -> %.3g; %s; %.1f s, %d sims, work %.3g\n", discrepancy::to_string(r.status), r.gap_before,
              r.gap_after, r.reason.c_str(), r.seconds, r.simulations, static_cast<double>(r.work));
}

discrepancy::DiscrepancyResult search(const generated_data::RecordSpec& spec, std::vector<std::string> candidates,
                                      std::vector<std::string> parameters) {
  discrepancy::DiscrepancyOptions options;
  options.threads = 1;  // the matrix's setting (a count decides where the budget stops: the same either way)
  if (!std::getenv("BACKLASH_ALL_CANDIDATES")) {  // the whole vocabulary: the matrix's own search (slow)
    options.candidates = std::move(candidates);
    options.parameters = std::move(parameters);
  }
  const auto r = discrepancy::find_discrepancy(model::load_case("V"), generated_data::generate_record(spec), kStep, options);
  show(r);
  return r;
}

TEST(DelayPairsItem2, item2_delay_and_motor_coulomb_named_though_the_delay_alone_fits_worse) {
  const auto r = search(matrix_record({"delay", "coulomb_motor"}, 107),
                        {"delay", "coulomb_motor", "saturation", "restitution", "backlash_size"}, {"K", "motor.J", "load.J"});
  EXPECT_EQ(effects_named(r), (std::set<std::string>{"coulomb_motor", "delay"}));
  EXPECT_TRUE(r.parameter_corrections.empty());
  EXPECT_STREQ(discrepancy::to_string(r.status), "effect_found");
}

TEST(DelayPairsItem2, item2_delay_and_restitution_named_at_the_noise) {
  const auto r = search(matrix_record({"delay", "restitution"}, 108), {"delay", "restitution", "coulomb_motor"}, {"K"});
  EXPECT_EQ(effects_named(r), (std::set<std::string>{"delay", "restitution"}));
  EXPECT_TRUE(r.parameter_corrections.empty());
  EXPECT_STREQ(discrepancy::to_string(r.status), "effect_found");
}

}  // namespace
