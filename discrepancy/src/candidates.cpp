// The effects the workflow can name, as things a fit can vary (docs/discrepancy.md):
// each effect's parameters and the range searched, scaled to the model — torques
// to the initial drive K·|step|, times to the servo period, the backlash to its
// nominal value — and the nominal parameters a record may correct, each a one-parameter
// candidate searched from half to twice its nominal value (the reference ±¼ of the step).
#include "internal.hpp"

#include "backlash/model/effect_table.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace backlash::discrepancy::detail {

double ParameterRange::value(double u) const {
  u = std::min(1.0, std::max(0.0, u));
  return logarithmic ? low * std::pow(high / low, u) : low + (high - low) * u;
}

double ParameterRange::derivative(double u) const {
  return logarithmic ? value(u) * std::log(high / low) : high - low;
}

std::vector<std::vector<double>> EffectCandidate::scan() const {
  std::vector<std::vector<double>> points;
  if (ranges.size() == 1) {
    constexpr int n = 40;  // fine: with many bounces or events the cost has many shallow valleys
    for (int i = 0; i < n; ++i) points.push_back({i / double(n - 1)});
  } else {
    constexpr int n0 = 7, n1 = 5;
    for (int i = 0; i < n0; ++i)
      for (int j = 0; j < n1; ++j) points.push_back({i / double(n0 - 1), j / double(n1 - 1)});
  }
  return points;
}

namespace {

/// The nominal backlash's candidate is tried after the effects of STEP_RANK below it.
constexpr int kBacklashSizeRank = 7;

/// The model's own scale of a candidate range (model::CandidateScale).
double scale_of(model::CandidateScale scale, const numeric::Parameters& p, double step) {
  switch (scale) {
    case model::CandidateScale::StepTorque: return p.K * std::fabs(step);  // the drive at the start of the step
    case model::CandidateScale::Gain: return p.K;
    case model::CandidateScale::ServoPeriod: return numeric::servo_period(p);
    case model::CandidateScale::StepVelocity: return std::fabs(step) / numeric::servo_period(p);
    case model::CandidateScale::Absolute:
    case model::CandidateScale::DampingRatio:
    case model::CandidateScale::KineticRatio: return 1;
  }
  return 1;
}

/// A parameter fitted relative to another of its effect (model::CandidateScale): the compliance's
/// damping from its ratio ζ = cc/(2√(kc·m)), m the reduced inertia, with kc the stiffness fitted
/// with it (the parameter before); Stribeck's static level from its ratio Ts/Tk ≥ 1 to the kinetic
/// level fitted with it (the parameter after) — so Ts ≥ Tk at every point a fit tries.
double relative_value(const model::EffectInfo& effect, std::size_t k, const std::vector<double>& v, double reduced_inertia) {
  const model::EffectParameterInfo& parameter = model::effect_parameters[effect.first + k];
  if (parameter.scale == model::CandidateScale::DampingRatio) return 2 * v[k] * std::sqrt(v[k - 1] * reduced_inertia);
  if (parameter.scale == model::CandidateScale::KineticRatio) return v[k] * v[k + 1];
  return v[k];
}

/// The candidate of an effect of the table: its parameters' ranges, scaled; applying it sets
/// them (relative_value) and, for a contact law, puts every other contact law back to its
/// neutral values.
EffectCandidate table_candidate(const model::EffectInfo& effect, const numeric::Parameters& p, double step) {
  EffectCandidate c;
  c.effect = std::string(effect.key);
  for (std::size_t i = effect.first; i < effect.first + effect.count; ++i) {
    const model::EffectParameterInfo& parameter = model::effect_parameters[i];
    const double s = scale_of(parameter.scale, p, step);
    c.ranges.push_back({std::string(parameter.fit_name), parameter.low * s, parameter.high * s, parameter.logarithmic});
  }
  const double reduced_inertia = p.Jm * p.JL / (p.Jm + p.JL);
  c.apply = [&effect, reduced_inertia](const ModelPoint& b, const std::vector<double>& v) {
    ModelPoint m = b;
    for (std::size_t k = 0; k < effect.count; ++k)
      model::field(m.e, model::effect_parameters[effect.first + k].id) = relative_value(effect, k, v, reduced_inertia);
    if (effect.contact_law)
      for (const model::EffectInfo& other : model::effects_table)
        if (&other != &effect && other.contact_law)
          for (std::size_t i = other.first; i < other.first + other.count; ++i)
            model::field(m.e, model::effect_parameters[i].id) = model::effect_parameters[i].neutral;
    return m;
  };
  return c;
}

}  // namespace

const std::vector<std::string>& names() {
  static const std::vector<std::string> all =
      model::ranked_effects(&model::EffectInfo::step_rank, {{kBacklashSizeRank, "backlash_size"}});
  return all;
}

namespace {

/// The field of the nominal parameters a parameter candidate corrects ("backlash_size": the backlash).
double numeric::Parameters::*parameter_field(const std::string& key) {
  if (key == "motor.J") return &numeric::Parameters::Jm;
  if (key == "motor.F") return &numeric::Parameters::Fm;
  if (key == "load.J") return &numeric::Parameters::JL;
  if (key == "load.F") return &numeric::Parameters::FL;
  if (key == "K") return &numeric::Parameters::K;
  if (key == "reference") return &numeric::Parameters::theta_R;
  if (key == "backlash_size" || key == "backlash") return &numeric::Parameters::backlash;
  return nullptr;
}

/// A nominal parameter as a candidate: from half to twice its value (geometric), the reference
/// within a quarter of the step of its value, the backlash from 0.05 to 4 times its value.
EffectCandidate parameter_candidate(const std::string& key, const numeric::Parameters& p, double step) {
  double numeric::Parameters::*field = parameter_field(key);
  EffectCandidate c;
  c.effect = key;
  const double nominal = p.*field;
  const std::string name = key == "backlash_size" ? "backlash" : key;
  if (key == "reference") {
    c.ranges = {ParameterRange{name, nominal - 0.25 * std::fabs(step), nominal + 0.25 * std::fabs(step), false}};
  } else if (key == "backlash_size") {
    c.ranges = {nominal > 0 ? ParameterRange{name, 0.05 * nominal, 4.0 * nominal, true}
                            : ParameterRange{name, 1e-3 * std::fabs(step), 0.5 * std::fabs(step), true}};
  } else {
    if (!(nominal > 0))
      throw std::invalid_argument(key + " is 0 in the model: a correction is searched as a ratio of its nominal value");
    c.ranges = {ParameterRange{name, 0.5 * nominal, 2.0 * nominal, true}};
  }
  c.apply = [field](const ModelPoint& b, const std::vector<double>& v) {
    ModelPoint m = b;
    m.p.*field = v[0];
    return m;
  };
  return c;
}

}  // namespace

EffectCandidate combined(const std::vector<EffectCandidate>& parts) {
  EffectCandidate joint;
  std::vector<std::size_t> sizes;
  for (const EffectCandidate& c : parts) {
    joint.effect += (joint.effect.empty() ? "" : " + ") + c.effect;
    joint.ranges.insert(joint.ranges.end(), c.ranges.begin(), c.ranges.end());
    sizes.push_back(c.ranges.size());
  }
  joint.apply = [parts, sizes](const ModelPoint& base, const std::vector<double>& values) {
    ModelPoint m = base;
    std::size_t at = 0;
    for (std::size_t i = 0; i < parts.size(); ++i) {
      m = parts[i].apply(m, std::vector<double>(values.begin() + at, values.begin() + at + sizes[i]));
      at += sizes[i];
    }
    return m;
  };
  return joint;
}

double nominal_value(const std::string& key, const numeric::Parameters& p) {
  double numeric::Parameters::*field = parameter_field(key);
  return field ? p.*field : NAN;
}

EffectCandidate candidate_for(const std::string& effect, const ModelPoint& base, double step) {
  const numeric::Parameters& p = base.p;
  if (const model::EffectInfo* row = model::effect_keyed(effect)) return table_candidate(*row, p, step);
  if (parameter_field(effect) == nullptr || effect == "backlash") throw std::invalid_argument("unknown candidate '" + effect + "'");
  return parameter_candidate(effect, p, step);
}

}  // namespace backlash::discrepancy::detail

namespace backlash::discrepancy {

const std::vector<std::string>& vocabulary() { return detail::names(); }

const std::vector<std::string>& parameter_candidates() {
  static const std::vector<std::string> keys{"motor.J", "motor.F", "load.J", "load.F", "K", "reference"};
  return keys;
}

bool is_parameter_correction(const std::string& candidate) {
  return candidate == "backlash_size" ||
         std::find(parameter_candidates().begin(), parameter_candidates().end(), candidate) != parameter_candidates().end();
}

}  // namespace backlash::discrepancy
