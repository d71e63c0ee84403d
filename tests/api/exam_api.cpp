// exam_api — the facade (backlash/api/backlash.hpp) on known answers: case V's limit
// cycle (section 14, exact value in reports/errata/limit_cycles.toml), case I's first
// separation (closed form), a case given in code with exact rationals, effects reaching
// every computation, and bad input as one-line errors naming the argument.
#include "backlash/api/backlash.hpp"
#include "backlash/model/data_dir.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <numbers>

#include <unistd.h>

namespace {

using namespace backlash;

void expect_close(const std::string& what, double actual, double expected, double tolerance) {
  EXPECT_LE(std::fabs(actual - expected), tolerance)
      << what << " returned " << std::setprecision(17) << actual << " instead of " << expected << " (±" << tolerance << ")";
}

template <class Call>
std::string error_of(Call call) {
  try {
    call();
  } catch (const std::exception& error) {
    return error.what();
  }
  return "(no error)";
}

void expect_error(const std::string& what, const std::string& actual, const std::string& expected) {
  EXPECT_EQ(actual, expected) << what << " returned the error \"" << actual << "\" instead of \"" << expected << "\"";
  EXPECT_EQ(actual.find('\n'), std::string::npos) << what << ": the error is not one line";
}

const api::Model& case_V() {
  static const api::Model model(api::load("V"));
  return model;
}

TEST(ApiKnownAnswers, CaseV_LimitCycle) {
  const api::Cycle cycle = case_V().limit_cycle();
  ASSERT_TRUE(cycle.found()) << "limit_cycle() of case V returned status " << cycle.status() << " instead of limit_cycle";
  // reports/errata/limit_cycles.toml: exact_decimal = "0.500728496422" (12 digits).
  expect_close("limit_cycle().cycle.peak_to_peak of case V", cycle.cycle.peak_to_peak, 0.500728496422, 5e-13);
  expect_close("limit_cycle().cycle.amplitude of case V", cycle.cycle.amplitude, 0.500728496422 / 2, 1e-12);
  EXPECT_TRUE(cycle.cycle.stable) << "limit_cycle() of case V returned an unstable cycle instead of a stable one";
  const nlohmann::json j = nlohmann::json::parse(cycle.json());
  for (const char* key : {"case", "status", "amplitude", "peak_to_peak", "period", "separation_velocity", "multiplier"})
    EXPECT_TRUE(j.contains(key)) << "limit_cycle().json() returned no key " << key << " instead of docs/design.md's keys";
  EXPECT_EQ(j["case"], "V");
}

TEST(ApiKnownAnswers, CaseI_HasNoLimitCycle) {
  const api::Cycle cycle = api::Model(api::load("I")).limit_cycle();
  EXPECT_EQ(cycle.status(), "none") << "limit_cycle() of case I returned " << cycle.status() << " instead of none";
  EXPECT_FALSE(cycle.cycle.reason.empty());
}

TEST(ApiKnownAnswers, CaseI_FirstSeparation) {
  // Case I: J = 1, F = 0.8, K = 1, θR = 1, step 1, measured at the motor: cot φ = 0, so the
  // first separation is at θo = θR; with α = F/2J, ω = √(K/J − α²), e = θo − θR =
  // −e^{−αt}(cos ωt + (α/ω) sin ωt) first vanishes at t* = (π − atan(ω/α))/ω, where
  // θ̇o = e^{−αt*} (docs/physics.md: 1.0 and ≈ .42 in the thesis's worked example).
  const double alpha = 0.4, omega = std::sqrt(1 - alpha * alpha);
  const double t_star = (std::numbers::pi - std::atan(omega / alpha)) / omega;
  const api::Simulation run = api::Model(api::load("I")).simulate();
  ASSERT_FALSE(run.result.events.empty()) << "simulate() of case I returned no events instead of a separation";
  const numeric::SimulationEvent& first = run.result.events.front();
  EXPECT_EQ(std::string(numeric::to_string(first.kind)), "separation");
  expect_close("the first separation time of case I", first.t, t_star, 1e-12);
  expect_close("theta_o at the first separation of case I", first.theta_o, 1.0, 1e-12);
  expect_close("dtheta_o at the first separation of case I", first.dtheta_o, std::exp(-alpha * t_star), 1e-12);
  EXPECT_EQ(run.step, 1.0) << "simulate() took the step " << run.step << " instead of the case file's 1.0";
  EXPECT_EQ(run.t_end, 60.0) << "simulate() ran to " << run.t_end << " instead of the case file's 60";
}

TEST(ApiCases, ParametersInCodeAreExactAndGiveTheSameCycle) {
  api::CaseParameters p;
  p.name = "V from code";
  p.measured_at = model::MeasuredAt::Load;
  p.Jm = model::Rational(1, 2);
  p.Fm = model::Rational(1, 10);
  p.JL = model::Rational(1, 2);
  p.FL = model::Rational(3, 10);
  p.K = 1;
  p.backlash = model::Rational(3, 10);
  p.reference = 1;
  const api::Case c = api::load(p);
  const api::Case v = api::load("V");
  EXPECT_EQ(c.id(), "V from code");
  EXPECT_TRUE(c.spec().Fm == v.spec().Fm) << "Fm returned " << model::to_string(c.spec().Fm) << " instead of 1/10";
  EXPECT_TRUE(c.spec().backlash == v.spec().backlash);
  // The same numbers, through the stable parametric evaluator (not case V's generated one).
  const api::Cycle cycle = api::Model(c).limit_cycle();
  expect_close("limit_cycle().peak_to_peak of case V given in code", cycle.cycle.peak_to_peak, 0.500728496422, 5e-12);
}

TEST(ApiCases, CaseFileTextGivesTheCaseBack) {
  for (const std::string& id : model::thesis_case_ids()) {
    const api::Case c = api::load(id);
    const api::Case back = api::Case::from_text(c.case_file(), id + ".toml");
    const model::CaseSpec &a = c.spec(), &b = back.spec();
    EXPECT_TRUE(a.Jm == b.Jm && a.Fm == b.Fm && a.JL == b.JL && a.FL == b.FL && a.K == b.K && a.backlash == b.backlash &&
                a.reference == b.reference && a.measured_at == b.measured_at && a.name == b.name && b.id == id)
        << "case_file() of case " << id << " returned a file that reads back as another case:\n"
        << c.case_file();
    ASSERT_TRUE(b.experiment.has_value());
    EXPECT_TRUE(a.experiment->step == b.experiment->step && a.experiment->t_end == b.experiment->t_end);
  }
}

TEST(ApiCases, EffectsReachSimulationAndLimitCycle) {
  // Case V with Coulomb friction on the load (README, "Effects the thesis left out"): 0.01
  // keeps a stable cycle of smaller swing, found on the full return map; 0.03 brings the
  // servo to rest inside the friction's dead band.
  auto with_coulomb = [](const std::string& torque) {
    return api::Case::from_texts({{"name", "V with Coulomb"},
                                  {"measured_at", "load"},
                                  {"Jm", "1/2"},
                                  {"Fm", "0.1"},
                                  {"JL", "0.5"},
                                  {"FL", "0.3"},
                                  {"K", "1"},
                                  {"backlash", "0.3"},
                                  {"reference", "1"},
                                  {"step", "0.62"},
                                  {"coulomb_load", torque}});
  };
  const api::Case c = with_coulomb("0.01");
  EXPECT_TRUE(c.spec().effects.coulomb_load == model::Rational(1, 100));
  const api::Model m(c);
  EXPECT_EQ(m.effect_model().effects().coulomb_load, 0.01);
  const nlohmann::json sim = nlohmann::json::parse(m.simulate().json());
  EXPECT_EQ(sim["effects"]["coulomb_load"], 0.01) << "simulate().json() returned effects " << sim["effects"].dump()
                                                   << " instead of {\"coulomb_load\": 0.01}";
  const api::Cycle cycle = m.limit_cycle();
  ASSERT_TRUE(cycle.found()) << "limit_cycle() with coulomb_load = 0.01 returned " << cycle.status() << " ("
                             << cycle.cycle.reason << ") instead of a limit cycle";
  EXPECT_NE(cycle.cycle.method, "half-cycle map") << "limit_cycle() with effects returned the nominal method";
  // Smaller than the nominal 0.500728 (the friction takes energy out of each free flight);
  // the value is the one `backlash limit-cycle` prints for the same case file.
  expect_close("peak_to_peak with coulomb_load = 0.01", cycle.cycle.peak_to_peak, 0.398011155447, 1e-9);
  EXPECT_TRUE(cycle.cycle.stable);
  const nlohmann::json j = nlohmann::json::parse(cycle.json());
  EXPECT_EQ(j["effects"]["coulomb_load"], 0.01);
  EXPECT_TRUE(j.contains("iterations"));

  const api::Cycle at_rest = api::Model(with_coulomb("0.03")).limit_cycle();
  EXPECT_EQ(at_rest.status(), "none") << "limit_cycle() with coulomb_load = 0.03 returned " << at_rest.status()
                                          << " instead of none (the servo comes to rest)";
  EXPECT_NE(at_rest.cycle.reason.find("rest"), std::string::npos) << "the reason was: " << at_rest.cycle.reason;
}

TEST(ApiCases, SweepOverACase) {
  api::SweepRequest request;
  request.target = "V";
  request.vary = "K";
  request.from = 0.5;
  request.to = 2;
  request.points = 4;
  const api::Sweep sweep = api::sweep(request);
  ASSERT_EQ(sweep.rows.size(), 4u);
  expect_close("the sweep's third x", sweep.rows[2].point.x, 1.5, 1e-15);
  const std::string csv = sweep.csv();
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5) << "csv() returned " << csv;
  EXPECT_EQ(csv.rfind("series,x,Jm,Fm,JL,FL,K,backlash,effects,status", 0), 0u);
}

TEST(ApiErrors, OneLineNamingTheArgument) {
  const api::Model& v = case_V();
  expect_error("simulate(t_end = -3)", error_of([&] { v.simulate({.step = 0.5, .t_end = -3}); }), "t_end: must be > 0, got -3");
  expect_error("simulate(step = nan)", error_of([&] { v.simulate({.step = NAN}); }), "step: not finite, got nan");
  expect_error("trace({})", error_of([&] { v.trace({}); }), "v0: empty list");
  expect_error("load(\"IX\")", error_of([] { api::load("IX"); }), "unknown case 'IX': expected I..VIII or a case file path");
  expect_error("from_texts with Jm = 0",
               error_of([] {
                 api::Case::from_texts({{"measured_at", "load"}, {"Jm", "0"}, {"Fm", "0"}, {"JL", "1"}, {"FL", "0"},
                                        {"K", "1"}, {"backlash", "0"}, {"reference", "0"}});
               }),
               "Jm: non-positive inertia (got \"0\"; an inertia must be > 0)");
  expect_error("from_texts without K",
               error_of([] {
                 api::Case::from_texts({{"measured_at", "load"}, {"Jm", "1"}, {"Fm", "0"}, {"JL", "1"}, {"FL", "0"},
                                        {"backlash", "0"}, {"reference", "0"}});
               }),
               "K: missing key");
  expect_error("from_texts with Fm = abc",
               error_of([] {
                 api::Case::from_texts({{"measured_at", "load"}, {"Jm", "1"}, {"Fm", "abc"}, {"JL", "1"}, {"FL", "0"},
                                        {"K", "1"}, {"backlash", "0"}, {"reference", "0"}});
               }),
               "Fm: not a number: \"abc\" (expected a digit; write a decimal such as 0.3 or a fraction such as \"1/3\")");
  expect_error("from_texts with restitution and compliance",
               error_of([] {
                 api::Case::from_texts({{"measured_at", "load"}, {"Jm", "1"}, {"Fm", "0"}, {"JL", "1"}, {"FL", "0"},
                                        {"K", "1"}, {"backlash", "0.1"}, {"reference", "0"}, {"restitution", "0.5"},
                                        {"stiffness", "100"}, {"damping", "1"}});
               }),
               "restitution: restitution and compliance both model the impact (a compliant mesh has its own rebound, "
               "set by its damping); give one of them");
  expect_error("from_texts with Jx", error_of([] { api::Case::from_texts({{"Jx", "1"}}); }),
               "Jx: unknown parameter (allowed: name measured_at K backlash reference Jm Fm JL FL experiment step t_end "
               "drive_gain coulomb_motor coulomb_load restitution saturation stiffness damping delay torque_offset "
               "stribeck_motor_static stribeck_motor_kinetic stribeck_motor_velocity stribeck_load_static "
               "stribeck_load_kinetic stribeck_load_velocity)");
  expect_error("sweep(vary = Q)", error_of([] { api::sweep({.target = "V", .vary = "Q", .from = 0, .to = 1, .points = 2}); }),
               "vary: unknown parameter 'Q' (Jm, Fm, JL, FL, K, backlash, reference, JL_over_Jm, FL_over_F, "
               "coulomb_motor, coulomb_load, restitution, saturation, stiffness, damping, delay, torque_offset, "
               "stribeck_motor_static, stribeck_motor_kinetic, stribeck_motor_velocity, stribeck_load_static, "
               "stribeck_load_kinetic, stribeck_load_velocity)");
  expect_error("sweep(points = 0)", error_of([] { api::sweep({.target = "fig31", .points = 0}); }),
               "points: expected an integer >= 1, got 0");
  expect_error("validate(tolerance = 0)", error_of([] { api::validate(api::load("V"), false, 0); }),
               "tolerance: must be positive");
  try {
    case_V().simulate({.step = 0.5, .t_end = 0});
    ADD_FAILURE() << "simulate(t_end = 0) returned a result instead of BadInput";
  } catch (const api::BadInput& error) {
    EXPECT_EQ(error.argument(), "t_end");
    EXPECT_TRUE(api::is_bad_input(error));
  }
}

// No path is compiled in (docs/design.md, "Library and package"): the thesis's cases come
// from the data folder, share/backlash beside the binary, or $BACKLASH_DATA_DIR.
TEST(ApiData, ThesisCasesComeFromTheDataFolder) {
  const char* cases_variable = std::getenv("BACKLASH_CASES_DIR");  // ctest points it at the sources
  const std::string saved_cases = cases_variable != nullptr ? cases_variable : "";
  ::unsetenv("BACKLASH_CASES_DIR");
  ::unsetenv("BACKLASH_DATA_DIR");
  const std::filesystem::path beside = model::data_dir();
  EXPECT_TRUE(std::filesystem::exists(beside / "cases" / "V.toml"))
      << "data_dir() returned " << beside << " instead of a folder holding cases/V.toml";
  EXPECT_EQ(api::load("V").spec().name, "Case V");

  // $BACKLASH_DATA_DIR wins: a folder whose V.toml holds case VIII's numbers.
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("backlash-data-" + std::to_string(::getpid()));
  std::filesystem::create_directories(folder / "cases");
  std::filesystem::copy_file(beside / "cases" / "VIII.toml", folder / "cases" / "V.toml",
                             std::filesystem::copy_options::overwrite_existing);
  ::setenv("BACKLASH_DATA_DIR", folder.c_str(), 1);
  EXPECT_EQ(model::data_dir(), folder);
  const api::Case redirected = api::load("V");
  EXPECT_EQ(redirected.spec().name, "Case VIII") << "load(\"V\") with BACKLASH_DATA_DIR=" << folder << " read "
                                                 << redirected.spec().source << " instead of " << folder / "cases/V.toml";
  ::unsetenv("BACKLASH_DATA_DIR");
  std::filesystem::remove_all(folder);
  if (cases_variable != nullptr) ::setenv("BACKLASH_CASES_DIR", saved_cases.c_str(), 1);
}

TEST(ApiErrors, RecordsAreCheckedByTheCsvContract) {
  expect_error("make_record with t not increasing",
               error_of([] { api::make_record({0, 1, 1, 2, 3, 4, 5, 6, 7, 8}, std::vector<double>(10, 0.0)); }),
               "<arrays>: t: not strictly increasing: t[2] = 1 after t[1] = 1");
  expect_error("make_record with 3 samples", error_of([] { api::make_record({0, 1, 2}, {0, 0, 0}); }),
               "<arrays>: too few samples: 3 data rows, at least 10 required");
}

}  // namespace
