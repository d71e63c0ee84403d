// backlash/output/signals.hpp — what SIGINT, SIGTERM and SIGHUP do to the outputs being
// written, and how a later run removes what a killed one left (docs/design.md, "Output").
//
// After clean_up_on_signals() (the command line calls it first thing, cli/main.cpp), one of
// these signals removes every temporary output still being written — an AtomicFile's
// temporary file, a temporary StagedDirectory (".NAME.tmp-PID-XXXXXX") — and then ends the
// process by the signal itself (its default action: a shell sees 128 + the signal's number,
// 130 for SIGINT, 143 for SIGTERM).  An output being moved into place is finished first.
// Inside a StopOnSignal scope the signals only ask the work to stop (StopOnSignal::requested):
// the work polls and stops on its own terms (the map keeps its partial folder for --resume).
// A signal that is ignored when clean_up_on_signals() runs (nohup) stays ignored.  Without
// clean_up_on_signals() (a library user, Python) the signals are left alone.
//
// A process killed outright (SIGKILL, a power cut) cannot clean up: its temporaries carry its
// process id in their names and are locked (flock) while it lives, and the next AtomicFile or
// temporary StagedDirectory onto the same target removes those of dead processes
// (remove_stale_temporaries).
#pragma once

#include <filesystem>

namespace backlash::output {

/// Installs the handlers of SIGINT, SIGTERM and SIGHUP described above (once; later calls do
/// nothing).  Call it before starting threads.
void clean_up_on_signals();

/// While one exists, SIGINT/SIGTERM/SIGHUP set requested() instead of ending the process.
/// Needs clean_up_on_signals() to have been called (else the signals keep their old action).
class StopOnSignal {
 public:
  StopOnSignal();
  ~StopOnSignal();
  StopOnSignal(const StopOnSignal&) = delete;
  StopOnSignal& operator=(const StopOnSignal&) = delete;
  /// True once a signal arrived during any StopOnSignal's life (async-signal-safe to read).
  static bool requested();
};

/// Removes the temporaries ".NAME.tmp-PID-XXXXXX" beside `target` (files or folders) whose
/// process PID is gone and whose lock is free: what a killed run onto `target` left.  Never
/// fails (what cannot be removed stays).
void remove_stale_temporaries(const std::filesystem::path& target);

}  // namespace backlash::output
