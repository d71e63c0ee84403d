// The results of the discrepancy workflow as files: the JSON, a Markdown page and
// its figures (SVG drawn here, deterministically: the same result gives the same
// bytes), and the corrected case file.
#include "internal.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace backlash::discrepancy {

namespace {

// ------------------------------------------------------------------ a small SVG line plot

struct Series {
  std::string name, color;
  const std::vector<double>* x;
  const std::vector<double>* y;
  bool dashed = false;
};

struct Band {
  double x0, x1;
  std::string color;
};

std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return buffer;
}

std::string escape_xml(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

// "Nice" tick values covering [lo, hi].
std::vector<double> ticks(double lo, double hi) {
  const double span = hi - lo, raw = span / 5, magnitude = std::pow(10, std::floor(std::log10(raw)));
  const double step = raw / magnitude < 1.5 ? magnitude : raw / magnitude < 3 ? 2 * magnitude : raw / magnitude < 7 ? 5 * magnitude : 10 * magnitude;
  std::vector<double> out;
  for (double v = std::ceil(lo / step) * step; v <= hi + 1e-9 * span; v += step) out.push_back(std::fabs(v) < 1e-12 * span ? 0 : v);
  return out;
}

std::string line_plot(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                      const std::vector<Series>& series, const std::vector<Band>& bands = {},
                      const std::vector<std::pair<double, std::string>>& hlines = {}) {
  constexpr double W = 900, H = 420, left = 80, right = 190, top = 40, bottom = 55;
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const Series& s : series)
    for (std::size_t i = 0; i < s.x->size(); ++i) {
      x0 = std::min(x0, (*s.x)[i]);
      x1 = std::max(x1, (*s.x)[i]);
      y0 = std::min(y0, (*s.y)[i]);
      y1 = std::max(y1, (*s.y)[i]);
    }
  for (const auto& [y, label] : hlines) y0 = std::min(y0, y), y1 = std::max(y1, y);
  if (!(x1 > x0)) x1 = x0 + 1;
  if (!(y1 > y0)) y1 = y0 + 1;
  const double pad = 0.05 * (y1 - y0);
  y0 -= pad;
  y1 += pad;
  auto X = [&](double x) { return left + (x - x0) / (x1 - x0) * (W - left - right); };
  auto Y = [&](double y) { return H - bottom - (y - y0) / (y1 - y0) * (H - top - bottom); };
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" viewBox=\"0 0 " << W << " " << H
      << "\" font-family=\"sans-serif\" font-size=\"13\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg << "<text x=\"" << W / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">" << escape_xml(title) << "</text>\n";
  for (const Band& b : bands)
    svg << "<rect x=\"" << number(X(std::max(b.x0, x0))) << "\" y=\"" << top << "\" width=\""
        << number(std::max(0.0, X(std::min(b.x1, x1)) - X(std::max(b.x0, x0)))) << "\" height=\"" << H - top - bottom
        << "\" fill=\"" << b.color << "\" fill-opacity=\"0.18\"/>\n";
  for (double t : ticks(x0, x1))
    svg << "<line x1=\"" << number(X(t)) << "\" y1=\"" << H - bottom << "\" x2=\"" << number(X(t)) << "\" y2=\"" << top
        << "\" stroke=\"#ddd\"/><text x=\"" << number(X(t)) << "\" y=\"" << H - bottom + 18 << "\" text-anchor=\"middle\">"
        << number(t) << "</text>\n";
  for (double t : ticks(y0, y1))
    svg << "<line x1=\"" << left << "\" y1=\"" << number(Y(t)) << "\" x2=\"" << W - right << "\" y2=\"" << number(Y(t))
        << "\" stroke=\"#ddd\"/><text x=\"" << left - 6 << "\" y=\"" << number(Y(t) + 4) << "\" text-anchor=\"end\">" << number(t)
        << "</text>\n";
  svg << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << W - left - right << "\" height=\"" << H - top - bottom
      << "\" fill=\"none\" stroke=\"black\"/>\n";
  svg << "<text x=\"" << (left + W - right) / 2 << "\" y=\"" << H - 12 << "\" text-anchor=\"middle\">" << escape_xml(xlabel)
      << "</text>\n<text transform=\"translate(18," << (top + H - bottom) / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
      << escape_xml(ylabel) << "</text>\n";
  for (const auto& [y, label] : hlines)
    svg << "<line x1=\"" << left << "\" y1=\"" << number(Y(y)) << "\" x2=\"" << W - right << "\" y2=\"" << number(Y(y))
        << "\" stroke=\"#888\" stroke-dasharray=\"2,3\"/>\n";
  int row = 0;
  for (const Series& s : series) {
    svg << "<polyline fill=\"none\" stroke=\"" << s.color << "\" stroke-width=\"1.4\""
        << (s.dashed ? " stroke-dasharray=\"6,4\"" : "") << " points=\"";
    const std::size_t n = s.x->size(), stride = std::max<std::size_t>(1, n / 3000);  // at most ~3000 points
    for (std::size_t i = 0; i < n; i += stride) svg << number(X((*s.x)[i])) << "," << number(Y((*s.y)[i])) << " ";
    svg << "\"/>\n";
    const double ly = top + 14 + 20 * row++;
    svg << "<line x1=\"" << W - right + 12 << "\" y1=\"" << ly << "\" x2=\"" << W - right + 38 << "\" y2=\"" << ly << "\" stroke=\""
        << s.color << "\" stroke-width=\"2\"" << (s.dashed ? " stroke-dasharray=\"6,4\"" : "") << "/><text x=\"" << W - right + 44
        << "\" y=\"" << ly + 4 << "\">" << escape_xml(s.name) << "</text>\n";
  }
  for (const auto& [y, label] : hlines) {
    const double ly = top + 14 + 20 * row++;
    svg << "<line x1=\"" << W - right + 12 << "\" y1=\"" << ly << "\" x2=\"" << W - right + 38 << "\" y2=\"" << ly
        << "\" stroke=\"#888\" stroke-dasharray=\"2,3\"/><text x=\"" << W - right + 44 << "\" y=\"" << ly + 4 << "\">"
        << escape_xml(label) << "</text>\n";
    break;  // one legend entry for the band's two lines
  }
  svg << "</svg>\n";
  return svg.str();
}

std::string bar_chart(const std::string& title, const std::vector<std::pair<std::string, double>>& bars, double reference,
                      const std::string& reference_label) {
  constexpr double W = 900, row = 28, left = 170, right = 120, top = 40;
  const double H = top + row * (bars.size() + 1) + 30;
  double hi = reference;
  for (const auto& [name, v] : bars)
    if (std::isfinite(v)) hi = std::max(hi, v);
  hi *= 1.05;
  auto X = [&](double v) { return left + v / hi * (W - left - right); };
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" viewBox=\"0 0 " << W << " " << H
      << "\" font-family=\"sans-serif\" font-size=\"13\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg << "<text x=\"" << W / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">" << escape_xml(title) << "</text>\n";
  for (std::size_t i = 0; i < bars.size(); ++i) {
    const double y = top + row * i;
    const double v = std::isfinite(bars[i].second) ? bars[i].second : 0;
    svg << "<text x=\"" << left - 8 << "\" y=\"" << y + 17 << "\" text-anchor=\"end\">" << escape_xml(bars[i].first)
        << "</text><rect x=\"" << left << "\" y=\"" << y + 4 << "\" width=\"" << number(X(v) - left) << "\" height=\"" << row - 8
        << "\" fill=\"#4a78b5\"/><text x=\"" << number(X(v) + 6) << "\" y=\"" << y + 17 << "\">"
        << (std::isfinite(bars[i].second) ? number(bars[i].second) : std::string("failed")) << "</text>\n";
  }
  const double y_end = top + row * bars.size();
  svg << "<line x1=\"" << number(X(reference)) << "\" y1=\"" << top << "\" x2=\"" << number(X(reference)) << "\" y2=\"" << y_end
      << "\" stroke=\"#c33\" stroke-dasharray=\"5,4\"/><text x=\"" << number(X(reference)) << "\" y=\"" << y_end + 18
      << "\" text-anchor=\"middle\" fill=\"#c33\">" << escape_xml(reference_label) << "</text>\n</svg>\n";
  return svg.str();
}

// ------------------------------------------------------------------ JSON

nlohmann::json json_number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json parameters_json(const std::vector<Parameter>& ps) {
  nlohmann::json out = nlohmann::json::object();
  for (const Parameter& p : ps) out[p.name] = json_number(p.value);
  return out;
}

nlohmann::json uncertainty_json(const std::vector<Parameter>& ps) {
  nlohmann::json out = nlohmann::json::object();
  for (const Parameter& p : ps) out[p.name] = json_number(p.uncertainty);
  return out;
}

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

}  // namespace

std::string to_json(const model::CaseSpec& model, const DiscrepancyResult& r, double step) {
  nlohmann::json candidates = nlohmann::json::array(), rounds = nlohmann::json::array();
  for (std::size_t k = 0; k < r.rounds.size(); ++k) {
    nlohmann::json round = nlohmann::json::array();
    for (const Candidate& c : r.rounds[k]) {
      nlohmann::json item{{"effect", c.effect},
                          {"parameters", parameters_json(c.parameters)},
                          {"rms", json_number(c.rms)},
                          {"rms_fit", json_number(c.rms_fit)},
                          {"rms_holdout", json_number(c.rms_holdout)},
                          {"bic", json_number(c.bic)},
                          {"delta_bic", json_number(c.delta_bic)},
                          {"score", json_number(c.delta_bic)},
                          {"decisive", c.decisive},
                          {"at_range_edge", c.at_range_edge},
                          {"simulations", c.simulations},
                          {"seconds", c.seconds}};
      round.push_back(item);
      if (k == 0) candidates.push_back(item);
    }
    rounds.push_back(round);
  }
  nlohmann::json effects = nlohmann::json::array();
  for (const Candidate& c : r.effects)
    effects.push_back({{"effect", c.effect},
                       {"parameters", parameters_json(c.parameters)},
                       {"uncertainty", uncertainty_json(c.parameters)},
                       {"delta_bic", json_number(c.delta_bic)}});
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
                     {"parameters", found ? parameters_json(r.effects.front().parameters) : nlohmann::json(nullptr)},
                     {"effects", effects},
                     {"rms_before", r.rms_before},
                     {"rms_after", r.rms_after},
                     {"noise", r.noise},
                     {"gap_before", r.gap_before},
                     {"gap_after", r.gap_after},
                     {"first_departure", json_number(r.first_departure)},
                     {"candidates", candidates},
                     {"rounds", rounds},
                     {"regions", regions},
                     {"features",
                      {{"measured", features_json(r.measured)},
                       {"nominal", features_json(r.nominal)},
                       {"corrected", features_json(r.corrected)}}},
                     {"events", {{"nominal", events_json(r.nominal_events)}, {"corrected", events_json(r.corrected_events)}}},
                     {"simulations", r.simulations},
                     {"seconds", r.seconds}};
  return out.dump(2) + "\n";
}

std::vector<std::pair<std::string, std::string>> report_files(const model::CaseSpec& model, const std::string& data_name,
                                                              const DiscrepancyResult& r, double step) {
  std::vector<std::pair<std::string, std::string>> files;
  std::vector<double> residual_before(r.t.size()), residual_after(r.t.size());
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    residual_before[i] = r.theta_measured[i] - r.theta_nominal[i];
    residual_after[i] = r.theta_measured[i] - r.theta_corrected[i];
  }
  const bool found = !r.effects.empty();
  std::vector<Series> traces{{"measured", "#222", &r.t, &r.theta_measured}, {"nominal model", "#c33", &r.t, &r.theta_nominal, true}};
  if (found) traces.push_back({"corrected model", "#2a7", &r.t, &r.theta_corrected});
  files.push_back({"measured_vs_models.svg",
                   line_plot("Measured θo against the nominal and the corrected model", "t [s]", "θo [rad]", traces)});
  std::vector<Band> bands;
  for (const Region& g : r.regions)
    if (g.kind == "free") bands.push_back({g.t_start, g.t_end, "#f0a030"});
  std::vector<Series> residuals{{"nominal", "#c33", &r.t, &residual_before}};
  if (found) residuals.push_back({"corrected", "#2a7", &r.t, &residual_after});
  files.push_back({"residual.svg", line_plot("Residual θo(measured) − θo(model); shaded: free flight (nominal events)", "t [s]",
                                             "residual [rad]", residuals, bands,
                                             {{3 * r.noise, "noise band ±3σ"}, {-3 * r.noise, ""}})});
  std::vector<std::pair<std::string, double>> bars;
  if (!r.rounds.empty())
    for (const Candidate& c : r.rounds.front()) bars.push_back({c.effect, c.rms});
  files.push_back({"candidates.svg", bar_chart("First round: RMS of θo with each candidate effect fitted", bars, r.rms_before,
                                               "nominal " + number(r.rms_before))});
  files.push_back({"discrepancy.json", to_json(model, r, step)});
  files.push_back({"corrected.toml", corrected_case_file(model, r, step)});

  std::ostringstream md;
  md << "# Discrepancy: " << model.name << " against " << data_name << "\n\n";
  md << "**Status: `" << to_string(r.status) << "`.** Step " << number(step) << "; " << r.t.size() << " samples; noise of θo "
     << "estimated from the record: σ = " << number(r.noise) << " rad.\n\n";
  md << "| | RMS of θo [rad] | RMS / σ |\n|---|---|---|\n| nominal model | " << number(r.rms_before) << " | "
     << number(r.rms_before / r.noise) << " |\n| corrected model | " << number(r.rms_after) << " | "
     << number(r.rms_after / r.noise) << " |\n\n";
  if (std::isfinite(r.first_departure))
    md << "The residual of the nominal model first leaves the noise band (|r| > 3σ on 5 samples) at t = "
       << number(r.first_departure) << " s.\n\n";
  else
    md << "The residual of the nominal model never leaves the noise band.\n\n";
  if (found) {
    md << "## Effects named\n\n| effect | parameter | value | ± (1σ) | ΔBIC |\n|---|---|---|---|---|\n";
    for (const Candidate& c : r.effects)
      for (const Parameter& p : c.parameters)
        md << "| " << c.effect << " | " << p.name << " | " << number(p.value) << " | " << number(p.uncertainty) << " | "
           << number(c.delta_bic) << " |\n";
    md << "\nThe corrected model: [corrected.toml](corrected.toml) (it loads and simulates as it is).\n\n";
  }
  md << "![measured and models](measured_vs_models.svg)\n\n![residual](residual.svg)\n\n";
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
  md << "\n## Candidates\n\nEach effect added to the model and fitted on the first part of the record; scored by its BIC there "
        "and its RMS on the held-out rest. Decisive: ΔBIC < −10 and the held-out RMS reduced enough.\n\n";
  for (std::size_t k = 0; k < r.rounds.size(); ++k) {
    md << "### Round " << k + 1 << "\n\n| effect | parameters | RMS | RMS held out (weighted) | ΔBIC | decisive | simulations | time [s] |\n"
       << "|---|---|---|---|---|---|---|---|\n";
    for (const Candidate& c : r.rounds[k]) {
      md << "| " << c.effect << " | ";
      for (const Parameter& p : c.parameters) md << p.name << " = " << number(p.value) << " ";
      md << "| " << number(c.rms) << " | " << number(c.rms_holdout) << " | " << number(c.delta_bic) << " | "
         << (c.decisive ? "yes" : "no") << " | " << c.simulations << " | " << number(c.seconds) << " |\n";
    }
    md << "\n";
  }
  md << "![candidates](candidates.svg)\n";
  files.push_back({"discrepancy.md", md.str()});
  return files;
}

}  // namespace backlash::discrepancy
