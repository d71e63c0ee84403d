// Writing small .mat files with matio for the EMPS tests (bad records on purpose).
#pragma once

#include <matio.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace backlash::measurements::testing {

struct MatVariableSpec {
  enum class Kind { real, complex, text, single, int32, logical };
  MatVariableSpec(std::string name_, std::vector<double> values_, std::vector<std::size_t> dims_ = {},
                  Kind kind_ = Kind::real, std::string text_ = {})
      : name(std::move(name_)), values(std::move(values_)), dims(std::move(dims_)), kind(kind_), text(std::move(text_)) {}
  std::string name;
  std::vector<double> values;     ///< real part (complex: imaginary part = 1)
  std::vector<std::size_t> dims;  ///< empty: values.size() x 1
  Kind kind = Kind::real;
  std::string text;               ///< Kind::text only
};

/// Writes the variables into a new .mat file (v5 unless told otherwise).
/// Returns false when matio cannot create that version (e.g. v7.3 without HDF5).
inline bool write_mat(const std::filesystem::path& file, const std::vector<MatVariableSpec>& variables,
                      mat_ft version = MAT_FT_MAT5) {
  mat_t* mat = Mat_CreateVer(file.c_str(), nullptr, version);
  if (mat == nullptr) return false;
  for (const MatVariableSpec& spec : variables) {
    std::vector<std::size_t> dims = spec.dims.empty() ? std::vector<std::size_t>{spec.values.size(), 1} : spec.dims;
    std::vector<double> values = spec.values;
    std::vector<double> imaginary(values.size(), 1.0);
    std::vector<float> singles(values.begin(), values.end());
    std::vector<std::int32_t> integers;
    std::vector<std::uint8_t> logicals;
    for (double value : values) {
      integers.push_back(static_cast<std::int32_t>(value));
      logicals.push_back(value != 0 ? 1 : 0);
    }
    std::string text = spec.text;
    mat_complex_split_t split{values.data(), imaginary.data()};
    matvar_t* variable = nullptr;
    switch (spec.kind) {
      case MatVariableSpec::Kind::real:
        variable = Mat_VarCreate(spec.name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims.data(), values.data(), 0);
        break;
      case MatVariableSpec::Kind::complex:
        variable = Mat_VarCreate(spec.name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims.data(), &split, MAT_F_COMPLEX);
        break;
      case MatVariableSpec::Kind::text:
        dims = {1, text.size()};
        variable = Mat_VarCreate(spec.name.c_str(), MAT_C_CHAR, MAT_T_UTF8, 2, dims.data(), text.data(), 0);
        break;
      case MatVariableSpec::Kind::single:
        variable = Mat_VarCreate(spec.name.c_str(), MAT_C_SINGLE, MAT_T_SINGLE, 2, dims.data(), singles.data(), 0);
        break;
      case MatVariableSpec::Kind::int32:
        variable = Mat_VarCreate(spec.name.c_str(), MAT_C_INT32, MAT_T_INT32, 2, dims.data(), integers.data(), 0);
        break;
      case MatVariableSpec::Kind::logical:
        variable = Mat_VarCreate(spec.name.c_str(), MAT_C_UINT8, MAT_T_UINT8, 2, dims.data(), logicals.data(),
                                 MAT_F_LOGICAL);
        break;
    }
    if (variable == nullptr || Mat_VarWrite(mat, variable, MAT_COMPRESSION_NONE) != 0) {
      if (variable) Mat_VarFree(variable);
      Mat_Close(mat);
      throw std::runtime_error("matio cannot write variable " + spec.name + " to " + file.string());
    }
    Mat_VarFree(variable);
  }
  Mat_Close(mat);
  return true;
}

/// A small valid EMPS-like record: n samples at 1 kHz (t = k/1000), gtau = 35.
inline std::vector<MatVariableSpec> emps_variables(std::size_t samples = 10) {
  std::vector<double> t, qm, qg, vir;
  for (std::size_t k = 0; k < samples; ++k) {
    t.push_back(static_cast<double>(k) / 1000);
    qm.push_back(1e-3 * std::sin(static_cast<double>(k)));
    qg.push_back(1e-3 * std::sin(static_cast<double>(k) + 0.5));
    vir.push_back(2 * std::cos(static_cast<double>(k)));
  }
  return {{"t", t}, {"qm", qm}, {"qg", qg}, {"vir", vir}, {"gtau", {35}}, {"kp", {160}}, {"kv", {243}}};
}

/// The variable `name` of `variables` (must exist).
inline MatVariableSpec& variable_named(std::vector<MatVariableSpec>& variables, const std::string& name) {
  for (MatVariableSpec& spec : variables)
    if (spec.name == name) return spec;
  throw std::runtime_error("no variable " + name);
}

}  // namespace backlash::measurements::testing
