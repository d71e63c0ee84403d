// The one error type of the output layer (backlash/output/output_error.hpp).
#include "backlash/output/output_error.hpp"

#include <utility>

namespace backlash::output {

OutputError::OutputError(Kind kind, Problem problem, std::filesystem::path target, std::string detail,
                         const std::string& message)
    : std::runtime_error(message), kind_(kind), problem_(problem), target_(std::move(target)), detail_(std::move(detail)) {}

void refuse(Problem problem, const std::filesystem::path& target, std::string detail, const std::string& message) {
  throw OutputError(OutputError::Kind::bad_target, problem, target, std::move(detail), message);
}

void fail(Problem problem, const std::filesystem::path& target, std::string detail, const std::string& message) {
  throw OutputError(OutputError::Kind::write_failed, problem, target, std::move(detail), message);
}

}  // namespace backlash::output
