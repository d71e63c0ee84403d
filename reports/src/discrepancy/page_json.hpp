// reports/src/discrepancy/page_json.hpp (internal) — the JSON pieces both result pages write
// (the step record's page.cpp and the measured drive's drive_page.cpp): numbers (NaN as
// null), a fit's parameters and their uncertainties, each candidate of each round, the
// effects named.  nlohmann::json sorts an object's keys, so the bytes depend only on
// the content.
#pragma once

#include "backlash/discrepancy/discrepancy.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace backlash::discrepancy::detail {

inline nlohmann::json json_number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

/// {name: value} of a fit's parameters.
inline nlohmann::json parameter_values_json(const std::vector<Parameter>& ps) {
  nlohmann::json out = nlohmann::json::object();
  for (const Parameter& p : ps) out[p.name] = json_number(p.value);
  return out;
}

/// {name: 1σ uncertainty} of a fit's parameters.
inline nlohmann::json parameter_sigmas_json(const std::vector<Parameter>& ps) {
  nlohmann::json out = nlohmann::json::object();
  for (const Parameter& p : ps) out[p.name] = json_number(p.uncertainty);
  return out;
}

/// One candidate's fit; `work_key` names its count of simulations ("simulations" on a
/// step record, "least_squares" on a measured drive).
/// "parameter_corrections": key, nominal, fitted, sigma, ratio, given_free (both pages).
inline nlohmann::json corrections_json(const std::vector<ParameterCorrection>& corrections) {
  nlohmann::json out = nlohmann::json::array();
  for (const ParameterCorrection& c : corrections)
    out.push_back({{"key", c.key},
                   {"nominal", c.nominal},
                   {"fitted", c.fitted},
                   {"sigma", json_number(c.uncertainty)},
                   {"ratio", json_number(c.ratio)},
                   {"given_free", c.given_free}});
  return out;
}

inline nlohmann::json candidate_json(const Candidate& c, const char* work_key) {
  return {{"effect", c.effect},
          {"parameters", parameter_values_json(c.parameters)},
          {"rms", json_number(c.rms)},
          {"rms_fit", json_number(c.rms_fit)},
          {"rms_holdout", json_number(c.rms_holdout)},
          {"bic", json_number(c.bic)},
          {"delta_bic", json_number(c.delta_bic)},
          {"score", json_number(c.delta_bic)},
          {"decisive", c.decisive},
          {"at_range_edge", c.at_range_edge},
          {work_key, c.simulations},
          {"failure", c.failure}};
}

/// Every round's candidates, and the first round's again as "candidates".
struct RoundsJson {
  nlohmann::json candidates = nlohmann::json::array(), rounds = nlohmann::json::array();
};
inline RoundsJson rounds_json(const std::vector<std::vector<Candidate>>& rounds, const char* work_key) {
  RoundsJson out;
  for (std::size_t k = 0; k < rounds.size(); ++k) {
    nlohmann::json round = nlohmann::json::array();
    for (const Candidate& c : rounds[k]) {
      round.push_back(candidate_json(c, work_key));
      if (k == 0) out.candidates.push_back(candidate_json(c, work_key));
    }
    out.rounds.push_back(round);
  }
  return out;
}

/// The effects named, with their parameters, uncertainties and ΔBIC.
inline nlohmann::json effects_json(const std::vector<Candidate>& effects) {
  nlohmann::json out = nlohmann::json::array();
  for (const Candidate& c : effects) {
    out.push_back({{"effect", c.effect},
                   {"parameters", parameter_values_json(c.parameters)},
                   {"uncertainty", parameter_sigmas_json(c.parameters)},
                   {"delta_bic", json_number(c.delta_bic)}});
    // A σ not reported (null) says why; the key is absent when every σ is a number.
    const bool all = std::all_of(c.parameters.begin(), c.parameters.end(), [](const Parameter& p) { return std::isfinite(p.uncertainty); });
    if (!all) out.back()["no_sigma"] = c.no_sigma.empty() ? std::string("no covariance") : c.no_sigma;
  }
  return out;
}

}  // namespace backlash::discrepancy::detail
