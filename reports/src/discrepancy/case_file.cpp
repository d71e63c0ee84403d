// The corrected model as a case file that loads and simulates as it is.
#include "backlash/reports/discrepancy_pages.hpp"


#include "backlash/model/case_writer.hpp"

#include <sstream>

namespace backlash::discrepancy {

std::string corrected_case_file(const model::CaseSpec& spec, const DiscrepancyResult& result, double step) {
  model::CaseFileText c;
  c.blank_line_before_tables = true;
  c.comments.push_back("The model of " + spec.source.filename().string() + " corrected by `backlash discrepancy`.");
  for (const Candidate& candidate : result.effects) {
    std::ostringstream line;
    line << "  " << candidate.effect << ":";
    for (const Parameter& p : candidate.parameters) line << " " << p.name << " = " << p.value << " ± " << p.uncertainty;
    c.comments.push_back(line.str());
  }
  std::ostringstream rms;
  rms << "RMS of theta_out against the record: " << result.rms_before << " before, " << result.rms_after << " after (noise "
      << result.noise << ").";
  c.comments.push_back(rms.str());
  const numeric::Parameters& p = result.parameters;
  c.name = spec.name + " (corrected)";
  c.measured_at = spec.measured_at;
  c.K = model::exact_or_decimal(spec.K, p.K);
  c.backlash = model::exact_or_decimal(spec.backlash, p.backlash);
  c.reference = model::exact_or_decimal(spec.reference, p.theta_R);
  c.Jm = model::exact_or_decimal(spec.Jm, p.Jm), c.Fm = model::exact_or_decimal(spec.Fm, p.Fm);
  c.JL = model::exact_or_decimal(spec.JL, p.JL), c.FL = model::exact_or_decimal(spec.FL, p.FL);
  model::ExperimentText x;
  x.step = spec.experiment ? model::exact_or_decimal(spec.experiment->step, step) : model::decimal_text(step);
  if (spec.experiment && spec.experiment->t_end) x.t_end = model::exact_text(*spec.experiment->t_end);
  if (spec.experiment && spec.experiment->step_time) x.step_time = model::exact_text(*spec.experiment->step_time);
  c.experiment = x;
  c.effects = model::fitted_effect_texts(spec.effects, result.corrected_effects);
  return model::write_case_file(c);
}

}  // namespace backlash::discrepancy
