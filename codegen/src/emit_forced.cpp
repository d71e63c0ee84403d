#include "backlash/codegen/emit_forced.hpp"

#include "backlash/symbolic/escape.hpp"

#include "printer.hpp"
#include "term_emission.hpp"

#include <algorithm>
#include <sstream>

namespace backlash::codegen {

using detail::Input;
using detail::parameter_list;
using detail::Style;
using detail::Term;
using detail::TermEmitter;
using detail::unused_markers;
using symbolic::ForcedModes;
using symbolic::ForcedOutput;
using symbolic::ForcedSolution;

namespace {

// The terms are converted and printed by the case emitter's machinery
// (term_emission.hpp), so the forced block reads like the rest of the header.

struct Output {
  const ForcedOutput* source;
  std::vector<Term> terms;
};

struct Mode {
  const ForcedSolution* source;
  std::vector<Input> inputs;
  std::vector<Output> outputs;
};

// Every output's terms: what one mode's function computes.
std::vector<const std::vector<Term>*> all_terms(const Mode& mode) {
  std::vector<const std::vector<Term>*> all;
  for (const Output& o : mode.outputs) all.push_back(&o.terms);
  return all;
}

class ForcedEmitter {
 public:
  explicit ForcedEmitter(const ForcedModes& m);
  std::string code() const;
  std::map<std::string, std::string> latex() const;

 private:
  TermEmitter terms_;  // the rates and frequencies of every forced mode
  std::vector<Mode> modes_;

  std::string function(const Mode& mode) const;
};

ForcedEmitter::ForcedEmitter(const ForcedModes& m) : terms_(m.radicals) {
  for (const ForcedSolution* s : m.solutions()) {
    Mode mode;
    mode.source = s;
    for (std::size_t i = 0; i < s->arguments.size(); ++i) mode.inputs.push_back({s->arguments[i], s->argument_names[i]});
    for (const ForcedOutput& o : s->outputs) mode.outputs.push_back({&o, terms_.convert(o.segment.solution, mode.inputs)});
    modes_.push_back(std::move(mode));
  }
}

std::string ForcedEmitter::function(const Mode& mode) const {
  const ForcedSolution& s = *mode.source;
  const std::string type = s.name + "_t";
  std::ostringstream f;
  f << "struct " << type << " {\n";
  for (const Output& o : mode.outputs)
    f << "  double " << o.source->segment.name << ";  ///< " << symbolic::escape::cpp_comment(o.source->meaning) << "\n";
  f << "};\n\n";
  f << "/// " << s.name << ": " << symbolic::escape::cpp_comment(s.meaning) << ".\n";
  f << "/// " << symbolic::escape::cpp_comment(s.equation) << ":\n";
  for (const Output& o : mode.outputs)
    f << "///   " << o.source->segment.name << " = " << terms_.exact_text(o.terms, mode.inputs, Style::Text) << "\n";
  f << "inline " << type << " " << s.name << "(" << parameter_list(mode.inputs) << ") noexcept {\n";
  f << unused_markers(all_terms(mode), mode.inputs) << terms_.constants_for(all_terms(mode));
  f << "  " << type << " s;\n";
  for (const Output& o : mode.outputs)
    f << "  s." << o.source->segment.name << " = " << terms_.sum_code(o.terms, mode.inputs, "      ") << ";\n";
  f << "  return s;\n}\n\n";
  return f.str();
}

std::string ForcedEmitter::code() const {
  std::ostringstream h;
  h << "// Forced modes (docs/effects.md): each linear mode with a constant forcing that\n"
       "// Coulomb friction, saturation or a torque offset add, exact for this case\n"
       "// (symbolic/forced_modes.hpp).  Displacements are theta(t) - theta(0); the forcing\n"
       "// and the initial state are runtime arguments.\n";
  h << "namespace forced {\n\n";
  h << terms_.frequency_constants();
  for (const Mode& mode : modes_) h << function(mode);
  h << "/// LaTeX of every forced output (exact).\n";
  h << "struct latex {\n";
  for (const auto& [name, tex] : latex()) {
    std::string key = name;
    std::replace(key.begin(), key.end(), '.', '_');
    h << "  static constexpr const char* " << key << " = R\"tex(" << tex << ")tex\";\n";
  }
  h << "};\n\n";
  h << "}  // namespace forced\n\n";
  return h.str();
}

std::map<std::string, std::string> ForcedEmitter::latex() const {
  std::map<std::string, std::string> out;
  for (const Mode& mode : modes_) {
    out[mode.source->name] = mode.source->equation_latex;
    for (const Output& o : mode.outputs)
      out[mode.source->name + "." + o.source->segment.name] = terms_.exact_text(o.terms, mode.inputs, Style::Latex);
  }
  return out;
}

}  // namespace

std::string emit_forced_namespace(const ForcedModes& modes) { return ForcedEmitter(modes).code(); }

std::string emit_forced_namespace(const symbolic::CaseDerivation& derivation) {
  return emit_forced_namespace(symbolic::derive_forced_modes(derivation));
}

std::map<std::string, std::string> forced_latex(const ForcedModes& modes) { return ForcedEmitter(modes).latex(); }

std::string emit_forced_latex(const symbolic::CaseDerivation& d) {
  const ForcedModes modes = symbolic::derive_forced_modes(d);
  const std::map<std::string, std::string> tex = forced_latex(modes);
  auto escaped = [](const std::string& s) {
    std::string o;
    for (char c : s) o += c == '_' ? std::string("\\_") : std::string(1, c);
    return o;
  };
  std::ostringstream out;
  out << "\\subsection*{" << symbolic::escape::latex_text(d.name) << ": forced modes (effects)}\n";
  out << "Displacements $\\Delta = \\theta - \\theta(0)$ under a constant forcing (docs/effects.md); "
         "namespace \\texttt{forced} of the generated header.\n";
  for (const ForcedSolution* s : modes.solutions()) {
    out << "\\paragraph{\\texttt{" << escaped(s->name) << "}}\n";
    out << "\\begin{equation}\\label{eq:gen:" << d.case_id << ":forced:" << s->name << "}\n"
        << tex.at(s->name) << "\n\\end{equation}\n";
    for (const ForcedOutput& o : s->outputs)
      out << "\\begin{equation}\\label{eq:gen:" << d.case_id << ":forced:" << s->name << ":" << o.segment.name << "}\n"
          << o.lhs_latex << " = " << tex.at(s->name + "." + o.segment.name) << "\n\\end{equation}\n";
  }
  return out.str();
}

}  // namespace backlash::codegen
