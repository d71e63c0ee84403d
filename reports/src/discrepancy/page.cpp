// The results of the discrepancy workflow as files: the JSON, a Markdown page and
// its figures (SVG drawn by gnuplot through reports/plot.hpp, in memory; the same result
// gives the same bytes), and the corrected case file.
#include "backlash/reports/discrepancy_pages.hpp"

#include "page_json.hpp"
#include "plots.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
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

// ------------------------------------------------------------------ JSON

using detail::effects_json;
using detail::json_number;
using detail::rounds_json;

nlohmann::json features_json(const Features& f) {
  return {{"overshoot", json_number(f.overshoot)},           {"final_error", json_number(f.final_error)},
          {"decay_rate", json_number(f.decay_rate)},         {"cycle_amplitude", json_number(f.cycle_amplitude)},
          {"cycle_period", json_number(f.cycle_period)}};
}

nlohmann::json events_json(const std::vector<numeric::SimulationEvent>& events) {
  nlohmann::json out = nlohmann::json::array();
  for (const numeric::SimulationEvent& e : events) out.push_back({{"t", e.t}, {"kind", numeric::to_string(e.kind)}});
  return out;
}

nlohmann::json noise_json(const NoiseEstimate& n, const std::vector<Outlier>& outliers) {
  nlohmann::json spikes = nlohmann::json::array();
  for (const Outlier& o : outliers) spikes.push_back({{"index", o.index}, {"t", o.t}, {"column", o.column}, {"size", o.size}});
  return {{"sigma", n.sigma},         {"white_sigma", n.white_sigma}, {"correlation", n.correlation},
          {"tau_int", n.tau_int},     {"n_eff", n.n_eff},             {"at_noise", n.at_noise},
          {"outliers", spikes}};
}

/// What a nominal parameter is, for a sentence ("the load's inertia").
std::string parameter_words(const std::string& key) {
  if (key == "motor.J") return "the motor's inertia";
  if (key == "motor.F") return "the motor's viscous friction";
  if (key == "load.J") return "the load's inertia";
  if (key == "load.F") return "the load's viscous friction";
  if (key == "K") return "the loop gain K";
  if (key == "reference") return "the reference";
  return "the backlash";
}

/// The page's sentence on a correction: "the load's inertia is 15 % higher than the model says".
std::string correction_sentence(const ParameterCorrection& c) {
  std::ostringstream out;
  if (!std::isfinite(c.ratio)) {
    out << parameter_words(c.key) << " is " << number(c.fitted) << " where the model says " << number(c.nominal);
    return out.str();
  }
  const double percent = std::round(std::fabs(c.ratio - 1) * 1000) / 10;
  out << parameter_words(c.key) << " is " << number(percent) << " % " << (c.ratio >= 1 ? "higher" : "lower")
      << " than the model says (" << number(c.nominal) << " → " << number(c.fitted) << " ± " << number(c.uncertainty) << ")";
  return out.str();
}

/// What the status says, in a sentence.
std::string status_sentence(const DiscrepancyResult& r) {
  switch (r.status) {
    case Status::EffectFound: return "The effects named close the gap to the noise level.";
    case Status::ParametersCorrected:
      return "Corrections of nominal parameters alone close the gap to the noise level: no effect is missing.";
    case Status::PartlyExplained:
      return "What is named does not close the gap: the corrected model still leaves the noise band" +
             (std::isfinite(r.remaining_departure) ? " from t = " + number(r.remaining_departure) + " s" : std::string()) +
             " (the regions below say where).";
    case Status::Ambiguous:
      return "Two explanations fit the record alike; the experiment that would tell them apart: " +
             r.distinguishing_experiment + ".";
    case Status::NoDiscrepancy: return "The nominal model already meets the record at the noise level.";
    case Status::Unexplained: return "No candidate closes the gap decisively.";
  }
  return "";
}

}  // namespace

std::string to_json(const model::CaseSpec& model, const DiscrepancyResult& r, double step) {
  const detail::RoundsJson rounds = rounds_json(r.rounds, "simulations");
  const nlohmann::json effects = effects_json(r.effects);
  nlohmann::json regions = nlohmann::json::array();
  for (const Region& g : r.regions)
    regions.push_back({{"t_start", g.t_start},
                       {"t_end", g.t_end},
                       {"kind", g.kind},
                       {"samples", g.samples},
                       {"rms", g.rms_before},
                       {"rms_after", g.rms_after}});
  const bool found = !r.effects.empty();
  nlohmann::json out{{"model", model.source.string()},
                     {"step", step},
                     {"status", to_string(r.status)},
                     {"effect", found ? nlohmann::json(r.effects.front().effect) : nlohmann::json(nullptr)},
                     {"parameters", found ? detail::parameter_values_json(r.effects.front().parameters) : nlohmann::json(nullptr)},
                     {"effects", effects},
                     {"rms_before", r.rms_before},
                     {"rms_after", r.rms_after},
                     {"noise", r.noise},
                     {"gap_before", r.gap_before},
                     {"gap_after", r.gap_after},
                     {"first_departure", json_number(r.first_departure)},
                     {"candidates", rounds.candidates},
                     {"rounds", rounds.rounds},
                     {"regions", regions},
                     {"features",
                      {{"measured", features_json(r.measured)},
                       {"nominal", features_json(r.nominal)},
                       {"corrected", features_json(r.corrected)}}},
                     {"events", {{"nominal", events_json(r.nominal_events)}, {"corrected", events_json(r.corrected_events)}}},
                     {"simulations", r.simulations},
                     {"parameter_corrections", detail::corrections_json(r.parameter_corrections)},
                     {"noise_model", noise_json(r.noise_estimate, r.outliers)},
                     {"alternatives", effects_json(r.alternatives)},
                     {"distinguishing_experiment",
                      r.distinguishing_experiment.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.distinguishing_experiment)},
                     {"remaining_departure", json_number(r.remaining_departure)},
                     {"reason", r.reason.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.reason)}};
  return out.dump(2) + "\n";
}

namespace {

// The noise as read from the residual, and the spikes given no weight.
std::string noise_section(const DiscrepancyResult& r) {
  std::ostringstream md;
  const NoiseEstimate& n = r.noise_estimate;
  md << "Noise of θo read from the residual: σ = " << number(n.sigma) << " rad";
  if (n.correlation > 0)
    md << ", correlated (AR(1), a = " << number(n.correlation) << " per sample, τ_int = " << number(n.tau_int)
       << " samples; the white-noise rule alone says " << number(n.white_sigma) << ")";
  else
    md << ", white";
  md << "; the BIC counts n_eff = " << number(n.n_eff) << " residuals; at the noise level means RMS ≤ " << number(n.at_noise)
     << " σ.\n\n";
  if (!r.outliers.empty()) {
    md << "**Outliers** (isolated spikes, given no weight): " << r.outliers.size() << ".\n\n| t [s] | column | size [σ] |\n|---|---|---|\n";
    for (const Outlier& o : r.outliers) md << "| " << number(o.t) << " | " << o.column << " | " << number(o.size) << " |\n";
    md << "\n";
  }
  return md.str();
}

// The nominal parameters the record corrects, in words and as a table.
std::string corrections_section(const DiscrepancyResult& r) {
  if (r.parameter_corrections.empty()) return "";
  std::ostringstream md;
  md << "## Nominal parameters corrected\n\n";
  for (const ParameterCorrection& c : r.parameter_corrections)
    md << "- " << correction_sentence(c) << (c.given_free ? " — listed in [fit] free, fitted first" : "") << ".\n";
  md << "\n| parameter | nominal | fitted | ± (1σ) | ratio |\n|---|---|---|---|---|\n";
  for (const ParameterCorrection& c : r.parameter_corrections)
    md << "| " << c.key << " | " << number(c.nominal) << " | " << number(c.fitted) << " | " << number(c.uncertainty) << " | "
       << number(c.ratio) << " |\n";
  md << "\n";
  return md.str();
}

// Ambiguous: the explanations that fit alike.
std::string alternatives_section(const DiscrepancyResult& r) {
  if (r.alternatives.empty()) return "";
  std::ostringstream md;
  md << "## Explanations that fit alike\n\n| candidate | parameters | BIC | RMS held out (weighted) |\n|---|---|---|---|\n";
  for (const Candidate& c : r.alternatives) {
    md << "| " << c.effect << " | ";
    for (const Parameter& p : c.parameters) md << p.name << " = " << number(p.value) << " ";
    md << "| " << number(c.bic) << " | " << number(c.rms_holdout) << " |\n";
  }
  md << "\nThe first was adopted. To tell them apart: " << r.distinguishing_experiment << ".\n\n";
  return md.str();
}

// Every round's candidates.
std::string rounds_section(const DiscrepancyResult& r) {
  std::ostringstream md;
  md << "\n## Candidates\n\nEach effect added to the model and fitted on the first part of the record; scored by its BIC there "
        "and its RMS on the held-out rest. Decisive: ΔBIC < −10 and the held-out RMS reduced enough.\n\n";
  for (std::size_t k = 0; k < r.rounds.size(); ++k) {
    md << "### Round " << k + 1 << "\n\n| effect | parameters | RMS | RMS held out (weighted) | ΔBIC | decisive | simulations |\n"
       << "|---|---|---|---|---|---|---|\n";
    for (const Candidate& c : r.rounds[k]) {
      md << "| " << c.effect << " | ";
      for (const Parameter& p : c.parameters) md << p.name << " = " << number(p.value) << " ";
      md << "| " << number(c.rms) << " | " << number(c.rms_holdout) << " | " << number(c.delta_bic) << " | "
         << (c.decisive ? "yes" : "no") << " | " << c.simulations << " |\n";
    }
    md << "\n";
  }
  return md.str();
}

}  // namespace

std::vector<std::pair<std::string, std::string>> report_files(const model::CaseSpec& model, const std::string& data_name,
                                                              const DiscrepancyResult& r, double step) {
  std::vector<std::pair<std::string, std::string>> files;
  std::vector<double> residual_before(r.t.size()), residual_after(r.t.size());
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    residual_before[i] = r.theta_measured[i] - r.theta_nominal[i];
    residual_after[i] = r.theta_measured[i] - r.theta_corrected[i];
  }
  const bool found = !r.effects.empty() || !r.parameter_corrections.empty();
  std::vector<Curve> traces{{"measured", "#222", &r.t, &r.theta_measured}, {"nominal model", "#c33", &r.t, &r.theta_nominal, true}};
  if (found) traces.push_back({"corrected model", "#2a7", &r.t, &r.theta_corrected});
  std::vector<reports::Plot> figures;
  figures.push_back(line_plot("measured_vs_models", "Measured θo against the nominal and the corrected model", "t [s]", "θo [rad]", traces));
  std::vector<Band> bands;
  for (const Region& g : r.regions)
    if (g.kind == "free") bands.push_back({g.t_start, g.t_end, "#f0a030"});
  std::vector<Curve> residuals{{"nominal", "#c33", &r.t, &residual_before}};
  if (found) residuals.push_back({"corrected", "#2a7", &r.t, &residual_after});
  figures.push_back(line_plot("residual", "Residual θo(measured) − θo(model); shaded: free flight (nominal events)", "t [s]",
                              "residual [rad]", residuals, bands, {{3 * r.noise, "noise band ±3σ"}, {-3 * r.noise, ""}}));
  std::vector<std::pair<std::string, double>> bars;
  if (!r.rounds.empty())
    for (const Candidate& c : r.rounds.front()) bars.push_back({c.effect, c.rms});
  figures.push_back(bar_chart("candidates", "First round: RMS of θo with each candidate effect fitted", bars, r.rms_before,
                              "nominal " + number(r.rms_before)));
  const std::optional<std::string> not_drawn = add_figures(figures, files);
  files.push_back({"discrepancy.json", to_json(model, r, step)});
  files.push_back({"corrected.toml", corrected_case_file(model, r, step)});

  std::ostringstream md;
  md << "# Discrepancy: " << model.name << " against " << data_name << "\n\n";
  md << "**Status: `" << to_string(r.status) << "`.** Step " << number(step) << "; " << r.t.size() << " samples; noise of θo "
     << "estimated from the record: σ = " << number(r.noise) << " rad.\n\n";
  md << "| | RMS of θo [rad] | RMS / σ |\n|---|---|---|\n| nominal model | " << number(r.rms_before) << " | "
     << number(r.rms_before / r.noise) << " |\n| corrected model | " << number(r.rms_after) << " | "
     << number(r.rms_after / r.noise) << " |\n\n";
  md << status_sentence(r) << (r.reason.empty() ? "" : " The search stopped short: " + r.reason + ".") << "\n\n";
  md << noise_section(r);
  if (std::isfinite(r.first_departure))
    md << "The residual of the nominal model first leaves the noise band (|r| > 3σ on 5 samples) at t = "
       << number(r.first_departure) << " s.\n\n";
  else
    md << "The residual of the nominal model never leaves the noise band.\n\n";
  md << corrections_section(r);
  if (!r.effects.empty()) {
    md << "## Effects named\n\n| effect | parameter | value | ± (1σ) | ΔBIC |\n|---|---|---|---|---|\n";
    for (const Candidate& c : r.effects)
      for (const Parameter& p : c.parameters)
        md << "| " << c.effect << " | " << p.name << " | " << number(p.value) << " | "
           << (std::isfinite(p.uncertainty) ? number(p.uncertainty) : "— (" + (c.no_sigma.empty() ? "no covariance" : c.no_sigma) + ")")
           << " | " << number(c.delta_bic) << " |\n";
  }
  if (found) md << "\nThe corrected model: [corrected.toml](corrected.toml) (it loads and simulates as it is).\n\n";
  md << alternatives_section(r);
  if (!not_drawn) md << "![measured and models](measured_vs_models.svg)\n\n![residual](residual.svg)\n\n";
  md << "## Where they disagree\n\n| from [s] | to [s] | nominal mode | samples | RMS before | RMS after |\n|---|---|---|---|---|---|\n";
  for (const Region& g : r.regions)
    md << "| " << number(g.t_start) << " | " << number(g.t_end) << " | " << g.kind << " | " << g.samples << " | "
       << number(g.rms_before) << " | " << number(g.rms_after) << " |\n";
  md << "\n| feature | measured | nominal | corrected |\n|---|---|---|---|\n";
  auto feature = [&](const char* name, double Features::*field) {
    md << "| " << name << " | " << number(r.measured.*field) << " | " << number(r.nominal.*field) << " | "
       << number(r.corrected.*field) << " |\n";
  };
  feature("overshoot [rad]", &Features::overshoot);
  feature("final error [rad]", &Features::final_error);
  feature("decay rate [1/s]", &Features::decay_rate);
  feature("cycle amplitude [rad]", &Features::cycle_amplitude);
  feature("cycle period [s]", &Features::cycle_period);
  md << rounds_section(r);
  md << (not_drawn ? *not_drawn : std::string("![candidates](candidates.svg)")) << "\n";
  files.push_back({"discrepancy.md", md.str()});
  return files;
}

}  // namespace backlash::discrepancy
