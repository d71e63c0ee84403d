// The measured-drive workflow's results as files: JSON, a Markdown page with its figures
// (SVG drawn by gnuplot through reports/plot.hpp, in memory), and the corrected case file.  No timings in the files: the same
// record gives the same bytes.
#include "backlash/reports/discrepancy_pages.hpp"

#include "page_json.hpp"
#include "plots.hpp"
#include "two_body_page.hpp"

#include "backlash/model/case_writer.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>
#include <sstream>

namespace backlash::discrepancy {

namespace {


using detail::Band;
using detail::Curve;
using detail::add_figures;
using detail::bar_chart;
using detail::line_plot;
using detail::number;

using detail::effects_json;
using detail::json_number;
using detail::parameter_values_json;
using detail::rounds_json;

nlohmann::json region_json(const TorqueRegion& g) {
  nlohmann::json out{{"kind", g.kind},         {"samples", g.samples},         {"rms", g.rms_before},
                     {"rms_after", g.rms_after}, {"mean", g.mean_before},       {"mean_after", g.mean_after}};
  if (std::isfinite(g.t_start)) out["t_start"] = g.t_start, out["t_end"] = g.t_end;
  return out;
}

nlohmann::json scores_json(const DriveScores& s) {
  return {{"record", s.record},
          {"samples", s.samples},
          {"torque_rms_nominal", s.torque_rms_nominal},
          {"torque_rms_corrected", s.torque_rms_corrected},
          {"position_rms_nominal", s.position_rms_nominal},
          {"position_rms_corrected", s.position_rms_corrected},
          {"windows", s.windows}};
}

nlohmann::json parameters_json(const numeric::Parameters& p) {
  return {{"motor.J", p.Jm}, {"motor.F", p.Fm}, {"load.J", p.JL}, {"load.F", p.FL}};
}


// The stretch of `count` windows that starts at the window with the largest error of `model`.
std::pair<std::size_t, std::size_t> worst_windows(const std::vector<double>& t, const std::vector<double>& measured,
                                                  const std::vector<double>& model, const std::vector<double>& starts,
                                                  int count) {
  if (starts.empty() || t.empty()) return {0, t.size()};
  std::size_t worst = 0;
  double worst_error = -1;
  std::size_t k = 0;
  for (std::size_t w = 0; w < starts.size(); ++w) {
    const double end = w + 1 < starts.size() ? starts[w + 1] : INFINITY;
    double e = 0;
    for (; k < t.size() && t[k] < end; ++k)
      if (std::isfinite(model[k])) e = std::max(e, std::fabs(measured[k] - model[k]));
    if (e > worst_error) worst_error = e, worst = w;
  }
  const std::size_t first_window = worst >= static_cast<std::size_t>(count / 2) ? worst - count / 2 : 0;
  const double from = starts[first_window];
  const double to = first_window + count < starts.size() ? starts[first_window + count] : INFINITY;
  const std::size_t a = static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), from) - t.begin());
  const std::size_t b = static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), to) - t.begin());
  return {a, std::min(b + 1, t.size())};
}

std::vector<double> slice(const std::vector<double>& v, std::pair<std::size_t, std::size_t> range) {
  return std::vector<double>(v.begin() + static_cast<std::ptrdiff_t>(range.first),
                             v.begin() + static_cast<std::ptrdiff_t>(range.second));
}

// The mean of y in equal bins of x (NaN in an empty bin).
std::pair<std::vector<double>, std::vector<double>> binned_mean(const std::vector<double>& x, const std::vector<double>& y,
                                                                int bins) {
  double lo = INFINITY, hi = -INFINITY;
  for (double v : x) lo = std::min(lo, v), hi = std::max(hi, v);
  std::vector<double> centre(bins), sum(bins, 0.0), count(bins, 0.0);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const int b = std::min(bins - 1, static_cast<int>((x[i] - lo) / (hi - lo) * bins));
    sum[b] += y[i];
    count[b] += 1;
  }
  for (int b = 0; b < bins; ++b) {
    centre[b] = lo + (b + 0.5) * (hi - lo) / bins;
    sum[b] = count[b] > 0 ? sum[b] / count[b] : NAN;
  }
  return {centre, sum};
}

}  // namespace

std::string drive_to_json(const model::CaseSpec& model, const DriveDiscrepancyResult& r) {
  const detail::RoundsJson rounds = rounds_json(r.rounds, "least_squares");
  const nlohmann::json effects = effects_json(r.effects);
  nlohmann::json regions = nlohmann::json::array(), classes = nlohmann::json::array();
  for (const TorqueRegion& g : r.stretches) regions.push_back(region_json(g));
  for (const TorqueRegion& g : r.classes) classes.push_back(region_json(g));
  nlohmann::json fitted = nlohmann::json::array(), refitted = nlohmann::json::array();
  for (const Parameter& p : r.nominal_fit) fitted.push_back({{"name", p.name}, {"value", p.value}, {"uncertainty", json_number(p.uncertainty)}});
  for (const Parameter& p : r.corrected_nominal)
    refitted.push_back({{"name", p.name}, {"value", p.value}, {"uncertainty", json_number(p.uncertainty)}});
  const bool found = !r.effects.empty();
  nlohmann::json out{
      {"model", model.source.string()},
      {"experiment", "drive"},
      {"status", to_string(r.status)},
      {"effect", found ? nlohmann::json(r.effects.front().effect) : nlohmann::json(nullptr)},
      {"parameters", found ? parameter_values_json(r.effects.front().parameters) : nlohmann::json(nullptr)},
      {"effects", effects},
      {"rms_before", r.rms_before},
      {"rms_after", r.rms_after},
      {"rms_unit", "torque (inverse dynamics)"},
      {"rms_given", r.rms_given},
      {"noise", r.noise},
      {"noise_sources", {{"position", r.position_noise}, {"drive", r.drive_noise}}},
      {"band",
       {{"sample_rate", r.sample_rate},
        {"cutoff", r.cutoff},
        {"cutoff_from_spectrum", r.cutoff_from_spectrum},
        {"spectrum_floor", json_number(r.spectrum_floor)},
        {"rest_speed", r.rest_speed}}},
      {"tau_int", {{"before", r.tau_int_before}, {"after", r.tau_int_after}}},
      {"nominal", {{"given", parameters_json(r.given)}, {"fitted", fitted}, {"parameters", parameters_json(r.nominal)}}},
      {"corrected", {{"parameters", parameters_json(r.parameters)}, {"refitted", refitted}, {"effects", r.corrected_effects.describe()}}},
      {"candidates", rounds.candidates},
      {"rounds", rounds.rounds},
      {"regions", regions},
      {"classes", classes},
      {"estimation", scores_json(r.estimation)},
      {"validation", r.validation ? scores_json(*r.validation) : nlohmann::json(nullptr)},
      {"least_squares", r.least_squares}};
  if (r.two_body) {  // a drive with a gap (two_body_drive.hpp)
    out["parameter_corrections"] = detail::corrections_json(r.two_body->parameter_corrections);
    out["two_body"] = detail::two_body_json(*r.two_body);
  }
  return out.dump(2) + "\n";
}

std::string drive_corrected_case_file(const model::CaseSpec& spec, const DriveDiscrepancyResult& r) {
  model::CaseFileText c;
  c.blank_line_before_tables = true;
  c.comments.push_back("The model of " + spec.source.filename().string() + " corrected by `backlash discrepancy` (measured drive).");
  auto comment = [&c](const std::string& head, const auto&... numbers) {  // numbers as a stream writes them
    std::ostringstream line;
    line << head;
    (line << ... << numbers);
    c.comments.push_back(line.str());
  };
  for (const Parameter& p : r.corrected_nominal) comment("  " + p.name + " = ", p.value, " ± ", p.uncertainty);
  for (const Candidate& candidate : r.effects)
    for (const Parameter& p : candidate.parameters)
      comment("  " + candidate.effect + ": " + p.name + " = ", p.value, " ± ", p.uncertainty);
  comment("Torque RMS of the inverse dynamics: ", r.rms_before, " (best nominal model) -> ", r.rms_after, ".");
  const numeric::Parameters& p = r.parameters;
  c.name = spec.name + " (corrected)";
  c.measured_at = spec.measured_at;
  c.K = model::exact_text(spec.K), c.reference = model::exact_text(spec.reference);
  c.backlash = r.two_body ? model::exact_or_decimal(spec.backlash, p.backlash) : "0";
  c.Jm = model::exact_or_decimal(spec.Jm, p.Jm), c.Fm = model::exact_or_decimal(spec.Fm, p.Fm);
  c.JL = model::exact_or_decimal(spec.JL, p.JL), c.FL = model::exact_or_decimal(spec.FL, p.FL);
  model::ExperimentText x{model::ExperimentKind::Drive, "", model::exact_text(spec.experiment->drive_gain), std::nullopt,
                         std::nullopt};
  if (spec.experiment->t_end) x.t_end = model::exact_text(*spec.experiment->t_end);
  c.experiment = x;
  c.fit_free = spec.fit_free;
  c.effects = model::fitted_effect_texts(spec.effects, r.corrected_effects);
  return model::write_case_file(c);
}

namespace {

// Drive torque over the samples `range`: measured, and what each model needs; returns the
// stretch's times (the position figure beside it shares them).
std::vector<double> torque_over_time(const DriveDiscrepancyResult& r, std::pair<std::size_t, std::size_t> range,
                                     const std::string& axis, std::vector<reports::Plot>& figures) {
  const std::vector<double> t = slice(r.t, range), measured = slice(r.torque_measured, range),
                            nominal = slice(r.torque_nominal, range), corrected = slice(r.torque_corrected, range);
  std::vector<Curve> torque{{"measured (filtered)", "#222", &t, &measured}, {"nominal needs", "#c33", &t, &nominal, true}};
  if (!r.effects.empty()) torque.push_back({"corrected needs", "#2a7", &t, &corrected});
  figures.push_back(line_plot("torque_over_time", "Drive torque: measured, and what each model needs along the measured motion",
                              "t [s]", axis, torque));
  return t;
}

// The first round's candidates: torque RMS with each fitted.
void candidates_chart(const DriveDiscrepancyResult& r, std::vector<reports::Plot>& figures) {
  std::vector<std::pair<std::string, double>> bars;
  if (!r.rounds.empty())
    for (const Candidate& c : r.rounds.front()) bars.push_back({c.effect, c.rms});
  figures.push_back(bar_chart("candidates", "First round: torque RMS with each candidate effect fitted", bars, r.rms_before,
                              "best nominal " + number(r.rms_before)));
}

// A drive with a gap: torque over the first three seconds, the lost motion, the hysteresis loop,
// the first round's candidates.
std::optional<std::string> two_body_drive_figures(const DriveDiscrepancyResult& r, std::vector<reports::Plot>& figures,
                                                  std::vector<std::pair<std::string, std::string>>& files) {
  const std::pair<std::size_t, std::size_t> range{0, static_cast<std::size_t>(std::lower_bound(r.t.begin(), r.t.end(), r.t.front() + 3) - r.t.begin())};
  // The corrected model drawn whether or not an effect was named (the parameter corrections
  // change it); its label says when it is the best nominal's own curve.
  const std::vector<double> t = slice(r.t, range), measured = slice(r.torque_measured, range),
                            nominal = slice(r.torque_nominal, range), corrected = slice(r.torque_corrected, range);
  const bool same = r.torque_corrected == r.torque_nominal;
  figures.push_back(line_plot("torque_over_time", "Drive torque: measured, and what each model needs along the measured motion",
                              "t [s]", "drive torque [N·m]",
                              {{"measured (filtered)", "#222", &t, &measured},
                               {"best nominal needs", "#c33", &t, &nominal, true},
                               {same ? "corrected needs (= the best nominal: no effect named)" : "corrected needs", "#2a7", &t, &corrected}}));
  figures.back().key = "below";
  detail::two_body_figures(*r.two_body, figures);
  candidates_chart(r, figures);
  return add_figures(figures, files);
}

// The figures: the torque residual against velocity, torque and position over the nominal
// model's worst windows (and the validation record's), the first round's candidates.  Drawn
// into `files`; returns the page's note when they could not be drawn.
std::optional<std::string> drive_figures(const DriveDiscrepancyResult& r, std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<reports::Plot> figures;
  const bool found = !r.effects.empty();
  // Torque residual against velocity: every sample's dot, and the mean in 60 velocity bins.
  std::vector<double> before(r.t.size()), after(r.t.size());
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    before[i] = r.torque_measured[i] - r.torque_nominal[i];
    after[i] = r.torque_measured[i] - r.torque_corrected[i];
  }
  const auto [vb, mean_before] = binned_mean(r.velocity, before, 60);
  const auto [va, mean_after] = binned_mean(r.velocity, after, 60);
  std::vector<Curve> scatter{{"nominal", "#d77", &r.velocity, &before, false, true},
                              {"nominal, mean", "#a11", &vb, &mean_before}};
  if (found) {
    scatter.push_back({"corrected", "#6b8", &r.velocity, &after, false, true});
    scatter.push_back({"corrected, mean", "#175", &va, &mean_after});
  }
  figures.push_back(line_plot("torque_residual_vs_velocity",
                              "Torque residual (measured drive − model's inverse dynamics) against velocity", "velocity [m/s]",
                              "force residual [N]", scatter, {}, {{0.0, "zero"}}));
  // Torque over time and position over windows: the stretch around the nominal model's worst window
  // (a drive with a gap: its own figures instead of the windows).
  if (r.two_body) return two_body_drive_figures(r, figures, files);
  const auto range = worst_windows(r.t, r.position, r.position_nominal, r.window_starts, 3);
  const std::vector<double> t = torque_over_time(r, range, "drive force [N]", figures);
  const std::vector<double> q = slice(r.position, range), qn = slice(r.position_nominal, range),
                            qc = slice(r.position_corrected, range);
  std::vector<Curve> position{{"measured", "#222", &t, &q}, {"nominal", "#c33", &t, &qn, true}};
  if (found) position.push_back({"corrected", "#2a7", &t, &qc});
  std::vector<Band> windows;
  for (std::size_t w = 0; w < r.window_starts.size(); w += 2)
    windows.push_back({r.window_starts[w], w + 1 < r.window_starts.size() ? r.window_starts[w + 1] : r.t.back(), "#9ab"});
  figures.push_back(line_plot("position_window",
                              "Position predicted over windows restarted from the measured state (shading: every other window)",
                              "t [s]", "position [m]", position, windows));
  if (r.validation) {
    const auto range_v = worst_windows(r.validation_t, r.validation_position, r.validation_nominal, r.validation_window_starts, 3);
    const std::vector<double> tv = slice(r.validation_t, range_v), qv = slice(r.validation_position, range_v),
                              qvn = slice(r.validation_nominal, range_v), qvc = slice(r.validation_corrected, range_v);
    std::vector<Curve> vp{{"measured", "#222", &tv, &qv}, {"nominal", "#c33", &tv, &qvn, true}};
    if (found) vp.push_back({"corrected", "#2a7", &tv, &qvc});
    figures.push_back(line_plot("validation_position_window", "Validation record (not fitted): position predicted over windows",
                                "t [s]", "position [m]", vp));
  }
  candidates_chart(r, figures);
  return add_figures(figures, files);
}

// The page's head: status, filter, noise.
void drive_page_head(std::ostringstream& md, const model::CaseSpec& model, const std::string& data_name,
                     const DriveDiscrepancyResult& r) {
  md << "# Discrepancy: " << model.name << " against " << data_name << " (measured drive)\n\n";
  md << "**Status: `" << to_string(r.status) << "`.** " << r.t.size() << " samples at " << number(r.sample_rate)
     << " Hz. The comparison is in the torque domain: the measured drive against the torque the model needs along the "
        "measured motion (inverse dynamics), both through the same zero-phase Butterworth low-pass (4th order, run forward "
        "and backward) with its cut-off at "
     << number(r.cutoff) << " Hz"
     << (r.cutoff_from_spectrum ? " — the highest frequency at which the position's spectrum stands 100× above its noise floor (" +
                                      number(r.spectrum_floor) + " position²/Hz)"
                                : " (set by the user)")
     << ".\n\n";
  if (r.two_body) {  // a drive with a gap: the sources named (docs/discrepancy.md, "Noise level on a drive with a gap")
    const TwoBodyNoise& n = r.two_body->noise;
    auto encoder = [](double step, double sigma) {
      return step > 0 ? "step " + number(step) + " → σ = step/√12 = " + number(sigma) : "not quantised, σ = " + number(sigma) + " (Δ⁴ rule)";
    };
    md << "Noise level of the torque residual: " << number(n.level) << ", the sources propagated through the filter, the "
       << "differences and the summed equation and added in quadrature — the motor encoder (" << encoder(n.step_motor, n.sigma_motor)
       << "): " << number(n.motor);
    if (r.two_body->load_encoder) md << "; the load encoder (" << encoder(n.step_load, n.sigma_load) << "): " << number(n.load);
    else md << " (carried with the two bodies' inertia: the observed load rides on the motor's counts)";
    md << "; the logged drive (σ = " << number(n.sigma_drive) << ", read on its band above the cut-off less the controller's "
       << "reaction to the encoders' counts): " << number(n.drive) << ". At rest: |velocity| < " << number(r.rest_speed) << ".\n\n";
  } else {
    md << "Noise: position σ = " << number(r.position_noise) << ", drive σ = " << number(r.drive_noise)
       << "; propagated through the filter and the derivatives, the torque residual's noise level is " << number(r.noise)
       << ". At rest: |velocity| < " << number(r.rest_speed) << ".\n\n";
  }
  md << "Units are the record's own (SI); the figures label them for a linear drive such as EMPS: position in m, velocity "
        "in m/s, the drive and its residual (the workflow's \"torque\") in N; for a rotary record read rad, rad/s and N·m.\n\n";
}

// The best nominal model's fitted parameters, and the effects named with their uncertainties.
void drive_page_fits(std::ostringstream& md, const DriveDiscrepancyResult& r) {
  const bool found = !r.effects.empty();
  if (!r.nominal_fit.empty()) {
    md << "## The best nominal model\n\nThe parameters the model file marks free are fitted first (torque domain, whole record):\n\n"
       << "| parameter | given | fitted | ± (1σ) |\n|---|---|---|---|\n";
    for (const Parameter& p : r.nominal_fit) {
      const double given = p.name == "motor.J" ? r.given.Jm : p.name == "load.J" ? r.given.JL : p.name == "motor.F" ? r.given.Fm : r.given.FL;
      md << "| " << p.name << " | " << number(given) << " | " << number(p.value) << " | " << number(p.uncertainty) << " |\n";
    }
    md << "\n";
  }
  if (found) {
    md << "## Effects named\n\n| effect | parameter | value | ± (1σ) | ΔBIC when named |\n|---|---|---|---|---|\n";
    for (const Candidate& c : r.effects)
      for (const Parameter& p : c.parameters)
        md << "| " << c.effect << " | " << p.name << " | " << number(p.value) << " | " << number(p.uncertainty) << " | "
           << number(c.delta_bic) << " |\n";
    for (const Parameter& p : r.corrected_nominal)
      md << "| (nominal) | " << p.name << " | " << number(p.value) << " | " << number(p.uncertainty) << " | |\n";
    md << "\nUncertainties: Ceres's covariance of the whole-record fit, scaled by the residual variance and by the residual's "
          "integrated autocorrelation time (τ_int = "
       << number(r.tau_int_after) << " samples: the filtered residuals are far from independent). The corrected model: "
       << "[corrected.toml](corrected.toml).\n\n";
  }
}

// The gap before and after, on the estimation and the validation record, with the figures.
void drive_page_gap(std::ostringstream& md, const std::string& data_name, const std::string& validation_name, bool drawn,
                    const DriveDiscrepancyResult& r) {
  md << "## The gap\n\n| record | torque RMS, best nominal | torque RMS, corrected | position RMS over " << r.estimation.windows
     << " windows, nominal | position RMS, corrected |\n|---|---|---|---|---|\n";
  auto row = [&](const DriveScores& s, const std::string& label) {
    md << "| " << label << " | " << number(s.torque_rms_nominal) << " | " << number(s.torque_rms_corrected) << " | "
       << number(s.position_rms_nominal) << " | " << number(s.position_rms_corrected) << " |\n";
  };
  row(r.estimation, data_name + " (estimation)");
  if (r.validation) row(*r.validation, validation_name + " (validation, not fitted)");
  md << "\nThe model as given in the file: torque RMS " << number(r.rms_given) << ".\n\n";
  if (!drawn) return;
  md << "![torque residual against velocity](torque_residual_vs_velocity.svg)\n\n![torque over time](torque_over_time.svg)\n\n"
     << "![position over windows](position_window.svg)\n\n";
  if (r.validation) md << "![validation record](validation_position_window.svg)\n\n";
}

// Where model and measurement disagree: by kind of motion, and the worst stretches.
void drive_page_regions(std::ostringstream& md, const DriveDiscrepancyResult& r) {
  md << "## Where they disagree\n\nThe torque residual by kind of motion (a mean of opposite signs forward and backward is the "
        "signature of Coulomb friction; one sign everywhere, that of an offset):\n\n"
     << "| samples of | count | RMS before | mean before | RMS after | mean after |\n|---|---|---|---|---|---|\n";
  for (const TorqueRegion& g : r.classes)
    md << "| " << g.kind << " | " << g.samples << " | " << number(g.rms_before) << " | " << number(g.mean_before) << " | "
       << number(g.rms_after) << " | " << number(g.mean_after) << " |\n";
  std::vector<TorqueRegion> worst = r.stretches;
  std::stable_sort(worst.begin(), worst.end(), [](const TorqueRegion& a, const TorqueRegion& b) { return a.rms_before > b.rms_before; });
  if (worst.size() > 10) worst.resize(10);
  md << "\nThe ten stretches between reversals with the largest residual before (all " << r.stretches.size()
     << " in discrepancy.json):\n\n| from [s] | to [s] | motion | samples | RMS before | RMS after |\n|---|---|---|---|---|---|\n";
  for (const TorqueRegion& g : worst)
    md << "| " << number(g.t_start) << " | " << number(g.t_end) << " | " << g.kind << " | " << g.samples << " | "
       << number(g.rms_before) << " | " << number(g.rms_after) << " |\n";
}

// Every round's candidates, and the first round's figure (or why the figures were not drawn).
void drive_page_candidates(std::ostringstream& md, const DriveDiscrepancyResult& r, const std::optional<std::string>& not_drawn) {
  md << "\n## Candidates\n\nEach effect added to the current model and fitted on seven of ten blocks of the record; ΔBIC with "
        "n_eff = n/τ_int independent residuals; decisive: ΔBIC < −10, the held-out RMS at most 0.8 of the current one, no "
        "parameter at an end of its range.\n\n";
  for (std::size_t k = 0; k < r.rounds.size(); ++k) {
    md << "### Round " << k + 1 << "\n\n| effect | parameter | torque RMS | RMS held out | ΔBIC | at range edge | decisive |\n"
       << "|---|---|---|---|---|---|---|\n";
    for (const Candidate& c : r.rounds[k]) {
      md << "| " << c.effect << " | ";
      for (const Parameter& p : c.parameters) md << p.name << " = " << number(p.value) << " ";
      // NaN: a candidate judged off the torque (a drive with a gap: on the gap's faces, the load's flights)
      auto rms = [](double v) { return std::isnan(v) ? std::string("— (judged on positions)") : number(v); };
      md << "| " << rms(c.rms) << " | " << rms(c.rms_holdout) << " | " << number(c.delta_bic) << " | "
         << (c.at_range_edge ? "yes" : "no") << " | " << (c.decisive ? "yes" : "no") << " |\n";
    }
    md << "\n";
  }
  md << (not_drawn ? *not_drawn : std::string("![candidates](candidates.svg)")) << "\n";
}

}  // namespace

std::vector<std::pair<std::string, std::string>> drive_report_files(const model::CaseSpec& model, const std::string& data_name,
                                                                    const std::string& validation_name,
                                                                    const DriveDiscrepancyResult& r) {
  std::vector<std::pair<std::string, std::string>> files;
  const std::optional<std::string> not_drawn = drive_figures(r, files);
  files.push_back({"discrepancy.json", drive_to_json(model, r)});
  files.push_back({"corrected.toml", drive_corrected_case_file(model, r)});
  std::ostringstream md;
  drive_page_head(md, model, data_name, r);
  drive_page_fits(md, r);
  if (r.two_body) {
    detail::two_body_page(md, *r.two_body, !not_drawn);
    md << "\nTorque RMS: " << number(r.rms_given) << " (the model as given), " << number(r.rms_before) << " (best nominal), "
       << number(r.rms_after) << " (corrected).\n\n" << (not_drawn ? "" : "![torque over time](torque_over_time.svg)\n\n");
  } else {
    drive_page_gap(md, data_name, validation_name, !not_drawn, r);
    drive_page_regions(md, r);
  }
  drive_page_candidates(md, r, not_drawn);
  files.push_back({"discrepancy.md", md.str()});
  return files;
}

}  // namespace backlash::discrepancy
