// make_two_body_record — writes a record of the independent two-body generator
// (two_body_generator.hpp) and the matching model file, from command-line parameters.
// Made the README's example (examples/two_body_drive.{csv,toml}; the model's backlash 1.5° and
// load inertia 25 % high, both free):
//   make_two_body_record --backlash-deg 2 --amplitude 0.4 --ramp 0.08 --rest 0.1
//     --nominal backlash=0.75 --nominal load.J=1.25 --free backlash --free load.J
//     --csv examples/two_body_drive.csv --toml examples/two_body_drive.toml
//
//   --csv FILE, --toml FILE   the outputs (required)
//   --backlash-deg B          the true total backlash [degrees] (default 2)
//   --motor-only              write t,theta_motor,drive (default: both encoders)
//   --on-load                 close the position loop on the load encoder (default: the motor's)
//   --stiffness K --damping C a compliant mesh [N·m/rad, N·m·s/rad] (default: rigid teeth)
//   --coulomb-motor C, --coulomb-load C   Coulomb friction [N·m] (default 0)
//   --jm, --fm, --jl, --fl    the bodies (defaults of TwoBodyPlant)
//   --kp, --kv, --ki          the loop's gains (defaults of TwoBodyLoop)
//   --amplitude A, --speed V, --ramp S, --rest S, --moves N   the reference (defaults of TwoBodyReference)
//   --counts N                encoder counts per revolution (default 65536)
//   --noise S                 σ of the logged drive's noise [N·m] (default 0.002)
//   --seed N                  the noise's seed (default 1)
//   --nominal KEY=FACTOR      the model file states KEY (backlash, motor.J, motor.F, load.J,
//                             load.F) times FACTOR (repeatable; default: the truth)
//   --free KEY                listed in the model's [fit] free (repeatable)
#include "two_body_generator.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <string>

namespace {

using namespace backlash::generated_data;

double number(const std::string& flag, const char* text) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(v)) throw std::invalid_argument(flag + ": not a number: " + text);
  return v;
}

void scale(TwoBodyPlant& p, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos) throw std::invalid_argument("--nominal: expected KEY=FACTOR, got " + assignment);
  const std::string key = assignment.substr(0, eq);
  const double factor = number("--nominal", assignment.c_str() + eq + 1);
  const std::map<std::string, double*> keys{
      {"backlash", &p.backlash}, {"motor.J", &p.Jm}, {"motor.F", &p.Fm}, {"load.J", &p.JL}, {"load.F", &p.FL}};
  const auto it = keys.find(key);
  if (it == keys.end()) throw std::invalid_argument("--nominal: unknown key " + key);
  *it->second *= factor;
}

}  // namespace

int main(int argc, char** argv) try {
  TwoBodyRecordSpec spec;
  spec.plant.backlash = 2 * M_PI / 180;
  spec.current_noise = 0.002;
  std::string csv, toml;
  bool both = true;
  std::vector<std::string> nominal, free;
  const std::map<std::string, double*> numbers{
      {"--stiffness", &spec.plant.stiffness}, {"--damping", &spec.plant.damping},
      {"--coulomb-motor", &spec.plant.coulomb_motor}, {"--coulomb-load", &spec.plant.coulomb_load},
      {"--jm", &spec.plant.Jm}, {"--fm", &spec.plant.Fm}, {"--jl", &spec.plant.JL}, {"--fl", &spec.plant.FL},
      {"--kp", &spec.loop.kp}, {"--kv", &spec.loop.kv}, {"--ki", &spec.loop.ki},
      {"--amplitude", &spec.reference.amplitude}, {"--speed", &spec.reference.speed}, {"--ramp", &spec.reference.ramp},
      {"--rest", &spec.reference.rest}, {"--noise", &spec.current_noise}};
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--motor-only") {
      both = false;
      continue;
    }
    if (flag == "--on-load") {
      spec.loop.on_load = true;
      continue;
    }
    if (i + 1 >= argc) throw std::invalid_argument(flag + ": needs a value (or is unknown)");
    const char* value = argv[++i];
    if (flag == "--csv") csv = value;
    else if (flag == "--toml") toml = value;
    else if (flag == "--backlash-deg") spec.plant.backlash = number(flag, value) * M_PI / 180;
    else if (flag == "--moves") spec.reference.moves = static_cast<int>(number(flag, value));
    else if (flag == "--counts") spec.counts_per_rev = static_cast<long>(number(flag, value));
    else if (flag == "--seed") spec.seed = static_cast<std::uint64_t>(number(flag, value));
    else if (flag == "--nominal") nominal.push_back(value);
    else if (flag == "--free") free.push_back(value);
    else if (numbers.count(flag)) *numbers.at(flag) = number(flag, value);
    else throw std::invalid_argument("unknown flag " + flag);
  }
  if (csv.empty() || toml.empty()) throw std::invalid_argument("--csv FILE and --toml FILE are required");
  const TwoBodyRecord record = generate_two_body_record(spec);
  TwoBodyCase model;
  model.nominal = spec.plant;
  for (const std::string& n : nominal) scale(model.nominal, n);
  model.free = free;
  model.name = std::string("geared servo with backlash (generated record, ") + (both ? "both encoders)" : "motor encoder)");
  char truth[512];
  std::snprintf(truth, sizeof truth,
                "Made by make_two_body_record (tests/discrepancy/two_body_generator.hpp). The truth:\n"
                "backlash %.6g rad (%.4g deg), motor J %.6g F %.6g, load J %.6g F %.6g, stiffness %s, Coulomb %.6g / %.6g N·m;\n"
                "a P position loop (kp %.4g N·m/rad) with velocity feedback (kv %.4g N·m·s/rad) on the %s encoder,\n%ld counts/rev, %zu samples at %.6g s, logged-drive noise %.3g N·m.",
                spec.plant.backlash, spec.plant.backlash * 180 / M_PI, spec.plant.Jm, spec.plant.Fm, spec.plant.JL, spec.plant.FL,
                std::isinf(spec.plant.stiffness) ? "rigid" : std::to_string(spec.plant.stiffness).c_str(), spec.plant.coulomb_motor,
                spec.plant.coulomb_load, spec.loop.kp, spec.loop.kv, spec.loop.on_load ? "load" : "motor", spec.counts_per_rev, record.t.size(), spec.loop.period,
                spec.current_noise);
  model.comment = truth;
  write_text_file(csv, two_body_csv(record, both));
  write_text_file(toml, two_body_case_toml(model));
  std::printf("%zu samples, %d reversals, %d impacts, %d engagements, %d sticks\n", record.t.size(), record.reversals,
              record.events.impacts, record.events.engagements, record.events.sticks);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "make_two_body_record: %s\n", e.what());
  return 2;
}
