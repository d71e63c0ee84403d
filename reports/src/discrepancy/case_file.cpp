// The corrected model as a case file that loads and simulates as it is.
#include "backlash/reports/discrepancy_pages.hpp"

#include "case_file_text.hpp"

#include <charconv>
#include <cmath>
#include <sstream>

namespace backlash::discrepancy {

namespace detail {

// The shortest decimal that reads back as the same double (the loader reads decimals exactly).
std::string decimal(double value) {
  char buffer[64];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
  std::string text(buffer, error == std::errc() ? end : buffer);
  if (text.find_first_of(".e") == std::string::npos) text += ".0";
  return text;
}

// The original exact value when the fit kept it, else the fitted decimal.
std::string exact_or(const model::Rational& original, double value) {
  return model::to_double(original) == value ? toml_string(model::to_string(original)) : decimal(value);
}

}  // namespace detail

using detail::decimal;
using detail::exact_or;
using detail::toml_string;

std::string corrected_case_file(const model::CaseSpec& spec, const DiscrepancyResult& result, double step) {
  std::ostringstream out;
  out << "# The model of " << spec.source.filename().string() << " corrected by `backlash discrepancy`.\n";
  for (const Candidate& c : result.effects) {
    out << "#   " << c.effect << ":";
    for (const Parameter& p : c.parameters) out << " " << p.name << " = " << p.value << " ± " << p.uncertainty;
    out << "\n";
  }
  out << "# RMS of theta_out against the record: " << result.rms_before << " before, " << result.rms_after
      << " after (noise " << result.noise << ").\n";
  const numeric::Parameters& p = result.parameters;
  const numeric::Effects& e = result.corrected_effects;
  out << "name = " << toml_string(spec.name + " (corrected)") << "\n";
  out << "measured_at = \"" << model::to_string(spec.measured_at) << "\"\n";
  out << "K = " << exact_or(spec.K, p.K) << "\n";
  out << "backlash = " << exact_or(spec.backlash, p.backlash) << "\n";
  out << "reference = " << exact_or(spec.reference, p.theta_R) << "\n\n";
  out << "[motor]\nJ = " << exact_or(spec.Jm, p.Jm) << "\nF = " << exact_or(spec.Fm, p.Fm) << "\n\n";
  out << "[load]\nJ = " << exact_or(spec.JL, p.JL) << "\nF = " << exact_or(spec.FL, p.FL) << "\n\n";
  out << "[experiment]\nstep = "
      << (spec.experiment && model::to_double(spec.experiment->step) == step ? toml_string(model::to_string(spec.experiment->step))
                                                                               : decimal(step))
      << "\n";
  if (spec.experiment && spec.experiment->t_end) out << "t_end = " << toml_string(model::to_string(*spec.experiment->t_end)) << "\n";
  if (!e.any()) return out.str();
  const model::Effects& m = spec.effects;
  out << "\n[effects]\n";
  if (e.coulomb_motor > 0) out << "coulomb_motor = " << exact_or(m.coulomb_motor, e.coulomb_motor) << "\n";
  if (e.coulomb_load > 0) out << "coulomb_load = " << exact_or(m.coulomb_load, e.coulomb_load) << "\n";
  if (e.restitution > 0) out << "restitution = " << exact_or(m.restitution, e.restitution) << "\n";
  if (e.saturating())
    out << "saturation = " << (m.saturation ? exact_or(*m.saturation, e.saturation) : decimal(e.saturation)) << "\n";
  if (e.compliant()) {
    const bool same = m.compliance && model::to_double(m.compliance->stiffness) == e.mesh_stiffness &&
                      model::to_double(m.compliance->damping) == e.mesh_damping;
    out << "compliance = { stiffness = "
        << (same ? toml_string(model::to_string(m.compliance->stiffness)) : decimal(e.mesh_stiffness))
        << ", damping = " << (same ? toml_string(model::to_string(m.compliance->damping)) : decimal(e.mesh_damping)) << " }\n";
  }
  if (e.delayed()) out << "delay = " << exact_or(m.delay, e.delay) << "\n";
  if (e.torque_offset != 0) out << "torque_offset = " << exact_or(m.torque_offset, e.torque_offset) << "\n";
  return out.str();
}

}  // namespace backlash::discrepancy
