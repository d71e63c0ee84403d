// backlash/api/backlash.hpp — the whole job through one door: a case in, a validated
// model, and every numeric result, each able to write itself as the CLI prints it.
//
//   #include "backlash/api/backlash.hpp"          // target backlash::api (no GiNaC)
//   const backlash::api::Model v(backlash::api::load("V"));
//   std::cout << v.limit_cycle().json();          // = `backlash limit-cycle V --json`
//
// The system (docs/physics.md, thesis notation, gear ratio 1): a motor (inertia Jm,
// viscous friction Fm) drives a load (JL, FL) through a gear with total backlash b, in a
// loop of gain K toward the reference θR; θo is the measured shaft — θm when the case is
// measured at the motor, θL at the load.  Units: angles in rad, times in s, velocities in
// rad/s, torques in units of K·rad.  The effects the thesis left out (Coulomb friction,
// restitution, saturation, compliance, delay, a torque offset: the [effects] table,
// docs/effects.md) are part of a case and reach every computation below.
//
// The route:
//   1. a Case: load("V") (a thesis case I…VIII), load("my.toml") (a case file),
//      load(CaseParameters{…}) or load(parameter texts) (numbers given in code) — every
//      number an exact rational, every input through the one strict case-file reader;
//   2. a Model: Model(case) passes the case through the validation gates (the closed-form
//      evaluator against Boost.Odeint, numeric/validation.hpp; the effect modes,
//      numeric/effects_simulation.hpp) and refuses a case that fails them;
//   3. results: Model::simulate (step response), Model::trace (dividing lines),
//      Model::limit_cycle, sweep() (limit cycles over a parameter), discrepancy() (a model
//      against a measured record), validate() (the gates' reports).  Each result keeps the
//      numeric library's own result (its fields are documented there) and writes itself:
//      json() / csv() / text() return exactly what the CLI prints for the same request
//      (docs/design.md: the JSON keys are a contract), final newline included.  A
//      discrepancy's JSON, page, figures and corrected case file are laid out apart, in
//      backlash/api/discrepancy_pages.hpp (target backlash::discrepancy_pages, also without GiNaC).
// The exact derivation (GiNaC) is apart, in backlash/api/derive.hpp (target
// backlash::api_derive), so that a program using this header alone never links GiNaC.
//
// Errors: bad input — an argument out of range, a bad case file (model::CaseFileError), a
// bad record (measurements::MeasuredDataError), parameters whose time scales double
// precision cannot handle (numeric/scales.hpp: refused before any work), or api::BadInput
// below — is an exception whose what() is one line naming the file, line and key, or the
// argument; the CLI prints it and exits 2.  A case whose evaluator fails its gate is
// numeric::ValidationFailed (one line naming the failing states; exit 1).  Nothing is
// written before the input is known good.  A simulation that stops before its end time
// (chattering, event cap, ...) is no error: Simulation::stopped_early() says so (the CLI's
// exit code 3).
//
// Long outputs stream: Model::simulate_csv and the sweep() taking a TextSink hand their
// CSV over row by row as it is computed, so memory stays flat in the output's length.
//
// Threads: every function here may run concurrently on different objects (numeric work
// only); sweep() and discrepancy() use `threads` worker threads themselves.
// Reproducibility: the same request gives byte-identical json()/csv()/text(), whatever
// the number of threads.
#pragma once

#include "backlash/discrepancy/discrepancy.hpp"
#include "backlash/discrepancy/measured_drive.hpp"
#include "backlash/measurements/emps.hpp"
#include "backlash/measurements/measured_record.hpp"
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/dividing_lines.hpp"
#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/limit_cycle.hpp"
#include "backlash/numeric/sweep.hpp"
#include "backlash/numeric/validation.hpp"

#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace backlash::api {

// ====================================================================== errors

/// A bad argument.  what() is one line, "ARGUMENT: problem" (e.g. "t_end: must be > 0,
/// got -3"); argument() is the facade's name for it (the CLI's flag without "--", '_' for
/// '-'), so that a front end can name it its own way.
class BadInput : public std::invalid_argument {
 public:
  BadInput(std::string argument, const std::string& problem);
  const std::string& argument() const { return argument_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string argument_;
  std::string problem_;
};

/// True for the exceptions that mean bad input (BadInput, model::CaseFileError,
/// measurements::MeasuredDataError): the CLI's exit code 2, Python's ValueError.
bool is_bad_input(const std::exception& error);

/// Where a streamed output goes: called with each piece of text in order (a CSV's header,
/// then one row at a time), e.g. [](std::string_view text) { std::cout << text; }.  An
/// exception it throws stops the computation and is passed on.
using TextSink = std::function<void(std::string_view)>;

// ====================================================================== 1. a case

/// A case given in code, every number an exact rational (model::Rational: 3/10 is
/// Rational(3, 10), never the double 0.3).  The fields are the case file's
/// (docs/design.md, "Case files"): Jm, Fm are [motor] J, F; JL, FL are [load] J, F.
struct CaseParameters {
  std::string name = "parameters";  ///< the case's name; also its id in results
  model::MeasuredAt measured_at = model::MeasuredAt::Load;
  model::Rational Jm{}, Fm{}, JL{}, FL{};  ///< inertias > 0, viscous frictions >= 0
  model::Rational K{};                     ///< loop gain > 0
  model::Rational backlash{};              ///< total backlash b >= 0 (faces at ±b/2)
  model::Rational reference{};             ///< θR
  std::optional<model::Rational> step{}, t_end{};  ///< an optional step experiment (t_end > 0)
  /// Neutral unless set: one exact member per effect parameter, named by its FIELD in the
  /// table of effects (model/effect_table.hpp), e.g. effects.coulomb_load = Rational(1, 100);
  /// a compliant mesh sets mesh_stiffness and mesh_damping (docs/effects.md).
  model::Effects effects{};
};

/// A case: exact parameters, optional experiment and effects.  Cheap to copy.
class Case {
 public:
  /// `case_or_path`: a thesis case "I" … "VIII" (any letter case; the files of the data
  /// folder, model/data_dir.hpp) or the path of a case file.  model::CaseFileError
  /// ("FILE:LINE: KEY: problem") on anything the strict reader refuses.
  static Case load(const std::string& case_or_path);

  /// Numbers given in code, checked by the same reader and rules as a case file.
  static Case from_parameters(const CaseParameters& parameters);

  /// Parameters as (name, exact text) pairs — how other languages pass them (Python's
  /// load(Jm="1/2", ...)).  Names: name measured_at Jm Fm JL FL K backlash reference,
  /// experiment ("step" | "drive") step t_end drive_gain, and every effect parameter by its
  /// NAME in the table of effects (backlash/model/effect_table.hpp).  Numbers
  /// as the case file's strings: "0.3" (= 3/10), "1/3", "-2e-3", "4".  A problem is a
  /// BadInput naming the parameter: "Jm: non-positive inertia (got "0"; an inertia must be
  /// > 0)", "K: missing key", "Jx: unknown parameter (allowed: ...)".
  static Case from_texts(const std::vector<std::pair<std::string, std::string>>& parameters);

  /// A case file's text already in memory; `name` stands for the file in messages; the
  /// id is `id`, or name's stem when `id` is empty (as for a file).
  static Case from_text(const std::string& toml, const std::string& name, const std::string& id = "");

  const model::CaseSpec& spec() const { return spec_; }
  const std::string& id() const { return spec_.id; }  ///< "V", a file's stem, or the name given
  /// As doubles (numeric::parameters_of, the one converter).
  numeric::Parameters parameters() const { return numeric::parameters_of(spec_); }
  numeric::Effects effects() const { return numeric::effects_of(spec_); }
  /// A case file with exactly these numbers ("p/q" strings): from_text(case_file(), id())
  /// gives this case back.
  std::string case_file() const;

 private:
  explicit Case(model::CaseSpec spec) : spec_(std::move(spec)) {}
  model::CaseSpec spec_;
};

/// Case::load and Case::from_parameters.
Case load(const std::string& case_or_path);
Case load(const CaseParameters& parameters);

// ====================================================================== results

/// `simulate`: the exact event-driven step response from rest in contact, θo = θR − step
/// (docs/physics.md, "Step experiment"), with the case's effects.
struct Simulation {
  std::string case_id;
  double step = 0;   ///< A [rad]
  double t_end = 0;  ///< [s]
  numeric::Parameters parameters;
  numeric::Effects effects;
  /// Events (separation, recombination, recontact, rest, stick, slip, saturation,
  /// desaturation; t [s], θo [rad], θ̇o [rad/s] after the event), the final state, the
  /// status (completed, rest, chattering, event_limit, non_finite, unresolved, work_limit),
  /// stop_reason for an early stop, and the trajectory samples when a sample interval was
  /// asked for (none from Model::simulate_csv, which streams them).
  numeric::SimulationResult result;
  /// The admitted start state of a run from a state (simulate_from_state; its JSON's "from").
  std::optional<numeric::HybridState> start{};

  /// θo − θR at the end [rad].
  double final_error() const { return result.theta_o_final - parameters.theta_R; }
  /// True when the run ended before t_end without the model stopping by itself
  /// (numeric::stopped_early: chattering, event_limit, non_finite, unresolved, work_limit):
  /// everything up to the stop is valid; the CLI exits 3 (docs/design.md, "Exit 3").
  bool stopped_early() const;
  /// "stopped early at t = T (STATUS): REASON", the line the CLI prints on stderr; empty
  /// when the run did not stop early.
  std::string stop_message() const;
  std::string json() const;  ///< `simulate CASE --json` (with "stop_reason" after an early stop)
  /// `simulate CASE --csv`: t,theta_o,dtheta_o,theta_m,dtheta_m,theta_L,dtheta_L,mode, and
  /// a last line "# stopped early at t = …" after an early stop.
  std::string csv() const;
  std::string text() const;  ///< `simulate CASE`
};

struct SimulationRequest {
  std::optional<double> step{};   ///< A [rad]; default: the case's [experiment] step (else BadInput "step")
  std::optional<double> t_end{};  ///< [s] > 0; default: the case's t_end, else 60
  double sample_interval = 0;     ///< > 0: record the trajectory every this many seconds (csv())
};

/// The most samples one simulation records or streams (t_end/sample_interval + 1): ten
/// million, 640 MB held in memory or about 1.3 GB of CSV text (docs/design.md, "Command line").
inline constexpr double largest_sample_count = 1e7;

/// A sampled trajectory's spacing [s] — the CLI's --dt, Python's dt — checked before any
/// work: BadInput "sample_interval" unless finite and > 0.  The simulations also refuse,
/// with the end time known, more than largest_sample_count samples (BadInput "sample_interval").
void check_sample_interval(double sample_interval);

/// A start in free flight just after a separation (the thesis's "second inputs", a point of
/// a limit cycle on the separation line): both shafts at θ̇o [rad/s], the measured one at
/// θo [rad], the gap at the face just left — face −1: θL − θm = −b/2 (the motor was pushing
/// forward), +1: +b/2.  Model::simulate_from runs the model from it.
struct FreeFlightStart {
  int face = -1;
  double theta_o = 0;   ///< [rad]
  double dtheta_o = 0;  ///< [rad/s]
};

/// `simulate --from`: any state of the hybrid system as a start (docs/physics.md: the gap
/// x = θL − θm is centred, the faces are x = ±b/2): both shafts' angles [rad] and velocities
/// [rad/s], in contact (on the face x = ±b/2, both shafts at one velocity; with a compliant mesh,
/// the mesh engaged: |x| >= b/2) or in free flight: strictly inside the backlash (|x| < b/2, any
/// velocities; the first event is the gap's arrival at a face) or leaving a face (x = ±b/2, the
/// gap not closing beyond it; the nominal model with both shafts at one velocity: the drive not
/// pressing them together — a flight that would end at once).  Model::simulate_from_state
/// checks it and runs the model from it.
struct StartState {
  double theta_m = 0, dtheta_m = 0, theta_L = 0, dtheta_L = 0;
  bool in_contact = true;
};

/// The start state a front end was given (`simulate --from LIST`, Python's
/// simulate_from(from_=...)): `from` is θm, θ̇m, θL, θ̇L, or θo, θ̇o — the measured shaft, the
/// gap x = θL − θm then `gap` (default: on the face that drives toward θR: x = −b/2 when
/// θo <= θR, the motor pushing forward, else +b/2; in flight: the face contact would leave
/// there, +b/2 when eq. 25's transmitted torque Tc > 0, else −b/2) and the other shaft moving at
/// `other_velocity` (default θ̇o).  In contact unless `in_contact` is false (free flight).
/// BadInput "from" for a list of another length, "gap" / "other_velocity" when given with
/// the four shaft values.  Admissibility is Model::simulate_from_state's to check.
StartState start_state(const numeric::Parameters& p, const std::vector<double>& from, bool in_contact,
                       std::optional<double> gap = std::nullopt, std::optional<double> other_velocity = std::nullopt);

/// `trace`: the dividing lines — for each θ̇m0 on the separation line θo = θR + cot φ·θ̇m0,
/// the first recombination (or recontact): time [s], motor and load just before the
/// impact, the recombined θo, θ̇o just after it (eq. 24).  The thesis's frame:
/// θm(0) = θL(0) at separation (docs/physics.md, "Two frames").
struct Trace {
  std::string case_id;
  std::string evaluator;  ///< the validated evaluator's name, e.g. "case V (generated)"
  numeric::DividingLines lines;
  std::string json() const;  ///< `trace CASE --json`
  std::string csv() const;   ///< v0,status,grazing,t,theta_m,dtheta_m,theta_L,dtheta_L,theta_o,dtheta_o (empty cells: none)
  std::string text() const;  ///< `trace CASE`
};

/// `limit-cycle`: the fixed point of the half-cycle return map on the separation line
/// (numeric/limit_cycle.hpp) — or of the full return map with effects
/// (numeric/effects_limit_cycle.hpp) — or its absence with the reason.  amplitude is
/// max|θo − θR| [rad], peak_to_peak the swing of θo (the thesis's "magnitude"), period [s],
/// separation_velocity |θ̇o| at separation [rad/s], multiplier the return map's derivative.
struct Cycle {
  std::string case_id;
  numeric::Parameters parameters;
  numeric::Effects effects;
  numeric::LimitCycle cycle;
  /// "limit_cycle" (a period-k cycle when cycle.period_count = k > 1), "none" (the motion
  /// settles; reason in cycle.reason), "divergent" or "unresolved" (the search could not
  /// decide; reason in cycle.reason): the CLI's `status`.
  /// The one place the numeric layer's status is turned into text.
  std::string status() const;
  bool found() const { return cycle.status == numeric::CycleStatus::LimitCycle; }
  std::string json() const;  ///< `limit-cycle CASE --json`
  std::string text() const;  ///< `limit-cycle CASE`
};

// ====================================================================== 2. the validated model

/// A case through its validation gates.  Construction first refuses parameters whose time
/// scales double precision or the certified event searches cannot handle (numeric/scales.hpp:
/// model::CaseFileError "FILE: cannot be computed in double precision: K, motor.J: …",
/// before any work), then runs the gates (a few milliseconds for a thesis case) and throws
/// numeric::ValidationFailed — "case V: the evaluator failed validation against odeint
/// (theta_m, gap); refusing to use it" — when one fails.
class Model {
 public:
  explicit Model(Case source);

  const Case& source() const { return case_; }
  const std::string& id() const { return case_.id(); }
  /// The nominal model's evaluator (generated for a thesis case with its own numbers,
  /// else the stable parametric one) and its validation report.
  const numeric::ValidatedEvaluator& evaluator() const { return validation_.evaluator(); }
  /// The model with its effects (the nominal one when the case has none).
  const numeric::ValidatedEffectModel& effect_model() const { return effects_.model(); }

  /// The step response.  BadInput "step" (none given and the case has no step
  /// experiment, or a step too large for double precision to resolve the backlash against,
  /// numeric/scales.hpp), "t_end" (<= 0), "sample_interval" (< 0, or more than
  /// largest_sample_count samples).
  Simulation simulate(const SimulationRequest& request = {}) const;
  /// The same, its CSV (Simulation::csv(), byte for byte) handed to `csv` as it is computed:
  /// the header, each sample, the early-stop line.  sample_interval must be > 0.
  Simulation simulate_csv(const SimulationRequest& request, const TextSink& csv) const;
  /// The dividing lines at these θ̇m0 [rad/s] (default: the thesis's values and a
  /// log-spaced sweep, numeric::default_dividing_line_grid).  BadInput "v0" for an empty
  /// or non-finite list.
  Trace trace(const std::vector<double>& v0 = numeric::default_dividing_line_grid()) const;
  /// The run from a free-flight start (not a step: Simulation::step is 0) to `t_end` [s] > 0,
  /// sampled every `sample_interval` [s] (0: events only).  BadInput "face" (not ±1),
  /// "theta_o" / "dtheta_o" (not finite), "t_end", "sample_interval".
  Simulation simulate_from(const FreeFlightStart& start, double t_end, double sample_interval = 0) const;
  /// The run from any admissible state (StartState; not a step: Simulation::step is 0, and
  /// Simulation::start is set) to request.t_end (default: the case's t_end, else 60 s),
  /// sampled every request.sample_interval.  BadInput "from" for a state that is not
  /// admissible, naming the coordinate and the rule: a value not finite, a gap outside
  /// [−b/2, b/2] (a compliant mesh in contact: inside the faces), contact off the faces or with
  /// two velocities, free flight off a face or closing onto it, free flight of a rigid drive (b = 0); "step" when request.step is set;
  /// "t_end", "sample_interval" as for simulate().
  Simulation simulate_from_state(const StartState& start, const SimulationRequest& request = {}) const;
  /// The same, its CSV handed to `csv` as it is computed (as simulate_csv).
  Simulation simulate_from_state_csv(const StartState& start, const SimulationRequest& request, const TextSink& csv) const;
  /// One point of the dividing lines at θ̇m0 = `v0` [rad/s], found by the direct search for
  /// the first gap event (numeric::dividing_line_point; trace() samples a profile instead):
  /// how the thesis's printed table entries are checked.
  numeric::DividingLinePoint trace_point(double v0) const;
  /// The limit cycle, seeded with the case's step experiment when it has one.
  Cycle limit_cycle() const;
  /// The nominal model's validation: its evaluator and the report against odeint (per state:
  /// max |error|, where, pass/fail; numeric/validation.hpp).  It passed (else no Model).
  const numeric::ValidationResult& validation() const { return validation_; }

 private:
  Case case_;
  numeric::ValidationResult validation_;
  numeric::EffectValidationResult effects_;
};

// ====================================================================== 3. sweeps

/// `sweep`: limit-cycle magnitude over one parameter, on the stable parametric
/// evaluators validated per pole-structure branch (numeric/sweep.hpp).
struct SweepRequest {
  /// "fig31" (thesis fig. 31: magnitude vs FL/F for JL = Jm and JL = 4 Jm), "fig32"
  /// (fig. 32: vs JL/Jm for three friction distributions), or a case (I … VIII or a
  /// file) with `vary`, `from`, `to`.
  std::string target{};
  /// For a case: Jm Fm JL FL K backlash reference, JL_over_Jm (keeping Jm + JL), FL_over_F
  /// (keeping Fm + FL), or an effect's parameter by its NAME in the table of effects
  /// (backlash/numeric/varied_parameter.hpp).
  std::string vary{};
  /// For a case: x_i = from + (to − from)·i/(points − 1).
  std::optional<double> from{}, to{};
  long points = 101;  ///< per series, 1 … 2^40/3 (indices and x stay exact in a double)
  int threads = 2;    ///< 1 … 1024
  /// Called from the worker threads (serialised) with (done, total).
  std::function<void(long, long)> progress{};
};

/// A sweep row's status as text ("limit_cycle", "none", "divergent", "unvalidated",
/// "refused", "error"): the CSV's `status` column.  The one place the numeric layer's row
/// status is turned into text.
std::string status_of(const numeric::SweepRow& row);

struct Sweep {
  std::vector<numeric::SweepRow> rows;  ///< in the order of the points (empty when streamed)
  numeric::SweepSummary summary;
  long points = 0;  ///< rows computed (all series)
  int threads = 0;
  /// `sweep ... --out F`'s CSV: series,x,Jm,Fm,JL,FL,K,backlash,effects,status,branches,
  /// peak_to_peak,amplitude,period,separation_velocity,multiplier (12 significant digits).
  std::string csv() const;
  static std::string csv_header();                        ///< the CSV's first line
  static std::string csv_row(const numeric::SweepRow& row);  ///< one row's line
  /// The one line `sweep` prints on stderr: points, threads, validated samples, branches.
  std::string summary_line() const;
};

/// The points of a request (for a case: parameters and effects at each x).  BadInput
/// "target" / "vary" / "from" / "to" / "points" / "threads" for a bad request, naming it.
std::vector<numeric::SweepPoint> sweep_points(const SweepRequest& request);
/// The sweep.  A point's own failure is a status in its row, never an exception.
Sweep sweep(const SweepRequest& request);
/// The same, streamed: the CSV (Sweep::csv(), byte for byte) handed to `csv` row by row, in
/// order, as the rows are done, and each row to `row` when given; the points are made on
/// demand, so memory does not grow with their number.  The result keeps no rows.
Sweep sweep(const SweepRequest& request, const TextSink& csv,
            const std::function<void(const numeric::SweepRow&)>& row = {});

// ====================================================================== 4. discrepancy

/// A measured record: the project's CSV (t, theta_out [, theta_motor, theta_load, drive]),
/// or an EMPS .mat read as `backlash import` converts it.  MeasuredDataError otherwise.
measurements::MeasuredRecord read_record(const std::filesystem::path& file);

/// A record from arrays, checked by the CSV contract (docs/design.md, "Measured data"):
/// `t` strictly increasing, every value finite, columns as long as `t`, at least 10
/// samples.  `name` stands for the file in messages ("NAME: theta_out: ...").
measurements::MeasuredRecord make_record(std::vector<double> t, std::vector<double> theta_out,
                                         std::optional<std::vector<double>> theta_motor = std::nullopt,
                                         std::optional<std::vector<double>> theta_load = std::nullopt,
                                         std::optional<std::vector<double>> drive = std::nullopt,
                                         const std::string& name = "<arrays>");

struct DiscrepancyRequest {
  /// Step workflow: the step A [rad] of the record (default: the model's [experiment]
  /// step); must not be 0; not for a measured drive.
  std::optional<double> step{};
  int threads = 2;  ///< step workflow: candidates fitted in parallel, 1 … 256
  /// Measured drive only: the low-pass cut-off [Hz] (default: from the position's
  /// spectrum), the position-prediction windows [s] (default 0.5), a second record of the
  /// same drive scored with the fitted models (not refitted).
  std::optional<double> cutoff{}, window{};
  std::optional<measurements::MeasuredRecord> validation{};
  /// Step workflow: set, called as each candidate of a round is fitted (done of total;
  /// serialised; each round starts again from 0) — the CLI's progress bar on a terminal.
  std::function<void(long done, long total)> progress{};
};

/// `discrepancy`: where the model and the record disagree, the missing effect named and
/// fitted (docs/discrepancy.md).  A model whose experiment is a measured drive
/// ([experiment] kind = "drive") runs the torque-domain workflow
/// (discrepancy/measured_drive.hpp), any other the step workflow (discrepancy/discrepancy.hpp).
class Discrepancy {
 public:
  bool measured_drive() const { return drive_.has_value(); }
  /// The step workflow's result (null for a measured drive) and the drive's (null otherwise).
  const discrepancy::DiscrepancyResult* step_result() const { return step_ ? &*step_ : nullptr; }
  const discrepancy::DriveDiscrepancyResult* drive_result() const { return drive_ ? &*drive_ : nullptr; }
  discrepancy::Status status() const;
  const model::CaseSpec& model() const { return model_; }
  double step() const { return step_value_; }  ///< the step compared (0 for a drive)

  /// `discrepancy`'s summary; `data` and `validation` name the records as the user gave them.
  /// Its JSON, page, figures and corrected case file: backlash/api/discrepancy_pages.hpp.
  std::string text(const std::string& data, const std::string& validation = "") const;

 private:
  friend Discrepancy discrepancy(const Case&, const measurements::MeasuredRecord&, const DiscrepancyRequest&);
  model::CaseSpec model_;
  double step_value_ = 0;
  double window_ = 0;  ///< measured drive: the prediction windows used [s]
  std::optional<discrepancy::DiscrepancyResult> step_;
  std::optional<discrepancy::DriveDiscrepancyResult> drive_;
};

/// The workflow.  BadInput "step" (0, missing — as model::CaseFileError
/// "FILE:1: experiment.step: ..." when the model file has no step either —, or given for a
/// measured drive), "threads", "cutoff", "window", "validation" (only for a measured drive);
/// BadInput "data" for a record the model cannot be compared with; MeasuredDataError naming
/// the line for a sample larger in size than 1e100 (measurements::require_computable) and,
/// for a step, a record that does not cover the step ([experiment] step_time) or has a gap.
Discrepancy discrepancy(const Case& model, const measurements::MeasuredRecord& data,
                        const DiscrepancyRequest& request = {});

/// `import FILE --out CSV`: a record of a real drive converted into the project's CSV
/// (docs/design.md, "Measured data (CSV)") for the measured-drive workflow.  EMPS
/// (measurements/emps.hpp): t → t [s], qm → theta_out [m], the drive force on the mechanism
/// → drive [N] = gtau·vir, plus pulses_N only if the data show the pulses are not already in
/// vir (in the published validation record they are).
struct Import {
  std::string input, out;           ///< the paths as given
  measurements::EmpsRecord emps;    ///< the record as read (gains kp, kv, gtau)
  measurements::EmpsPulses pulses{};  ///< where the excitation pulses are
  measurements::MeasuredRecord record;  ///< what was written
  /// What `import` prints: samples, duration, sample rate, gains, columns, the pulses, and
  /// the [experiment] table for a measured-drive model file.
  std::string text() const;
};

/// Reads the EMPS .mat `input` and writes its CSV to `out` atomically (an existing regular
/// file is replaced); measurements::MeasuredDataError (nothing written) for a record it
/// cannot read or convert.
Import import_record(const std::filesystem::path& input, const std::filesystem::path& out);

// ====================================================================== 5. the gates' reports

/// `validate`: every evaluator of a case — its generated one (a thesis case with its own
/// numbers), the stable parametric one, the direct per-branch formulas — and/or the
/// parametric and direct evaluators at a representative point of each of the 14
/// pole-structure branches, against Boost.Odeint: max abs error per state, where it occurs,
/// pass/fail.
struct Validation {
  std::string document;  ///< `validate ... --json`
  std::string report;    ///< `validate ...` (text)
  /// "case V: parametric (theta_m: max |error| … > tolerance)", ... (empty: all passed)
  std::vector<std::string> failures;
  bool passed() const { return failures.empty(); }
  std::string json() const { return document; }
  std::string text() const { return report; }
  /// "validation failed: FAILURE; FAILURE" — the CLI's one line instead of the report.
  std::string failure_message() const;
};

/// BadInput "tolerance" (<= 0 or not finite); BadInput "case" when neither a case nor
/// branches is asked for.  A case whose time scales double precision cannot handle is
/// refused before any work (model::CaseFileError, numeric/scales.hpp).
Validation validate(const std::optional<Case>& source, bool branches, double tolerance = 1e-9);

}  // namespace backlash::api
