// temporaries.hpp — the temporaries being written (an AtomicFile's file, a temporary
// StagedDirectory), known to the signal cleanup (signals.cpp; backlash/output/signals.hpp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <mutex>
#include <string>

namespace backlash::output::detail {

/// Holds off the signal cleanup while alive (the rename of an output into place).
std::unique_lock<std::recursive_mutex> hold_temporaries();

/// ".NAME.tmp-PID-" beside `target`: the start of its temporaries' names (mkstemp and mkdtemp
/// append "XXXXXX"); remove_stale_temporaries reads the PID back.
std::string temporary_prefix(const std::filesystem::path& target);

/// Registers `path` (a file or a folder, removed as a whole on a signal); returns its ticket.
std::uint64_t track_temporary(const std::filesystem::path& path);
/// Unregisters a ticket (it was moved into place or removed) and sets it to 0; 0 does nothing.
void forget_temporary(std::uint64_t& ticket);

/// flock(LOCK_EX) on `fd` (held until closed): a later run sees the temporary as alive.
void lock_temporary(int fd);

}  // namespace backlash::output::detail
