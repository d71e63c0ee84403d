// Internal helpers of backlash_measurements: guarded file access and the small
// text helpers the one-line error messages need.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace backlash::measurements::detail {

/// Throws MeasuredDataError(file, 0, "", ...) unless `file` is an existing
/// regular file (symbolic links followed) of at most max_bytes bytes.  Decided
/// from the file's metadata only: /dev/zero or a FIFO is refused without a read.
void require_readable_regular_file(const std::filesystem::path& file, std::uintmax_t max_bytes);

/// The whole content of a regular file of at most max_bytes bytes (checked on
/// the opened descriptor before reading, and again while reading).
std::string read_regular_file(const std::filesystem::path& file, std::uintmax_t max_bytes);

/// Writes `content` to `target` all at once (backlash/output/atomic_file.hpp: a unique
/// temporary sibling, fsync'ed and renamed into place); its refusals (a bad target) as
/// MeasuredDataError(target, 0, "", "cannot write: …" or "refusing to replace it: …"), its
/// failures (a full disk, a permission) as output::OutputError of kind write_failed whose
/// what() is "TARGET: cannot write: …".
void write_file_atomically(const std::filesystem::path& target, std::string_view content);

/// Text made safe for a one-line message: control and non-ASCII bytes, quote
/// and backslash as \xNN; cut after max_characters with "...".
std::string printable(std::string_view text, std::size_t max_characters = 40);

/// printable(text) in single quotes.
std::string quoted(std::string_view text, std::size_t max_characters = 40);

/// The shortest decimal that reads back as exactly `value`, for messages
/// (fmt's "{}": plain notation from 1e-4 to 1e16).
std::string shortest(double value);

}  // namespace backlash::measurements::detail
