// Placeholder: `backlash import` is being written (measured records → the project's CSV).
#include "commands.hpp"

namespace backlash::cli {
void register_import_command(CLI::App&) {}
}  // namespace backlash::cli
