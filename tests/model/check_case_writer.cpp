// check_case_writer — the one case-file writer (model/case_writer.hpp) against the reader:
// write → read → the same spec, and writing it again gives the same bytes; for the eight
// thesis cases and for random cases with every effect of the table of effects, a measured
// drive and [fit] free.  And the table itself: every effect has its parameters, every name
// is unique, every neutral value is admissible.
#include "backlash/model/case_spec.hpp"
#include "backlash/model/case_writer.hpp"
#include "backlash/model/effect_table.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <string>

namespace {

namespace model = backlash::model;
using model::Rational;

/// EXPECT that two specs hold the same numbers, experiment, effects and [fit] free.
void expect_same(const model::CaseSpec& a, const model::CaseSpec& b, const std::string& what) {
  EXPECT_EQ(a.name, b.name) << what;
  EXPECT_EQ(a.measured_at, b.measured_at) << what;
  for (const auto& [x, y, key] : {std::tuple{&a.K, &b.K, "K"}, {&a.backlash, &b.backlash, "backlash"},
                                  {&a.reference, &b.reference, "reference"}, {&a.Jm, &b.Jm, "motor.J"},
                                  {&a.Fm, &b.Fm, "motor.F"}, {&a.JL, &b.JL, "load.J"}, {&a.FL, &b.FL, "load.F"}})
    EXPECT_TRUE(*x == *y) << what << ": " << key << " returned " << model::to_string(*y) << " instead of "
                          << model::to_string(*x);
  ASSERT_EQ(a.experiment.has_value(), b.experiment.has_value()) << what;
  if (a.experiment) {
    EXPECT_EQ(a.experiment->kind, b.experiment->kind) << what;
    EXPECT_TRUE(a.experiment->step == b.experiment->step) << what;
    EXPECT_TRUE(a.experiment->drive_gain == b.experiment->drive_gain) << what;
    EXPECT_EQ(a.experiment->t_end, b.experiment->t_end) << what;
  }
  for (const model::EffectParameterInfo& p : model::effect_parameters)
    EXPECT_EQ(model::field(a.effects, p.id), model::field(b.effects, p.id)) << what << ": effects " << p.name;
  EXPECT_EQ(a.fit_free, b.fit_free) << what;
}

void expect_round_trip(const model::CaseSpec& spec, const std::string& what) {
  const std::string text = model::write_case_file(spec);
  const model::CaseSpec read = model::parse_case(text, spec.id + ".toml");
  expect_same(spec, read, what + "\n" + text);
  EXPECT_EQ(model::write_case_file(read), text) << what << ": written twice, the bytes differ";
}

TEST(CaseWriter, exam_ThesisCasesRoundTrip) {
  for (const std::string& id : model::thesis_case_ids()) expect_round_trip(model::load_case(id), "case " + id);
}

/// A random exact number p/q with |p/q| in about [1e-3, 1e3].
Rational random_rational(std::mt19937_64& random, bool positive) {
  std::uniform_int_distribution<long> numerator(1, 1000000), denominator(1, 1000);
  Rational value(numerator(random), denominator(random));
  return positive || random() % 2 ? value : Rational(-value);
}

TEST(CaseWriter, check_RandomCasesWithEveryEffectRoundTrip) {
  std::mt19937_64 random(20261127);
  for (int trial = 0; trial < 300; ++trial) {
    model::CaseSpec spec = model::load_case("V");
    spec.name = "random \"case\" " + std::to_string(trial);
    spec.Jm = random_rational(random, true), spec.FL = random_rational(random, true);
    spec.reference = random_rational(random, false);
    spec.measured_at = trial % 2 ? model::MeasuredAt::Motor : model::MeasuredAt::Load;
    if (trial % 3 == 0) spec.experiment = model::Experiment{model::ExperimentKind::Drive, 0, random_rational(random, true), {}, {}};
    if (trial % 5 == 0 && spec.experiment) spec.experiment->t_end = random_rational(random, true);
    if (trial % 7 == 1 && spec.experiment && spec.experiment->kind == model::ExperimentKind::Step)
      spec.experiment->step_time = random_rational(random, false);  // issue 18, item 4: it round-trips
    if (trial % 4 == 0) spec.fit_free = {"motor.J", "load.F"};
    // Each effect present or not; one contact law at most (the reader refuses the pair).
    bool contact_law = false;
    for (const model::EffectInfo& effect : model::effects_table) {
      if (random() % 2 || (effect.contact_law && contact_law)) continue;
      contact_law = contact_law || effect.contact_law;
      for (std::size_t i = effect.first; i < effect.first + effect.count; ++i) {
        const model::EffectParameterInfo& p = model::effect_parameters[i];
        Rational value = random_rational(random, p.admissible != model::Admissible::Any);
        if (p.admissible == model::Admissible::BelowOne) value = Rational(1, 2) / (1 + value);
        model::field(spec.effects, p.id) = value;
        if (p.key == "kinetic")  // a kinetic friction level above the static one is refused (Stribeck)
          model::field(spec.effects, p.id) = std::min(value, *model::field(spec.effects, model::effect_parameters[i - 1].id));
      }
    }
    expect_round_trip(spec, "trial " + std::to_string(trial));
  }
}

TEST(EffectTable, exam_EveryEffectHasItsParametersAndUniqueNames) {
  std::set<std::string_view> names, keys;
  std::size_t parameters = 0;
  for (const model::EffectInfo& effect : model::effects_table) {
    EXPECT_GE(effect.count, 1U) << effect.key << " has no parameter";
    EXPECT_TRUE(keys.insert(effect.key).second) << effect.key << " twice";
    parameters += effect.count;
    for (std::size_t i = effect.first; i < effect.first + effect.count; ++i)
      EXPECT_EQ(model::effect_parameters[i].effect, effect.key) << "the parameters of an effect must be adjacent";
  }
  EXPECT_EQ(parameters, model::kEffectParameterCount) << "a parameter belongs to no effect";
  for (const model::EffectParameterInfo& p : model::effect_parameters) {
    EXPECT_TRUE(names.insert(p.name).second) << p.name << " twice";
    EXPECT_TRUE(p.neutral == model::kAbsent || p.admits(p.neutral)) << p.name << ": its neutral value is not admissible";
    EXPECT_EQ(&model::info(p.id), &p) << p.name << ": the id does not index its row";
    EXPECT_LT(p.low, p.high) << p.name << ": an empty candidate range";
  }
}

}  // namespace
