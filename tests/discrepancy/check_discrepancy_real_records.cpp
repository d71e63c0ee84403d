// The discrepancy workflow (discrepancy.hpp) on records as real machines make them (issue 21):
// made by the INDEPENDENT odeint simulator (generator.hpp) — never by the closed-form code the
// workflow fits with — with several effects at once, errors in the nominal parameters, an effect
// outside the vocabulary (sensor drifts, a sinusoidal pickup at two frequencies in the full matrix), coloured noise, spikes, a coarse encoder, jittered
// time stamps and a late start.
//   Item1*  a nominal parameter's error is reported as a correction, not as an effect; [fit]
//           fixed keeps a parameter, [fit] free fits it first;
//   Item2*  two effects at once are both named;
//   Item3*  the statuses say what the numbers say (an effect outside the vocabulary is never
//           effect_found);
//   Item4*  clean records under coloured noise or with spikes are quiet, the spikes listed;
//   Item6*  a search that reaches its work budget says so;
//   Matrix  a confusion matrix over these kinds of record (a slice here; all of them with
//           BACKLASH_FULL_MATRIX=1, bench/discrepancy_real_records.sh).  An `ambiguous` answer
//           counts as right when the truth is among the explanations it lists alike
//           (truth_among_alternatives): the page names the experiment that tells them apart.
#include "generator.hpp"

#include "backlash/discrepancy/discrepancy.hpp"
#include "backlash/model/case_spec.hpp"

#include <gtest/gtest.h>

#include "backlash/measurements/measured_record.hpp"
#include <fstream>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace {

using namespace backlash;
using numeric::Effects;
using numeric::Parameters;

constexpr double kStep = 0.62;  // case V's experiment

/// Case V (cases/V.toml) with its [fit] lists.
model::CaseSpec case_v(std::vector<std::string> free = {}, std::vector<std::string> fixed = {}) {
  model::CaseSpec s = model::load_case("V");
  s.fit_free = std::move(free);
  s.fit_fixed = std::move(fixed);
  return s;
}

/// What a record hides: the truth's parameters (case V's, some off) and effects.
struct Truth {
  std::string label;
  Parameters parameters = numeric::parameters_of(model::load_case("V"));
  Effects effects;
  std::set<std::string> named;        ///< the effects the workflow should name
  std::set<std::string> corrections;  ///< the parameters it should correct
  bool outside = false;               ///< an effect outside the vocabulary: a sensor drift, or
  double drift = 0.002;               ///< of this rate [rad/s] (2 mrad/s unless said), or
  double hum = 0, hum_frequency = 0;  ///< a sinusoidal pickup on the sensor [rad, Hz]
};

/// Effect sizes on case V's scale (K·|step| = 0.62, servo period ≈ 6.4 s): each stands tens of
/// noise levels above a 0.1 % noise.
void hide(Truth& t, const std::string& effect) {
  const double torque = t.parameters.K * kStep, period = numeric::servo_period(t.parameters);
  if (effect == "coulomb_motor") t.effects.coulomb_motor = 0.05 * torque;
  if (effect == "coulomb_load") t.effects.coulomb_load = 0.05 * torque;
  if (effect == "saturation") t.effects.saturation = 0.5 * torque;
  if (effect == "delay") t.effects.delay = 0.03 * period;
  if (effect == "torque_offset") t.effects.torque_offset = 0.04 * torque;
  if (effect == "restitution") t.effects.restitution = 0.6;
  t.label += (t.label.empty() ? "" : " + ") + effect;
  t.named.insert(effect);
}

/// A nominal parameter of the truth off by `ratio` (the model keeps case V's value).
void mistake(Truth& t, const std::string& key, double ratio) {
  if (key == "load.J") t.parameters.JL *= ratio;
  if (key == "motor.J") t.parameters.Jm *= ratio;
  if (key == "load.F") t.parameters.FL *= ratio;
  if (key == "motor.F") t.parameters.Fm *= ratio;
  char text[64];
  std::snprintf(text, sizeof text, "%s x%.2f", key.c_str(), ratio);
  t.label += (t.label.empty() ? "" : " + ") + std::string(text);
  t.corrections.insert(key);
}

/// How a record is measured.
struct Condition {
  std::string label = "white";
  double rate = 100, duration = 30, noise = 0.001, quantum = 0, correlation = 0, spikes = 0, jitter = 0, start = 0;
};

generated_data::RecordSpec record_of(const Truth& t, const Condition& c, std::uint64_t seed) {
  generated_data::RecordSpec r;
  r.parameters = t.parameters;
  r.effects = t.effects;
  r.step = kStep;
  r.duration = c.duration;
  r.rate = c.rate;
  r.noise = c.noise;
  r.quantum = c.quantum;
  r.noise_correlation = c.correlation;
  r.spike_fraction = c.spikes;
  r.jitter = c.jitter;
  r.start = c.start;
  r.seed = seed;
  // A sensor drift or a sinusoidal pickup on the sensor: no effect of the vocabulary makes either.
  if (t.outside) r.drift = t.hum > 0 ? 0 : t.drift, r.hum = t.hum, r.hum_frequency = t.hum_frequency;
  return r;
}

/// What the workflow said, as a row of the confusion matrix.
struct Said {
  std::set<std::string> named, corrected;
  std::set<std::string> alternatives;  ///< ambiguous: the explanations alike (the one adopted among them)
  std::string status;
  double seconds = 0, cpu = 0, gap_after = 0;
  long work = 0;
};

void show(const discrepancy::DiscrepancyResult& r);

discrepancy::DiscrepancyResult find(const model::CaseSpec& model, const measurements::MeasuredRecord& data,
                                    const discrepancy::DiscrepancyOptions& options = {}) {
  discrepancy::DiscrepancyResult r = discrepancy::find_discrepancy(model, data, kStep, options);
  show(r);
  return r;
}

Said run(const model::CaseSpec& model, const measurements::MeasuredRecord& data,
         const discrepancy::DiscrepancyOptions& options = {}) {
  const std::clock_t started = std::clock();  // the process's CPU time: one thread, one core's seconds
  const discrepancy::DiscrepancyResult r = find(model, data, options);
  Said s;
  s.cpu = static_cast<double>(std::clock() - started) / CLOCKS_PER_SEC;
  for (const discrepancy::Candidate& c : r.effects)
    if (!discrepancy::is_parameter_correction(c.effect)) s.named.insert(c.effect);
  for (const discrepancy::ParameterCorrection& c : r.parameter_corrections) s.corrected.insert(c.key);
  for (const discrepancy::Candidate& c : r.alternatives) s.alternatives.insert(c.effect);
  s.status = discrepancy::to_string(r.status);
  s.seconds = r.seconds;
  s.work = r.work;
  s.gap_after = r.gap_after;
  return s;
}

void show(const discrepancy::DiscrepancyResult& r) {
  if (std::getenv("BACKLASH_DEBUG_ROUNDS")) {  // every round's candidates, for a look at a wrong answer
    for (std::size_t k = 0; k < r.rounds.size(); ++k)
      for (const discrepancy::Candidate& c : r.rounds[k])
        std::printf("  round %zu %-28s dBIC %10.1f held %.3g %s%s %d sims %.2f s %s\n", k + 1, c.effect.c_str(), c.delta_bic,
                    c.rms_holdout, c.decisive ? "decisive" : "", c.at_range_edge ? " edge" : "", c.simulations, c.seconds,
                    c.failure.c_str());
    std::printf("  noise %.3g (white %.3g) tau %.3g; gap %.3g -> %.3g; %s; %.1f s, %d sims, work %.3g\n", r.noise_estimate.sigma,
                r.noise_estimate.white_sigma, r.noise_estimate.tau_int, r.gap_before, r.gap_after, r.reason.c_str(), r.seconds,
                r.simulations, static_cast<double>(r.work));
  }
}

std::string joined(const std::set<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ",") + n;
  return out.empty() ? "-" : out;
}

// ------------------------------------------------------------------ item 1

TEST(RealRecordsItem1, item1_inertia_error_alone_is_a_correction_not_an_effect) {
  Truth t;
  mistake(t, "load.J", 1.15);
  const measurements::MeasuredRecord data = generated_data::generate_record(record_of(t, {}, 11));
  if (const char* folder = std::getenv("BACKLASH_WRITE_EXAMPLES"))  // the README's record
    std::ofstream(std::string(folder) + "/case_V_with_heavier_load.csv") << measurements::format_measured_csv(data);
  const discrepancy::DiscrepancyResult r = find(case_v(), data);
  EXPECT_STREQ(discrepancy::to_string(r.status), "parameters_corrected");
  EXPECT_TRUE(r.effects.empty()) << "named " << r.effects.front().effect;
  ASSERT_EQ(r.parameter_corrections.size(), 1u);
  const discrepancy::ParameterCorrection& c = r.parameter_corrections.front();
  EXPECT_EQ(c.key, "load.J");
  EXPECT_DOUBLE_EQ(c.nominal, 0.5);
  // Within 3 reported σ or 2 % of the truth (the fit on the record is exact up to the noise).
  EXPECT_LE(std::fabs(c.fitted - 0.575), std::max(3 * c.uncertainty, 0.02 * 0.575)) << c.fitted << " ± " << c.uncertainty;
  EXPECT_NEAR(c.ratio, c.fitted / 0.5, 1e-12);
  EXPECT_FALSE(c.given_free);
}

TEST(RealRecordsItem1, item1_fit_free_is_fitted_first_and_fit_fixed_is_kept) {
  Truth t;
  mistake(t, "load.J", 1.15);
  const measurements::MeasuredRecord data = generated_data::generate_record(record_of(t, {}, 11));
  const discrepancy::DiscrepancyResult free = find(case_v({"load.J"}), data);
  ASSERT_EQ(free.parameter_corrections.size(), 1u);
  EXPECT_EQ(free.parameter_corrections.front().key, "load.J");
  EXPECT_TRUE(free.parameter_corrections.front().given_free);
  EXPECT_STREQ(discrepancy::to_string(free.status), "parameters_corrected");
  const discrepancy::DiscrepancyResult fixed = find(case_v({}, {"load.J"}), data);
  for (const discrepancy::ParameterCorrection& c : fixed.parameter_corrections) EXPECT_NE(c.key, "load.J");
  for (const auto& round : fixed.rounds)
    for (const discrepancy::Candidate& c : round) EXPECT_EQ(c.effect.find("load.J"), std::string::npos) << "tried " << c.effect;
}

TEST(RealRecordsItem1, item1_friction_error_with_an_effect_is_corrected_beside_it) {
  Truth t;
  hide(t, "coulomb_load");
  mistake(t, "load.F", 0.85);
  const Said s = run(case_v(), generated_data::generate_record(record_of(t, {}, 12)));
  EXPECT_EQ(joined(s.named), "coulomb_load");
  EXPECT_EQ(joined(s.corrected), "load.F");
  EXPECT_EQ(s.status, "effect_found");
}

// ------------------------------------------------------------------ item 2

TEST(RealRecordsItem2, item2_two_effects_at_once_are_both_named) {
  Truth t;
  hide(t, "delay");
  hide(t, "torque_offset");
  const Said s = run(case_v(), generated_data::generate_record(record_of(t, {}, 102)));
  EXPECT_EQ(joined(s.named), "delay,torque_offset");
  EXPECT_EQ(s.status, "effect_found");
}

TEST(RealRecordsItem3, item3_a_pair_not_found_is_partly_explained_not_effect_found) {
  // Two Coulomb frictions at once: the search names one (or a stand-in) and a gap remains.
  Truth t;
  hide(t, "coulomb_load");
  hide(t, "coulomb_motor");
  const Said s = run(case_v(), generated_data::generate_record(record_of(t, {}, 101)));
  if (s.named != t.named) EXPECT_EQ(s.status, "partly_explained") << "named " << joined(s.named);
  else EXPECT_EQ(s.status, "effect_found");
}

// ------------------------------------------------------------------ item 3

TEST(RealRecordsItem3, item3_an_effect_outside_the_vocabulary_is_never_effect_found) {
  Truth t;
  t.label = "sensor drift";
  t.outside = true;
  Condition ten_seconds;
  ten_seconds.duration = 10;
  const Said s = run(case_v(), generated_data::generate_record(record_of(t, ten_seconds, 14)));
  EXPECT_TRUE(s.status == "unexplained" || s.status == "partly_explained") << s.status << ", named " << joined(s.named);
}

// ------------------------------------------------------------------ item 4

TEST(RealRecordsItem4, item4_clean_record_with_coloured_noise_is_quiet) {
  Condition c;
  c.correlation = 15;
  const measurements::MeasuredRecord data = generated_data::generate_record(record_of(Truth{}, c, 15));
  const discrepancy::DiscrepancyResult r = find(case_v(), data);
  EXPECT_STREQ(discrepancy::to_string(r.status), "no_discrepancy");
  // AR(1) with ℓ = 15 samples: τ_int = (1 + a)/(1 − a) ≈ 2ℓ = 30; its level the generator's σ.
  EXPECT_GT(r.noise_estimate.tau_int, 15);
  EXPECT_LT(r.noise_estimate.tau_int, 60);
  EXPECT_NEAR(r.noise_estimate.sigma, 0.001 * kStep, 0.25 * 0.001 * kStep);
}

TEST(RealRecordsItem4, item4_clean_record_with_spikes_is_quiet_and_lists_them) {
  Condition c;
  c.spikes = 0.005;
  generated_data::RecordSpec spec = record_of(Truth{}, c, 16);
  const measurements::MeasuredRecord data = generated_data::generate_record(spec);
  generated_data::RecordSpec smooth = spec;
  smooth.spike_fraction = 0;
  const measurements::MeasuredRecord without = generated_data::generate_record(smooth);
  std::size_t spikes = 0;
  for (std::size_t i = 0; i < data.size(); ++i) spikes += data.theta_out[i] != without.theta_out[i];
  const discrepancy::DiscrepancyResult r = find(case_v(), data);
  EXPECT_STREQ(discrepancy::to_string(r.status), "no_discrepancy");
  ASSERT_GT(spikes, 5u);
  EXPECT_EQ(r.outliers.size(), spikes);
  for (const discrepancy::Outlier& o : r.outliers) EXPECT_GT(std::fabs(o.size), 10) << "at t = " << o.t;
}

// ------------------------------------------------------------------ item 6

TEST(RealRecordsItem6, item6_the_work_budget_reached_is_a_status_reason) {
  Truth t;
  hide(t, "coulomb_load");
  hide(t, "saturation");
  discrepancy::DiscrepancyOptions options;
  options.total_work = 200'000;  // 200 simulations: far too few for a round of candidates
  const discrepancy::DiscrepancyResult r =
      discrepancy::find_discrepancy(case_v(), generated_data::generate_record(record_of(t, {}, 17)), kStep, options);
  EXPECT_NE(r.reason.find("work budget"), std::string::npos) << r.reason;
  EXPECT_NE(r.status, discrepancy::Status::EffectFound);
}

// ------------------------------------------------------------------ the matrix

/// The records of the matrix: pairs, an effect with a parameter error, parameter errors alone,
/// outside the vocabulary, and each measurement condition with one effect and clean.
std::vector<std::pair<Truth, Condition>> matrix(bool full) {
  std::vector<std::pair<Truth, Condition>> out;
  const std::vector<std::string> effects{"coulomb_load", "delay", "saturation", "torque_offset", "coulomb_motor", "restitution"};
  for (std::size_t i = 0; i < effects.size(); ++i)
    for (std::size_t j = i + 1; j < effects.size(); ++j) {
      if (!full && (i + j) % 3 != 1) continue;
      Truth t;
      hide(t, effects[i]);
      hide(t, effects[j]);
      out.push_back({t, {}});
    }
  const std::vector<std::pair<std::string, double>> errors{{"load.J", 1.15}, {"motor.J", 0.85}, {"load.F", 1.2}, {"motor.F", 0.8}};
  for (std::size_t i = 0; i < effects.size(); ++i)
    for (std::size_t k = 0; k < errors.size(); ++k) {
      if (!full && (i + k) % 4 != 0) continue;
      Truth t;
      hide(t, effects[i]);
      mistake(t, errors[k].first, errors[k].second);
      out.push_back({t, {}});
    }
  for (std::size_t k = 0; k < errors.size(); ++k) {
    if (!full && k % 2 != 0) continue;
    Truth t;
    mistake(t, errors[k].first, errors[k].second);
    out.push_back({t, {}});
  }
  Truth drift;
  drift.label = "sensor drift";
  drift.outside = true;
  out.push_back({drift, {}});
  if (full) {  // more kinds outside the vocabulary: a slower drift of the other sign, a pickup at two frequencies
    Truth slow = drift;
    slow.label = "sensor drift -0.5 mrad/s", slow.drift = -0.0005;
    out.push_back({slow, {}});
    for (const double f : {0.37, 1.7}) {
      Truth hum = drift;
      hum.label = f < 1 ? "sensor hum 0.37 Hz" : "sensor hum 1.7 Hz";
      hum.hum = 10 * 0.001 * kStep, hum.hum_frequency = f;  // 10 noise levels
      out.push_back({hum, {}});
    }
  }
  std::vector<Condition> conditions(7);
  conditions[0].label = "coloured 10", conditions[0].correlation = 10;
  conditions[1].label = "spikes", conditions[1].spikes = 0.005;
  conditions[2].label = "encoder 1024", conditions[2].quantum = 2 * M_PI / 1024, conditions[2].noise = 0.0005;
  conditions[3].label = "10 s", conditions[3].duration = 10;
  conditions[4].label = "20 Hz", conditions[4].rate = 20;
  conditions[5].label = "jitter 20%", conditions[5].jitter = 0.2;
  conditions[6].label = "late 0.5 s", conditions[6].start = 0.5;
  for (std::size_t k = 0; k < conditions.size(); ++k) {
    if (!full && k % 3 != 0) continue;
    Truth t;
    hide(t, effects[k % effects.size()]);
    out.push_back({t, conditions[k]});
    Truth clean;
    clean.label = "clean";
    out.push_back({clean, conditions[k]});
  }
  return out;
}

/// An ambiguous answer is right when the truth is among the explanations it lists alike: what
/// it named and corrected, with one of them replaced by another of its alternatives
/// (docs/discrepancy.md, "Statuses": two explanations that fit alike, the experiment named).
bool truth_among_alternatives(const Said& s, const Truth& t) {
  if (s.status != "ambiguous") return false;
  std::set<std::string> said = s.named, truth = t.named;
  said.insert(s.corrected.begin(), s.corrected.end());
  truth.insert(t.corrections.begin(), t.corrections.end());
  if (said == truth) return true;
  for (const std::string& adopted : s.alternatives)
    for (const std::string& other : s.alternatives) {
      if (!said.count(adopted) || said.count(other)) continue;
      std::set<std::string> swapped = said;
      swapped.erase(adopted);
      swapped.insert(other);
      if (swapped == truth) return true;
    }
  return false;
}

TEST(RealRecordsMatrix, the_confusion_matrix_over_real_kinds_of_record) {
  const bool full = std::getenv("BACKLASH_FULL_MATRIX") != nullptr;
  if (!full && std::getenv("BACKLASH_MATRIX_SLICE") == nullptr)
    GTEST_SKIP() << "the matrix runs with BACKLASH_FULL_MATRIX=1 (bench/discrepancy_real_records.sh) or BACKLASH_MATRIX_SLICE=1";
  std::map<std::string, std::pair<int, int>> by_kind;  // right, total
  std::vector<double> seconds, cpu;
  std::uint64_t seed = 100;
  const char* only = std::getenv("BACKLASH_MATRIX_ONLY");  // a label's part: one kind of record, to look at
  const char* shard = std::getenv("BACKLASH_MATRIX_SHARD");  // "k/n": every n-th record from the k-th (n processes)
  const int shard_k = shard ? std::atoi(shard) : 0, shard_n = shard && std::strchr(shard, '/') ? std::atoi(std::strchr(shard, '/') + 1) : 1;
  int index = 0;
  for (const auto& [truth, condition] : matrix(full)) {
    if ((only && (truth.label + " / " + condition.label).find(only) == std::string::npos) || index++ % shard_n != shard_k) {
      ++seed;
      continue;
    }
    discrepancy::DiscrepancyOptions one_core;  // the bound is per record on one core
    one_core.threads = 1;
    auto list = [](const char* text) {  // a comma-separated list (to look at one answer)
      std::vector<std::string> out;
      for (std::string rest = text; !rest.empty();) {
        const std::size_t comma = rest.find(',');
        if (comma > 0) out.push_back(rest.substr(0, comma));
        rest = comma == std::string::npos ? "" : rest.substr(comma + 1);
      }
      return out;
    };
    if (const char* names = std::getenv("BACKLASH_MATRIX_CANDIDATES")) one_core.candidates = list(names);
    if (const char* names = std::getenv("BACKLASH_MATRIX_PARAMETERS")) one_core.parameters = list(names);
    if (const char* work = std::getenv("BACKLASH_MATRIX_TOTAL_WORK")) one_core.total_work = std::atol(work);  // a budget tried
    const measurements::MeasuredRecord record = generated_data::generate_record(record_of(truth, condition, seed++));
    if (const char* folder = std::getenv("BACKLASH_MATRIX_RECORDS")) {  // each record as a CSV (to compare two builds' answers)
      char name[32];
      std::snprintf(name, sizeof name, "/%02d.csv", index - 1);
      std::ofstream(std::string(folder) + name) << measurements::format_measured_csv(record);
    }
    const Said s = run(case_v(), record, one_core);
    std::string kind = truth.outside ? "outside the vocabulary"
                       : truth.named.empty() && truth.corrections.empty() ? "clean (" + condition.label + ")"
                       : truth.named.size() == 2                          ? "two effects"
                       : truth.corrections.empty()                        ? "one effect (" + condition.label + ")"
                       : truth.named.empty()                              ? "parameter error alone"
                                                                          : "effect + parameter error";
    bool right = false;
    if (truth.outside) right = s.status != "effect_found" && s.status != "parameters_corrected";
    else if (truth.named.empty() && truth.corrections.empty()) right = s.status == "no_discrepancy";
    else right = s.named == truth.named && s.corrected == truth.corrections &&
                 (s.status == "effect_found" || s.status == "parameters_corrected");
    if (truth.named.size() < 2 && !truth.corrections.empty() && !truth.named.empty())  // the effect right, the error corrected
      right = s.named == truth.named && s.corrected == truth.corrections;
    if (!truth.outside && !(truth.named.empty() && truth.corrections.empty())) right = right || truth_among_alternatives(s, truth);
    by_kind[kind].first += right;
    ++by_kind[kind].second;
    seconds.push_back(s.seconds);
    cpu.push_back(s.cpu);
    std::printf("%-34s %-13s -> %-20s named %-26s corrected %-14s gap %.2f  %.1f s (cpu %.1f s) %.3g work %s\n", truth.label.c_str(),
                condition.label.c_str(), s.status.c_str(), joined(s.named).c_str(), joined(s.corrected).c_str(), s.gap_after,
                s.seconds, s.cpu, static_cast<double>(s.work), right ? "" : "  <-- wrong");
    std::fflush(stdout);
  }
  std::printf("\n%-30s right / records\n", "kind of record");
  int right = 0, total = 0;
  for (const auto& [kind, counts] : by_kind) {
    std::printf("%-30s %d / %d\n", kind.c_str(), counts.first, counts.second);
    right += counts.first, total += counts.second;
  }
  std::sort(seconds.begin(), seconds.end());
  std::sort(cpu.begin(), cpu.end());
  std::printf("all: %d / %d; seconds per record (1 thread): wall median %.1f, worst %.1f; cpu median %.1f, worst %.1f\n", right,
              total, seconds[seconds.size() / 2], seconds.back(), cpu[cpu.size() / 2], cpu.back());
  // Clean records quiet and nothing outside the vocabulary reported as found, every time; the
  // rest at least 80 % right on this slice (the bar of 90 % is for the full matrix, whose
  // result the report of issue 21 gives).
  for (const auto& [kind, counts] : by_kind)
    if (kind.rfind("clean", 0) == 0 || kind == "outside the vocabulary") EXPECT_EQ(counts.first, counts.second) << kind;
  EXPECT_GE(right, 0.8 * total);
}

}  // namespace
