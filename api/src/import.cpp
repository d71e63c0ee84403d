// import.cpp — `backlash import`: an EMPS record (measurements/emps.hpp) converted into the
// project's CSV, and the summary the CLI prints.
#include "backlash/api/backlash.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace backlash::api {

namespace {

const char* describe(measurements::EmpsPulses pulses) {
  switch (pulses) {
    case measurements::EmpsPulses::none: return "none";
    case measurements::EmpsPulses::contained: return "already contained in vir (it steps with every edge): not added";
    case measurements::EmpsPulses::added: return "not in vir: added to gtau*vir";
  }
  return "?";
}

}  // namespace

Import import_record(const std::filesystem::path& input, const std::filesystem::path& out) {
  Import result;
  result.input = input.string();
  result.out = out.string();
  result.emps = measurements::read_emps(input);
  result.pulses = measurements::emps_pulses_in_vir(result.emps);
  result.record = measurements::to_measured_record(result.emps);
  measurements::write_measured_csv(result.record, out);
  return result;
}

std::string Import::text() const {
  const std::size_t samples = record.size();
  const double duration = record.t.back() - record.t.front();
  double shortest_step = record.t[1] - record.t[0], longest_step = shortest_step;
  for (std::size_t index = 2; index < samples; ++index) {
    const double step = record.t[index] - record.t[index - 1];
    shortest_step = std::min(shortest_step, step);
    longest_step = std::max(longest_step, step);
  }
  std::string text = fmt::format("imported {} (EMPS) into {}\n", input, out);
  text += fmt::format("  samples      {}\n", samples);
  text += fmt::format("  duration     {:.10g} s (t = {:.10g} ... {:.10g})\n", duration, record.t.front(), record.t.back());
  text += fmt::format("  sample rate  {:.6g} Hz (steps {:.6g} ... {:.6g} s)\n", static_cast<double>(samples - 1) / duration,
                      shortest_step, longest_step);
  text += fmt::format("  gtau         {} N/V (kp = {}, kv = {})\n", emps.gtau, emps.kp, emps.kv);
  text += fmt::format("  columns      t [s], theta_out = qm [m], drive = {} [N]\n",
                      pulses == measurements::EmpsPulses::added ? "gtau*vir + pulses_N" : "gtau*vir");
  text += fmt::format("  pulses_N     {}\n", describe(pulses));
  text += fmt::format("suggested [experiment] for a measured-drive model file (data: {}):\n", out);
  text += "[experiment]\nkind = \"drive\"\ndrive_gain = 1\n";
  return text;
}

}  // namespace backlash::api
