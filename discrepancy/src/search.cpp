// The search for what a model is missing (docs/discrepancy.md, "The search"): rounds of
// candidates — effects and nominal parameters — judged by one decisive rule, pairs where no
// single candidate is decisive, everything named refitted together, and a named candidate that
// the later ones make needless replaced.
#include "internal.hpp"

#include "backlash/model/effect_table.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <deque>
#include <iterator>
#include <cmath>
#include <mutex>
#include <map>
#include <set>
#include <thread>

namespace backlash::discrepancy::detail {

Scores score(const Observations& o, const std::vector<std::vector<double>>& traces) {
  Scores s;
  const std::vector<double> fit = residuals(o, traces, o.fit_indices);
  const std::vector<double> held = residuals(o, traces, o.holdout_indices);
  s.sse_fit = sum_of_squares(fit);
  s.sse_holdout = sum_of_squares(held);
  s.sse = s.sse_fit + s.sse_holdout;
  s.n_fit = fit.size();
  s.n_holdout = held.size();
  s.n = s.n_fit + s.n_holdout;
  s.robust = robust_sum(fit) + robust_sum(held);
  s.tau_int = o.tau_int;
  double sum = 0;
  for (std::size_t i : o.all_indices) sum += (o.columns[0][i] - traces[0][i]) * (o.columns[0][i] - traces[0][i]);
  s.rms_theta_out = std::sqrt(sum / std::max<std::size_t>(1, o.all_indices.size()));
  return s;
}

double at_noise_level(const Observations& o, double noise_level) {
  const double n = static_cast<double>(std::max<std::size_t>(1, o.all_indices.size() * o.columns.size()));
  return std::max(noise_level, 1 + 3 * std::sqrt(o.tau_int / (2 * n)));
}

int Search::parameters() const {
  int k = 0;
  for (const Named& n : named) k += static_cast<int>(n.candidate.ranges.size());
  return k;
}

bool Search::rescore() {
  const auto traces = simulator.traces(current, o.size());
  if (!traces) return false;
  scores = score(o, *traces);
  return true;
}

namespace {

/// The candidates fitted in a round after the first (the rest screened out by their scans).
constexpr std::size_t kRoundFits = 6;
/// The singles a pair is built on: the round's best five by BIC (a pair's first effect can rank
/// fourth or fifth alone, behind parameters that absorb part of both).
constexpr std::size_t kSingles = 5;
/// The partners fitted with each of a round's best kSingles singles (screened at its fit: a partner
/// that only a joint fit shows — its single fit biased by the missing partner — can rank low there).
constexpr std::size_t kPartners = 8;

// A named candidate's parameters as reported: one fitted relative to another (the compliance's
// damping from its ratio, Stribeck's static level from its ratio to the kinetic one,
// model::CandidateScale) as the model's value; σ of Ts from σ of both (taken as independent).
std::vector<Parameter> reported(const EffectCandidate& c, const std::vector<double>& values,
                                const std::vector<double>& uncertainty, const ModelPoint& point) {
  std::vector<Parameter> out;
  for (std::size_t i = 0; i < c.ranges.size(); ++i)
    out.push_back({c.ranges[i].name, values[i], uncertainty.empty() ? NAN : uncertainty[i]});
  const model::EffectInfo* row = model::effect_keyed(c.effect);
  for (std::size_t k = 0; row && k < row->count && k < out.size(); ++k) {
    const model::EffectParameterInfo& parameter = model::effect_parameters[row->first + k];
    const double value = model::field(point.e, parameter.id), ratio = values[k];
    if (parameter.scale == model::CandidateScale::DampingRatio) out[k] = {out[k].name, value, out[k].uncertainty * value / ratio};
    if (parameter.scale == model::CandidateScale::KineticRatio) {
      const double kinetic = value / ratio, kinetic_sigma = out[k + 1].uncertainty;  // the kinetic level follows
      out[k] = {out[k].name, value, value * std::hypot(out[k].uncertainty / ratio, kinetic_sigma / kinetic)};
    }
  }
  return out;
}

// The fit's coordinate u of a named candidate's reported parameter (the compliance's damping
// back to its ratio, Stribeck's static level back to Ts/Tk).
double coordinate_of(const EffectCandidate& c, const std::vector<Parameter>& ps, std::size_t j, const ModelPoint& base) {
  const ParameterRange& r = c.ranges[j];
  double value = ps[j].value;
  if (c.effect == "compliance" && j == 1)
    value = value / (2 * std::sqrt(ps[0].value * base.p.Jm * base.p.JL / (base.p.Jm + base.p.JL)));
  if (const model::EffectInfo* row = model::effect_keyed(c.effect); row && j + 1 < ps.size() &&
      model::effect_parameters[row->first + j].scale == model::CandidateScale::KineticRatio)
    value = value / ps[j + 1].value;
  const double u = r.logarithmic ? std::log(value / r.low) / std::log(r.high / r.low) : (value - r.low) / (r.high - r.low);
  return std::min(1.0, std::max(0.0, u));
}

struct Trial {
  EffectCandidate candidate;
  Fit fit;
  Candidate result;
  ModelPoint point;
};

// The held-out samples confirm a model scored `sc` against the current one: they must shrink, or,
// when the model already meets them at the noise level, at least not get worse.  Shrinking means
// to at most decisive_holdout of the current RMS, or by as much as the held-out samples' own
// likelihood ratio calls decisive (n_eff·ln(SSE ratio) < −decisive_bic: a large gap that a real
// effect closes only in part, while another remains).
bool holdout_confirms(const Search& s, const Scores& sc) {
  const DiscrepancyOptions& options = s.options;
  const double held = s.scores.rms_holdout(), rms = sc.rms_holdout();
  const double n_held = std::max(1.0, static_cast<double>(sc.n_holdout) / s.o.tau_int);
  return rms < options.decisive_holdout * held || n_held * 2 * std::log(rms / held) < -options.decisive_bic ||
         (held <= options.noise_level && rms <= 1.02 * held);
}

// A fitted trial scored against the current model by the decisive rule (docs/discrepancy.md).
void judge(Trial& t, const Search& s, int current_k) {
  const DiscrepancyOptions& options = s.options;
  t.point = t.candidate.apply(s.current, t.fit.values);
  const auto traces = s.simulator.traces(t.point, s.o.size());
  if (!traces) {
    t.fit.ok = false;
    return;
  }
  const Scores sc = score(s.o, *traces);
  ++t.result.simulations;
  t.result.parameters = reported(t.candidate, t.fit.values, t.fit.uncertainty, t.point);
  t.result.rms = sc.rms_theta_out;
  t.result.rms_fit = sc.rms_fit();
  t.result.rms_holdout = sc.rms_holdout();
  const int k = current_k + static_cast<int>(t.candidate.ranges.size());
  t.result.bic = sc.bic(k);
  t.result.delta_bic = t.result.bic - s.scores.bic(current_k);
  // Decisive on both: the BIC, and the held-out samples (holdout_confirms).
  const bool confirmed = holdout_confirms(s, sc);
  // A parameter pinned at the edge of its range cannot be told from that limit: not decisive.
  t.result.at_range_edge = std::any_of(t.fit.u.begin(), t.fit.u.end(), [](double u) { return u < 1e-3 || u > 1 - 1e-3; });
  t.result.decisive = t.result.delta_bic < -options.decisive_bic && confirmed && !t.result.at_range_edge;
}

// One trial: the candidate built around the current model, fitted, judged.
void run_trial(Trial& t, Search& s, const std::string& name, double departure, const std::vector<double>* start) {
  const auto started = std::chrono::steady_clock::now();
  t.result.effect = name;
  try {
    if (t.candidate.ranges.empty()) t.candidate = candidate_for(name, s.current, s.step);
    // A pair (started from its singles' fits) gets a quarter of a single candidate's budget.
    const long budget = start ? s.options.candidate_work / 4 : s.options.candidate_work;
    t.fit = fit_candidate(s.simulator, s.o, s.current, t.candidate, false, start, budget, departure);
    if (t.fit.budget_exhausted)
      t.result.failure = s.simulator.budget_reached()
                             ? "the search's work budget of " + std::to_string(s.options.total_work) + " was reached"
                             : "its fit reached the work budget of " + std::to_string(s.options.candidate_work) +
                                   " (1000 per simulation plus its events)";
  } catch (const std::exception& error) {  // a candidate that cannot be built or simulated has failed
    t.fit = Fit{};
    t.result.failure = error.what();
  }
  t.result.simulations = t.fit.simulations;
  if (t.fit.ok) judge(t, s, s.parameters());
  if (!t.fit.ok) t.result.bic = t.result.rms = t.result.rms_holdout = INFINITY;
  t.result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
}

// Runs job(i) for i < n on the options' threads (each index once; the results stay in index order).
template <typename Job>
void parallel_for(std::size_t n, int threads, Job job) {
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    for (std::size_t i = next++; i < n; i = next++) job(i);
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < std::max(1, threads); ++k) pool.emplace_back(work);
  work();
  for (std::thread& th : pool) th.join();
}

// What a computation asked of the simulator: its simulations and their work (Simulator::traces's
// cost).  Exact when every one had a cost: a point outside the family or one that threw has none
// (not kept: asked again, it is tried again, not served).
struct Charged {
  int simulations = 0;
  long work = 0;
  bool exact = true;
  void add(long cost) { ++simulations, work += cost, exact = exact && cost > 0; }
};

// The directions in which already-fitted parameters move the residual on the fitted samples: the
// columns ∂r/∂u at `u` of `c` applied to `base` (central differences, ±0.01 in u), orthonormalised
// (thin QR).  Empty when a point could not be simulated.  `charged`, if given, adds its simulations.
Eigen::MatrixXd directions(Search& s, const EffectCandidate& c, const ModelPoint& base, const std::vector<double>& u,
                           Charged* charged = nullptr) {
  const std::size_t n = s.o.fit_indices.size() * s.o.columns.size();
  Eigen::MatrixXd jacobian(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(u.size()));
  for (std::size_t k = 0; k < u.size(); ++k) {
    std::vector<double> plus = u, minus = u;
    plus[k] = std::min(1.0, u[k] + 0.01), minus[k] = std::max(0.0, u[k] - 0.01);
    std::vector<std::vector<double>> r;
    for (const std::vector<double>* at : {&plus, &minus}) {
      std::vector<double> values;
      for (std::size_t i = 0; i < at->size(); ++i) values.push_back(c.ranges[i].value((*at)[i]));
      long cost = 0;
      const auto traces = s.simulator.traces(c.apply(base, values), s.o.size(), nullptr, &cost, Simulator::Grid::fitted);
      if (charged) charged->add(cost);
      if (!traces) return {};
      r.push_back(residuals(s.o, *traces, s.o.fit_indices));
    }
    for (std::size_t i = 0; i < n; ++i) jacobian(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)) = (r[0][i] - r[1][i]) / (plus[k] - minus[k]);
  }
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(jacobian);
  return qr.householderQ() * Eigen::MatrixXd::Identity(jacobian.rows(), jacobian.cols());
}

// Everything named as one candidate applied to the nominal model, and its coordinates now.
std::pair<EffectCandidate, std::vector<double>> named_joint(const Search& s) {
  std::vector<EffectCandidate> parts;
  std::vector<double> u;
  for (const Named& n : s.named) {
    parts.push_back(n.candidate);
    for (std::size_t j = 0; j < n.candidate.ranges.size(); ++j) u.push_back(coordinate_of(n.candidate, n.result.parameters, j, s.base));
  }
  return {combined(parts), u};
}

// The directions of everything named, and of `also` at `also_u` if given (none: empty).
Eigen::MatrixXd named_directions(Search& s, const EffectCandidate* also = nullptr, const std::vector<double>* also_u = nullptr,
                                 Charged* charged = nullptr) {
  auto [joint, u] = named_joint(s);
  if (!also) return u.empty() ? Eigen::MatrixXd() : directions(s, joint, s.base, u);
  std::vector<EffectCandidate> parts;
  if (!u.empty()) parts.push_back(joint);
  parts.push_back(*also);
  u.insert(u.end(), also_u->begin(), also_u->end());
  return directions(s, combined(parts), s.base, u, charged);
}

// The best point of a candidate's scan added to `at`, on the fitted samples: its sum of squares
// with the `fitted` directions projected out — what is left once the parameters already fitted
// move with it, to first order (a partner that only shows when they move ranks where it belongs)
// — INFINITY if no point could be simulated, and u.  At most a quarter of a single candidate's
// budget (a stiff mesh with a delay is slow).  `held`, if given, holds the best point's simulation
// (Simulator::hold: a pair's fit starts there, after thousands of other simulations); `charged`,
// if given, adds the scan's simulations.
double best_scan_point(Search& s, const EffectCandidate& c, const ModelPoint& at, const Eigen::MatrixXd& fitted,
                       std::vector<double>& best_u, Simulator::Held* held = nullptr, Charged* charged = nullptr) {
  double best = INFINITY;
  long work = 0;
  prepare_candidate(s.simulator, c, at);  // else every scan point outside the box is validated alone
  for (const std::vector<double>& u : c.scan()) {
    if (s.simulator.budget_reached() || work >= s.options.candidate_work / 4) break;
    std::vector<double> values;
    for (std::size_t k = 0; k < u.size(); ++k) values.push_back(c.ranges[k].value(u[k]));
    long cost = 0;
    const ModelPoint point = c.apply(at, values);
    const auto traces = s.simulator.traces(point, s.o.size(), nullptr, &cost, Simulator::Grid::fitted);
    work += cost;
    if (charged) charged->add(cost);
    if (!traces) continue;
    std::vector<double> r = residuals(s.o, *traces, s.o.fit_indices);
    double sse = sum_of_squares(r);
    if (fitted.cols() > 0 && static_cast<std::size_t>(fitted.rows()) == r.size())
      sse -= (fitted.transpose() * Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()))).squaredNorm();
    if (sse < best) {
      best = sse, best_u = u;
      if (held) *held = s.simulator.hold(point, s.o.size(), Simulator::Grid::fitted);
    }
  }
  return best;
}

// Every candidate of a round, fitted on the first part and scored (threads over candidates).
std::vector<Trial> round_of(Search& s, double departure, const std::vector<std::string>& names) {
  std::vector<Trial> trials(names.size());
  // After the first round (the model then costs more: a delay named makes every simulation
  // numerical), every candidate's scan is screened and only the best kRoundFits are fitted.
  std::vector<char> fitted(names.size(), 1);
  if (!s.named.empty() && names.size() > kRoundFits) {
    std::vector<std::pair<double, std::size_t>> screened(names.size(), {INFINITY, 0});
    const Eigen::MatrixXd named = named_directions(s);
    parallel_for(names.size(), s.options.threads, [&](std::size_t i) {
      screened[i].second = i;
      try {
        trials[i].candidate = candidate_for(names[i], s.current, s.step);
        std::vector<double> u;
        screened[i].first = best_scan_point(s, trials[i].candidate, s.current, named, u);
      } catch (const std::exception&) {  // fitted (and failed) below, with its reason
      }
    });
    std::stable_sort(screened.begin(), screened.end());
    for (std::size_t k = kRoundFits; k < screened.size(); ++k) {
      Trial& t = trials[screened[k].second];
      fitted[screened[k].second] = 0;
      t.result.effect = names[screened[k].second];
      t.result.failure = "not fitted: its scan ranked " + std::to_string(k + 1) + " of " + std::to_string(names.size()) +
                         " (the best " + std::to_string(kRoundFits) + " are fitted)";
      t.result.bic = t.result.rms = t.result.rms_holdout = INFINITY;
    }
  }
  std::mutex progress_mutex;
  long finished = 0;
  parallel_for(trials.size(), s.options.threads, [&](std::size_t i) {
    if (fitted[i]) run_trial(trials[i], s, names[i], departure, nullptr);
    if (!s.options.progress) return;
    std::lock_guard<std::mutex> lock(progress_mutex);
    s.options.progress(++finished, static_cast<long>(trials.size()));
  });
  std::stable_sort(trials.begin(), trials.end(), [](const Trial& a, const Trial& b) { return a.result.bic < b.result.bic; });
  return trials;
}

// Torque levels (they do not scale with the step) and the shaft an explanation lives on.
bool torque_level(const std::string& name) {
  return name.find("coulomb") != std::string::npos || name == "saturation" || name == "torque_offset" ||
         name.find("stribeck") != std::string::npos;
}
int shaft_of(const std::string& name) {
  if (name.find("motor") != std::string::npos) return 1;
  if (name.find("load") != std::string::npos) return 2;
  return 0;
}

// The experiment that would tell two explanations apart.
std::string experiment_between(const std::string& a, const std::string& b) {
  if (shaft_of(a) != 0 && shaft_of(b) != 0 && shaft_of(a) != shaft_of(b))
    return "the other shaft measured (theta_motor and theta_load columns): the two act on different bodies";
  if (torque_level(a) != torque_level(b))
    return "a larger or a smaller step: a torque level does not scale with the step, a linear term does";
  return "a longer record: the two differ most in how the motion settles";
}

// The decisive trial named: the best by BIC, but a nominal parameter's correction where one fits
// within ambiguity_bic of an effect (no new physics where a wrong number explains the record).
const Trial* choose(const std::vector<Trial>& trials, const Search& s) {
  const double alike = s.options.ambiguity_bic;
  const auto best = std::find_if(trials.begin(), trials.end(), [](const Trial& t) { return t.result.decisive; });
  if (best == trials.end()) return nullptr;
  const Trial* chosen = &*best;
  if (!is_parameter_correction(chosen->result.effect))
    for (const Trial& t : trials)
      if (t.result.decisive && is_parameter_correction(t.result.effect) && t.result.bic < best->result.bic + alike) {
        chosen = &t;
        break;
      }
  return chosen;
}

// The other decisive trials within ambiguity_bic of the one named: explanations alike.
void record_alike(const std::vector<Trial>& trials, const Trial* chosen, Search& s) {
  const double alike = s.options.ambiguity_bic;
  for (const Trial& t : trials)
    if (&t != chosen && t.result.decisive && std::fabs(t.result.bic - chosen->result.bic) < alike) {
      if (s.alike.empty()) s.alike.push_back(chosen->result);
      s.alike.push_back(t.result);
      if (s.experiment.empty()) s.experiment = experiment_between(chosen->result.effect, t.result.effect);
    }
}

// Two contact laws cannot be combined (each puts the others back to neutral): refused by name.
std::string combination_problem(const std::string& a, const std::string& b) {
  const model::EffectInfo* x = model::effect_keyed(a);
  const model::EffectInfo* y = model::effect_keyed(b);
  if (x && y && x->contact_law && y->contact_law)
    return a + " and " + b + " cannot be combined: both are contact laws (one law at the contact)";
  return "";
}

// A partner screened for a single candidate S: the best point of its scan with S at S's fit.
struct Screened {
  const Trial* single = nullptr;
  const Trial* partner = nullptr;
  std::vector<double> u;  ///< the partner's best scan point
  double sse = INFINITY;
  std::string problem;    ///< why the two cannot be combined
  Simulator::Held held;   ///< the best point's simulation, kept for the pair's fit (it starts there)
  Charged charged;        ///< the simulations of the single's directions and of this scan
};

// The partner's scan, every point on the fitted samples with `single` at its fit.
void screen(Screened& x, Search& s, const Eigen::MatrixXd& single) {
  x.problem = combination_problem(x.single->result.effect, x.partner->result.effect);
  if (x.problem.empty()) x.sse = best_scan_point(s, x.partner->candidate, x.single->point, single, x.u, &x.held, &x.charged);
}

// A screen already done (`screened`: the same single and partner) taken over for `x`: what
// screening it again gives, bit for bit — the single's directions and the partner's scan are the
// same simulations, served as kept ones and charged again — provided none is outside the family
// and the search's budget cannot end them on the way (docs/discrepancy.md, "Work budget").  False
// (nothing done) otherwise.
bool take_over(Screened& x, Search& s, const std::vector<Screened>& screened) {
  const auto y = std::find_if(screened.begin(), screened.end(),
                              [&](const Screened& y) { return y.single == x.single && y.partner == x.partner; });
  if (y == screened.end() || !y->problem.empty() || !y->charged.exact || !s.simulator.affords(y->charged.work)) return false;
  x.problem = y->problem, x.u = y->u, x.sse = y->sse, x.held = y->held, x.charged = y->charged;
  s.simulator.charge(y->charged.simulations, y->charged.work);
  return true;
}

// An effect paired with a nominal parameter's correction, chosen from one side only (the other
// single ranked below the best kSingles), gets the other start too: the partner's own fit with the
// single screened at it.  A parameter error that a wrong effect's fit absorbs in part shows little
// alone (a 15 % error in motor.J: ΔBIC −87 beside a Coulomb friction's −1162), and the pair fitted
// from the effect's biased fit ends in a wrong valley (ΔBIC −1260, at a range's edge) where the
// parameter's side reaches the noise (−22636).  `reversed` holds the new starts (stable addresses);
// a start whose partner is a base was screened already (in `screened`: take_over).
void add_reverse_starts(Search& s, std::vector<std::vector<const Screened*>>& chosen, const std::vector<Screened>& screened,
                        std::deque<Screened>& reversed) {
  std::vector<std::size_t> which;
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    const Screened& x = *chosen[i].front();
    if (chosen[i].size() == 1 &&
        is_parameter_correction(x.single->result.effect) != is_parameter_correction(x.partner->result.effect))
      reversed.push_back({x.partner, x.single, {}, INFINITY, "", nullptr, {}}), which.push_back(i);
  }
  parallel_for(reversed.size(), s.options.threads, [&](std::size_t i) {
    Screened& x = reversed[i];
    if (!take_over(x, s, screened)) screen(x, s, named_directions(s, &x.single->candidate, &x.single->fit.u, &x.charged));
  });
  for (std::size_t i = 0; i < reversed.size(); ++i)
    if (std::isfinite(reversed[i].sse)) chosen[which[i]].push_back(&reversed[i]);
}

// Every other candidate screened as a partner of each of fitted[from, to), with its directions
// (and the named's) projected out; appended to `screened`.
void screen_partners(Search& s, const std::vector<const Trial*>& fitted, std::size_t from, std::size_t to,
                     std::vector<Screened>& screened) {
  const std::size_t first = screened.size();
  for (std::size_t i = from; i < to; ++i)
    for (const Trial* partner : fitted)
      if (partner != fitted[i]) screened.push_back({fitted[i], partner, {}, INFINITY, "", nullptr, {}});
  std::vector<Eigen::MatrixXd> moving(to - from);  // each S's directions (with the named)
  std::vector<Charged> charged(to - from);         // and their simulations
  parallel_for(moving.size(), s.options.threads, [&](std::size_t i) {
    moving[i] = named_directions(s, &fitted[from + i]->candidate, &fitted[from + i]->fit.u, &charged[i]);
  });
  parallel_for(screened.size() - first, s.options.threads, [&](std::size_t i) {
    Screened& x = screened[first + i];
    const std::size_t which = static_cast<std::size_t>(std::find(fitted.begin(), fitted.end(), x.single) - fitted.begin());
    x.charged = charged[which - from];
    screen(x, s, moving[which - from]);
  });
}

// The best pair, where it leaves the fitted samples above the noise, refitted from its fit on the
// growing horizons (a single candidate's budget): fitted on the whole record at once, a pair with
// impacts ends in a valley beside the truth (a delay with restitution: 0.186 s and 0.58 for 0.1885 s
// and 0.6, 4.7σ left) which the short horizons, where the response is smooth in the parameters,
// lead out of (at the noise).  Kept when its BIC is lower.
void refine_pair(Search& s, Trial& pair, double departure) {
  if (pair.result.rms_fit <= at_noise_level(s.o, s.options.noise_level) || s.simulator.budget_reached()) return;
  const auto started = std::chrono::steady_clock::now();
  Trial refined;
  refined.candidate = pair.candidate;
  refined.result.effect = pair.result.effect;
  refined.fit = fit_candidate(s.simulator, s.o, s.current, refined.candidate, false, &pair.fit.u, s.options.candidate_work,
                              departure, true);
  if (!refined.fit.ok) return;
  refined.result.simulations = refined.fit.simulations;
  judge(refined, s, s.parameters());
  if (!refined.fit.ok || !refined.result.decisive || refined.result.bic >= pair.result.bic) return;
  refined.result.simulations += pair.result.simulations;
  refined.result.seconds = pair.result.seconds + std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  pair = std::move(refined);
}

// A pair's name, the same from either single: "a + b" in name order.
std::string pair_key(const std::string& a, const std::string& b) { return std::min(a, b) + " + " + std::max(a, b); }

// "The best single plus one": each of the round's best kSingles singles S (fitted, by BIC) with
// every other candidate screened at S's fit (a scan of the partner alone); the kPartners best partners
// of each S fitted together with it (from S's fit and the partner's best scan point; a quarter
// of a single candidate's budget) and judged with both parameters' penalty.  Two contact laws
// cannot be combined: refused by name in the round's list.  The best decisive pair, or nothing.
std::optional<Trial> best_pair(Search& s, const std::vector<Trial>& singles, double departure, std::vector<Candidate>& round) {
  std::vector<const Trial*> fitted;
  for (const Trial& t : singles)
    if (t.fit.ok) fitted.push_back(&t);
  // The best decisive effect below the best kSingles is a single too: beside a parameter error
  // each shows little alone (a torque offset with a 20 % error in load.F: ΔBIC −76 and +113,
  // seventh and eleventh, behind K's −2710), together they meet the noise (−18947).
  std::size_t bases = std::min(kSingles, fitted.size());
  const auto effect = std::find_if(fitted.begin() + static_cast<std::ptrdiff_t>(bases), fitted.end(), [](const Trial* t) {
    return t->result.decisive && !is_parameter_correction(t->result.effect);
  });
  if (effect != fitted.end()) std::rotate(fitted.begin() + static_cast<std::ptrdiff_t>(bases), effect, effect + 1), ++bases;
  std::vector<Screened> screened;
  screen_partners(s, fitted, 0, bases, screened);
  // The best single's best-screened partner, when it is an effect below the bases, is a base too: a
  // pair found beside a stand-in (a delay beside K where Coulomb friction on the motor is missing,
  // ΔBIC −6699: the delay alone, +377, ranked twelfth and the friction, −3.5, eighth) is found from
  // the partner's side.
  const Screened* partner = nullptr;
  for (const Screened& x : screened)
    if (x.single == fitted[0] && std::isfinite(x.sse) && (!partner || x.sse < partner->sse)) partner = &x;
  if (partner && (is_parameter_correction(partner->partner->result.effect) ||
                  std::find(fitted.begin(), fitted.begin() + static_cast<std::ptrdiff_t>(bases), partner->partner) !=
                      fitted.begin() + static_cast<std::ptrdiff_t>(bases)))
    partner = nullptr;
  if (partner) {
    const auto at = std::find(fitted.begin(), fitted.end(), partner->partner);
    std::rotate(fitted.begin() + static_cast<std::ptrdiff_t>(bases), at, at + 1);
    screen_partners(s, fitted, bases, bases + 1, screened), ++bases;
  }
  // A pair chosen from both of its singles is fitted from both starts (each single's fit with the
  // other's screened point): Levenberg–Marquardt on a cost with event kinks ends in the valley of
  // its start, and a single fitted alone is biased by the partner it lacks.
  std::vector<std::vector<const Screened*>> chosen;
  std::map<std::string, std::size_t> seen;
  for (std::size_t i = 0; i < bases; ++i) {
    std::vector<const Screened*> mine;
    for (const Screened& x : screened)
      if (x.single == fitted[i] && std::isfinite(x.sse)) mine.push_back(&x);
    std::sort(mine.begin(), mine.end(), [](const Screened* a, const Screened* b) { return a->sse < b->sse; });
    for (std::size_t k = 0; k < std::min<std::size_t>(kPartners, mine.size()); ++k) {
      const std::string a = mine[k]->single->result.effect, b = mine[k]->partner->result.effect;
      const auto [at, added] = seen.emplace(pair_key(a, b), chosen.size());
      if (added) chosen.push_back({mine[k]});
      else chosen[at->second].push_back(mine[k]);
    }
  }
  for (const Screened& x : screened)  // refused combinations, by name
    if (!x.problem.empty() && seen.emplace(pair_key(x.single->result.effect, x.partner->result.effect), chosen.size()).second) {
      Candidate refused;
      refused.effect = x.single->result.effect + " + " + x.partner->result.effect;
      refused.failure = x.problem;
      refused.bic = refused.rms = refused.rms_holdout = INFINITY;
      round.push_back(refused);
    }
  std::deque<Screened> reversed;
  add_reverse_starts(s, chosen, screened, reversed);
  std::vector<Trial> pairs(chosen.size());
  parallel_for(chosen.size(), s.options.threads, [&](std::size_t i) {
    for (const Screened* from : chosen[i]) {
      Trial trial;
      trial.candidate = combined({from->single->candidate, from->partner->candidate});
      std::vector<double> start = from->single->fit.u;
      start.insert(start.end(), from->u.begin(), from->u.end());
      run_trial(trial, s, trial.candidate.effect, departure, &start);
      if (from == chosen[i].front() || trial.result.bic < pairs[i].result.bic) pairs[i] = std::move(trial);
    }
  });
  std::size_t best = pairs.size();
  for (std::size_t i = 0; i < pairs.size(); ++i)
    if (pairs[i].result.decisive && (best == pairs.size() || pairs[i].result.bic < pairs[best].result.bic)) best = i;
  if (best < pairs.size()) refine_pair(s, pairs[best], departure);
  for (const Trial& pair : pairs) round.push_back(pair.result);
  if (best == pairs.size()) return std::nullopt;
  return std::move(pairs[best]);
}

// Everything named refitted together on the whole record from `base`, from their current values;
// each named candidate's parameters updated.  Returns the model, or nothing if the fit failed.
std::optional<ModelPoint> joint_refit(Search& s, std::vector<Named>& named) {
  if (named.empty()) return s.base;
  std::vector<EffectCandidate> parts;
  std::vector<double> start;
  for (const Named& n : named) {
    parts.push_back(n.candidate);
    for (std::size_t j = 0; j < n.candidate.ranges.size(); ++j)
      start.push_back(coordinate_of(n.candidate, n.result.parameters, j, s.base));
  }
  const EffectCandidate joint = combined(parts);
  const Fit fit = fit_candidate(s.simulator, s.o, s.base, joint, true, &start);
  if (!fit.ok) return std::nullopt;
  const ModelPoint point = joint.apply(s.base, fit.values);
  std::size_t at = 0;
  for (Named& n : named) {
    const std::size_t k = n.candidate.ranges.size();
    const std::vector<double> values(fit.values.begin() + at, fit.values.begin() + at + k);
    const std::vector<double> sigma(fit.uncertainty.begin() + at, fit.uncertainty.begin() + at + k);
    n.result.parameters = reported(n.candidate, values, sigma, point);
    n.result.no_sigma = std::all_of(sigma.begin(), sigma.end(), [](double x) { return std::isfinite(x); }) ? "" : fit.no_sigma;
    n.result.simulations += fit.simulations;
    at += k;
  }
  return point;
}

// A named candidate the others make needless — the model without it, refitted, is not decisively
// worse on the whole record (ΔBIC < decisive_bic) — is dropped (the first one named is not kept
// just because it came first).  Returns the name dropped, or "".
std::string replace_needless(Search& s) {
  if (s.named.size() < 2) return "";
  const int k = s.parameters();
  const double bic_all = s.scores.bic(k);
  for (std::size_t i = 0; i < s.named.size(); ++i) {
    std::vector<Named> others = s.named;
    others.erase(others.begin() + static_cast<std::ptrdiff_t>(i));
    const auto point = joint_refit(s, others);
    if (!point) continue;
    const auto traces = s.simulator.traces(*point, s.o.size());
    if (!traces) continue;
    const Scores without = score(s.o, *traces);
    if (without.bic(k - static_cast<int>(s.named[i].candidate.ranges.size())) - bic_all < s.options.decisive_bic) {
      const std::string dropped = s.named[i].result.effect;
      s.named = std::move(others);
      s.current = *point;
      s.scores = without;
      return dropped;
    }
  }
  return "";
}

// Names a trial: refitted on the whole record from its fit (its uncertainty), added.
void name_trial(Search& s, const Trial& t) {
  const Fit whole = fit_candidate(s.simulator, s.o, s.current, t.candidate, true, &t.fit.u);
  Named n{t.result, t.candidate};
  ModelPoint point = t.point;
  n.result.no_sigma = "its fit on the whole record failed (the fit on the first part has no covariance)";
  if (whole.ok) {
    point = t.candidate.apply(s.current, whole.values);
    n.result.parameters = reported(t.candidate, whole.values, whole.uncertainty, point);
    n.result.no_sigma = whole.no_sigma;
    n.result.simulations += whole.simulations;
  }
  s.named.push_back(n);
  s.current = point;
}

// Names a decisive pair: each part with its slice of the pair's fit.
void name_pair(Search& s, const Trial& pair, const std::vector<Trial>& singles) {
  std::size_t at = 0;
  for (const std::string& part : {pair.result.effect.substr(0, pair.result.effect.find(" + ")),
                                  pair.result.effect.substr(pair.result.effect.find(" + ") + 3)}) {
    const auto single = std::find_if(singles.begin(), singles.end(), [&](const Trial& t) { return t.result.effect == part; });
    Named n{single->result, single->candidate};
    const std::size_t k = single->candidate.ranges.size();
    n.result.parameters = reported(n.candidate, std::vector<double>(pair.fit.values.begin() + at, pair.fit.values.begin() + at + k),
                                   {}, pair.point);
    n.result.delta_bic = pair.result.delta_bic;
    n.result.decisive = true;
    n.result.no_sigma = "the pair's refit on the whole record failed (its fit on the first part has no covariance)";
    s.named.push_back(n);
    at += k;
  }
  s.current = pair.point;
}

// The current model's residual still above the noise level (its Huber RMS: docs/discrepancy.md).
bool above_noise(const Search& s) { return s.scores.robust_rms() > at_noise_level(s.o, s.options.noise_level); }

// The model of everything named but the i-th, at the named values (not refitted), and the
// directions in which those others move the residual (directions()).
std::pair<ModelPoint, Eigen::MatrixXd> without(Search& s, std::size_t i) {
  std::vector<EffectCandidate> parts;
  std::vector<double> u;
  for (std::size_t j = 0; j < s.named.size(); ++j) {
    if (j == i) continue;
    parts.push_back(s.named[j].candidate);
    for (std::size_t k = 0; k < s.named[j].candidate.ranges.size(); ++k)
      u.push_back(coordinate_of(s.named[j].candidate, s.named[j].result.parameters, k, s.base));
  }
  if (parts.empty()) return {s.base, Eigen::MatrixXd()};
  const EffectCandidate others = combined(parts);
  std::vector<double> values;
  for (std::size_t k = 0; k < u.size(); ++k) values.push_back(others.ranges[k].value(u[k]));
  return {others.apply(s.base, values), directions(s, others, s.base, u)};
}

// The named candidates with the i-th replaced by the parameter `name` (from u), refitted together.
std::optional<std::pair<std::vector<Named>, ModelPoint>> swapped_for(Search& s, std::size_t i, const std::string& name, double u) {
  std::vector<Named> swapped = s.named;
  Named& y = swapped[i];
  y.candidate = candidate_for(name, s.base, s.step);
  y.result = Candidate{};
  y.result.effect = name;
  y.result.parameters = {{y.candidate.ranges[0].name, y.candidate.ranges[0].value(u), NAN}};
  const auto point = joint_refit(s, swapped);
  if (!point) return std::nullopt;
  return std::make_pair(std::move(swapped), *point);
}

/// The parameters tried in a named correction's place (the best of their scans).
constexpr std::size_t kSwaps = 2;

// A named parameter correction swapped for another (docs/discrepancy.md, "The search"): K and
// motor.J both move the servo's frequency, and beside a delay fitted from a biased start K can be
// named where motor.J is wrong (ΔBIC −15638, 5.9σ left).  Every other parameter is scanned with
// the correction taken out (the rest named moving with it, to first order), the best kSwaps are
// refitted with everything else named; the best replaces the correction when decisively better
// and the model then meets the record at the noise level; within ambiguity_bic the two are alike
// (the status ambiguous).  Returns the parameter named in its place, or "".
std::string swap_correction(Search& s, const std::vector<std::string>& remaining) {
  const int k = s.parameters();
  for (std::size_t i = 0; i < s.named.size(); ++i) {
    if (!is_parameter_correction(s.named[i].result.effect) || s.named[i].candidate.ranges.size() != 1) continue;
    const auto [at, moving] = without(s, i);
    std::vector<std::pair<double, std::pair<std::string, double>>> ranked;
    for (const std::string& name : remaining) {
      if (!is_parameter_correction(name) || name == "backlash_size" || s.simulator.budget_reached()) continue;
      try {
        std::vector<double> u;
        const double sse = best_scan_point(s, candidate_for(name, at, s.step), at, moving, u);
        if (std::isfinite(sse)) ranked.push_back({sse, {name, u[0]}});
      } catch (const std::exception&) {  // a parameter at 0 is no candidate
      }
    }
    std::sort(ranked.begin(), ranked.end());
    for (std::size_t r = 0; r < std::min(kSwaps, ranked.size()); ++r) {
      const std::string& name = ranked[r].second.first;
      auto swapped = swapped_for(s, i, name, ranked[r].second.second);
      const auto traces = swapped ? s.simulator.traces(swapped->second, s.o.size()) : nullptr;
      if (!traces) continue;
      const Scores scores = score(s.o, *traces);
      const double delta = scores.bic(k) - s.scores.bic(k);
      Candidate& y = swapped->first[i].result;
      if (std::fabs(delta) < s.options.ambiguity_bic) {
        if (s.alike.empty()) s.alike.push_back(s.named[i].result);
        s.alike.push_back(y);
        if (s.experiment.empty()) s.experiment = experiment_between(s.named[i].result.effect, name);
      }
      // Only a swap that closes the gap: a greedy swap that merely improves can block the round
      // that would have dropped the correction as needless (a backlash change named beside
      // Coulomb friction on the load, where a torque offset is missing, swapped for the reference).
      if (delta >= -s.options.decisive_bic || scores.robust_rms() > at_noise_level(s.o, s.options.noise_level)) continue;
      y.decisive = true, y.delta_bic = delta;
      s.named = std::move(swapped->first);
      s.current = swapped->second;
      s.scores = scores;
      return name;
    }
  }
  return "";
}

/// The Stribeck scan of a refinement: cell centres of 3 ratios Ts/Tk × 3 Stribeck velocities.
constexpr int kRefineCells = 3;

// The start of stribeck_<body> refining the i-th named (coulomb_<body>): the named Coulomb level as
// the kinetic one, the best of the scan's ratios and velocities with the rest named at their
// values (moving with it, to first order); its parameters as reported, or empty.
std::vector<Parameter> refinement_start(Search& s, std::size_t i, const EffectCandidate& c) {
  const auto [at, moving] = without(s, i);
  const ParameterRange& kinetic = c.ranges[1];
  const double level = s.named[i].result.parameters.front().value;
  const double u1 = std::clamp(kinetic.logarithmic ? std::log(level / kinetic.low) / std::log(kinetic.high / kinetic.low)
                                                   : (level - kinetic.low) / (kinetic.high - kinetic.low), 0.0, 1.0);
  double best = INFINITY;
  std::vector<Parameter> start;
  for (int a = 0; a < kRefineCells; ++a)
    for (int b = 0; b < kRefineCells; ++b) {
      const std::vector<double> values{c.ranges[0].value((a + 0.5) / kRefineCells), kinetic.value(u1),
                                       c.ranges[2].value((b + 0.5) / kRefineCells)};
      const auto traces = s.simulator.traces(c.apply(at, values), s.o.size(), nullptr, nullptr, Simulator::Grid::fitted);
      if (!traces) continue;
      std::vector<double> r = residuals(s.o, *traces, s.o.fit_indices);
      double sse = sum_of_squares(r);
      if (moving.cols() > 0 && static_cast<std::size_t>(moving.rows()) == r.size())
        sse -= (moving.transpose() * Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()))).squaredNorm();
      if (sse < best)
        best = sse, start = {{c.ranges[0].name, values[0] * values[1], NAN}, {kinetic.name, values[1], NAN}, {c.ranges[2].name, values[2], NAN}};
    }
  return start;
}

// Friction refined (docs/discrepancy.md, "Stribeck friction"): Stribeck friction contains Coulomb
// friction (Ts = Tk), so it is no candidate of a round.  Where coulomb_<body> is named and the
// model still leaves a gap above the noise, stribeck_<body> (in `refinements`) replaces it, from
// refinement_start, refitted with everything named on the whole record, and is kept when decisive
// by a round's rule: ΔBIC < −decisive_bic with its two more parameters, the held-out samples
// confirming (holdout_confirms), no parameter at an end of its range.  Each body is tried once;
// the attempt is listed last in `round`.  Returns whether Stribeck friction was named.
bool refine_friction(Search& s, std::vector<std::string>& refinements, std::vector<Candidate>& round) {
  for (std::size_t i = 0; i < s.named.size() && !s.simulator.budget_reached(); ++i) {
    const std::string& coulomb = s.named[i].result.effect;
    if (coulomb.rfind("coulomb_", 0) != 0) continue;
    const std::string name = "stribeck_" + coulomb.substr(std::string("coulomb_").size());
    const auto found = std::find(refinements.begin(), refinements.end(), name);
    if (found == refinements.end()) continue;
    refinements.erase(found);
    std::vector<Named> refined = s.named;
    Named& y = refined[i];
    y.candidate = candidate_for(name, s.base, s.step);
    y.result = Candidate{};
    y.result.effect = name;
    Candidate& r = refined[i].result;
    std::optional<ModelPoint> point;
    Simulator::Traces traces;
    if (s.current.e.delay > 0) r.failure = "refining " + coulomb + ": the delayed model has no Stribeck friction";
    else try {
        r.parameters = refinement_start(s, i, y.candidate);
        if (!r.parameters.empty()) point = joint_refit(s, refined);
        if (point) traces = s.simulator.traces(*point, s.o.size());
      } catch (const std::exception& error) {  // a model that cannot be simulated: not refined
        r.failure = "refining " + coulomb + ": " + error.what();
      }
    if (!traces) {
      if (r.failure.empty()) r.failure = "refining " + coulomb + ": its refit with everything named failed";
      r.bic = r.rms = r.rms_holdout = INFINITY;
      round.push_back(r);
      continue;
    }
    const Scores sc = score(s.o, *traces);
    const int k = s.parameters();
    r.rms = sc.rms_theta_out, r.rms_fit = sc.rms_fit(), r.rms_holdout = sc.rms_holdout();
    r.bic = sc.bic(k - static_cast<int>(s.named[i].candidate.ranges.size()) + static_cast<int>(r.parameters.size()));
    r.delta_bic = r.bic - s.scores.bic(k);
    for (std::size_t j = 0; j < r.parameters.size(); ++j) {
      const double u = coordinate_of(refined[i].candidate, r.parameters, j, s.base);
      r.at_range_edge = r.at_range_edge || u < 1e-3 || u > 1 - 1e-3;
    }
    r.decisive = r.delta_bic < -s.options.decisive_bic && holdout_confirms(s, sc) && !r.at_range_edge;
    round.push_back(r);
    if (!r.decisive) continue;
    s.named = std::move(refined);
    s.current = *point;
    s.scores = sc;
    return true;
  }
  return false;
}

}  // namespace

void fit_free_parameters(Search& s, const std::vector<std::string>& free) {
  if (free.empty()) return;
  std::vector<Named> named;
  std::vector<EffectCandidate> parts;
  for (const std::string& key : free) {
    Named n;
    n.candidate = candidate_for(key, s.base, s.step);  // a parameter at 0 is refused here
    n.result.effect = key;
    named.push_back(n);
    parts.push_back(n.candidate);
  }
  // One or two: the scan and the growing horizons, as for a candidate; more: from the nominal values.
  const EffectCandidate joint = combined(parts);
  std::vector<double> start;
  for (const Named& n : named) {
    const ParameterRange& r = n.candidate.ranges[0];
    const double v = nominal_value(n.result.effect, s.base.p);
    start.push_back(r.logarithmic ? std::log(v / r.low) / std::log(r.high / r.low) : (v - r.low) / (r.high - r.low));
  }
  const auto traces0 = s.simulator.traces(s.base, s.o.size());
  const double departure = traces0 ? first_departure(s.o, (*traces0)[0]) : NAN;
  const Fit fit = fit_candidate(s.simulator, s.o, s.base, joint, true, free.size() <= 2 ? nullptr : &start,
                                std::numeric_limits<long>::max(), departure);
  if (!fit.ok) return;
  const ModelPoint point = joint.apply(s.base, fit.values);
  const auto traces = s.simulator.traces(point, s.o.size());
  if (!traces) return;
  const Scores fitted = score(s.o, *traces);
  const double delta = fitted.bic(static_cast<int>(free.size())) - s.scores.bic(0);
  if (!(delta < -s.options.decisive_bic)) return;
  for (std::size_t i = 0; i < named.size(); ++i) {
    named[i].result.parameters = {{named[i].candidate.ranges[0].name, fit.values[i], fit.uncertainty[i]}};
    named[i].result.delta_bic = delta, named[i].result.decisive = true;
  }
  s.named = std::move(named);
  s.current = point;
  s.scores = fitted;
}

void run_search(Search& s, std::vector<std::string> remaining) {
  auto erase = [&](const std::string& name) { remaining.erase(std::remove(remaining.begin(), remaining.end(), name), remaining.end()); };
  for (const Named& n : s.named) erase(n.result.effect);
  // Stribeck friction refines a named Coulomb friction (refine_friction), never a round's candidate.
  std::vector<std::string> refinements;
  std::copy_if(remaining.begin(), remaining.end(), std::back_inserter(refinements),
               [](const std::string& name) { return name.rfind("stribeck_", 0) == 0; });
  for (const std::string& name : refinements) erase(name);
  auto go_on = [&](int round) {
    return round < s.options.max_effects + 2 && above_noise(s) &&
           static_cast<int>(s.named.size()) < s.options.max_effects && !remaining.empty() && !s.simulator.budget_reached();
  };
  for (int rounds = 0; go_on(rounds); ++rounds) {
    const auto current_traces = s.simulator.traces(s.current, s.o.size());
    const double departure = current_traces ? first_departure(s.o, (*current_traces)[0]) : NAN;
    const std::vector<Trial> trials = round_of(s, departure, remaining);
    std::vector<Candidate> round;
    for (const Trial& t : trials) round.push_back(t.result);
    const std::size_t before = s.named.size();
    // Pairs where no single candidate is decisive or the best one leaves a gap above the noise;
    // a pair replaces the best single one when decisively better (ΔBIC < −decisive_bic between them).
    const Trial* winner = choose(trials, s);
    std::optional<Trial> pair;
    if (static_cast<int>(s.named.size()) + 2 <= s.options.max_effects &&
        (!winner || winner->result.rms_fit > at_noise_level(s.o, s.options.noise_level)))
      pair = best_pair(s, trials, departure, round);
    if (pair && (!winner || pair->result.bic < winner->result.bic - s.options.decisive_bic)) {
      name_pair(s, *pair, trials);
    } else if (winner) {
      record_alike(trials, winner, s);
      name_trial(s, *winner);
    }
    s.rounds.push_back(round);
    if (s.named.size() == before) break;
    for (std::size_t i = before; i < s.named.size(); ++i) erase(s.named[i].result.effect);
    if (s.named.size() > 1)
      if (const auto point = joint_refit(s, s.named)) s.current = *point;
    if (!s.rescore()) break;
    replace_needless(s);  // a dropped candidate is not tried again
    if (above_noise(s)) erase(swap_correction(s, remaining));
    if (above_noise(s) && refine_friction(s, refinements, s.rounds.back())) replace_needless(s);
    // The noise re-read from what the model now leaves: a large gap hides the noise's colour.
    if (const auto traces = s.simulator.traces(s.current, s.o.size())) {
      reestimate_noise(s.o, *traces);
      s.rescore();
    }
  }
}

}  // namespace backlash::discrepancy::detail
