// derive.cpp — the exact derivation through the facade (GiNaC: backlash::api_derive only).
#include "backlash/api/derive.hpp"

#include "backlash/codegen/emit.hpp"
#include "backlash/symbolic/derivation_output.hpp"
#include "backlash/symbolic/forced_modes.hpp"
#include "backlash/symbolic/general_derivation.hpp"

#include <mutex>

namespace backlash::api {

namespace {
std::mutex& ginac_lock() {
  static std::mutex lock;  // GiNaC/CLN are not thread-safe
  return lock;
}
}  // namespace

Derivation derive(const Case& source) {
  const std::lock_guard<std::mutex> guard(ginac_lock());
  const symbolic::CaseDerivation derivation = symbolic::derive_case(source.spec());
  const symbolic::ForcedModes forced = symbolic::derive_forced_modes(derivation);
  Derivation out;
  out.case_id = source.id();
  out.text = symbolic::to_text(derivation);
  out.latex = symbolic::to_latex(derivation) + symbolic::forced_modes_latex(forced);
  nlohmann::json document = symbolic::to_json(derivation);
  // The modes the effects add (constant torques, the closed motor loop, coupled free flight).
  document["forced_modes"] = symbolic::forced_modes_json(forced);
  out.json = document.dump(2) + "\n";
  return out;
}

GeneralDerivation derive_general() {
  const std::lock_guard<std::mutex> guard(ginac_lock());
  const auto branches = symbolic::derive_general_branches();
  GeneralDerivation out;
  nlohmann::json all = nlohmann::json::array();
  for (const auto& branch : branches) {
    all.push_back(symbolic::to_json(branch));
    out.latex += symbolic::to_latex(branch) + "\n";
  }
  out.json = all.dump(2) + "\n";
  return out;
}

std::vector<GeneratedFile> generate_code(const Case& source) {
  const std::lock_guard<std::mutex> guard(ginac_lock());
  std::vector<GeneratedFile> out;
  for (codegen::GeneratedFile& file : codegen::emit_case_files(source.spec()))
    out.push_back({file.relative.string(), std::move(file.content)});
  return out;
}

ExactCase derive_exact(const Case& source) {
  const std::lock_guard<std::mutex> guard(ginac_lock());
  ExactCase out;
  out.derivation = symbolic::derive_case(source.spec());
  out.header = codegen::emit_case_header(source.spec(), out.derivation);
  return out;
}

}  // namespace backlash::api
