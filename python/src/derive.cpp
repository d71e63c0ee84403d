// backlash._derive — the exact derivation (backlash/api/derive.hpp, GiNaC) for Python,
// imported only by Case.derive(): `import backlash` alone never loads GiNaC.  The case
// arrives as its exact case file (Case.case_file()), read back by the same strict reader.
// GiNaC is not thread-safe: the GIL is held throughout (and the facade locks as well).
#include "backlash/api/derive.hpp"

#include <pybind11/pybind11.h>

namespace py = pybind11;
using namespace backlash;

PYBIND11_MODULE(_derive, m) {
  m.doc() = "backlash's exact derivation (GiNaC); use Case.derive() of the package `backlash`.";
  py::register_exception<api::BadInput>(m, "BadInput", PyExc_ValueError);
  py::register_exception<model::CaseFileError>(m, "CaseFileError", PyExc_ValueError);
  m.def(
      "derive",
      [](const std::string& case_file, const std::string& id) {
        const api::Case c = api::Case::from_text(case_file, id, id);
        const api::Derivation d = api::derive(c);
        py::dict out;
        out["case"] = id;
        out["text"] = d.text;
        out["latex"] = d.latex;
        out["json"] = d.json;
        return out;
      },
      py::arg("case_file"), py::arg("id"));
  m.def("derive_general", [] {
    const api::GeneralDerivation d = api::derive_general();
    py::dict out;
    out["latex"] = d.latex;
    out["json"] = d.json;
    return out;
  });
}
