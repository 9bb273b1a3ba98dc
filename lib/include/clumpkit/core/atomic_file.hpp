#pragma once
/// Outputs are written to a temporary file beside the target and renamed into place, so a failed
/// or killed run never leaves a half-written file under the final name.
#include <filesystem>
#include <string>
#include <string_view>

namespace clumpkit {

/// Writes `content` to `path` atomically. Throws InputError naming the path if the folder is not
/// writable or the disk is full; the target is then untouched and no temporary is left.
void write_file_atomic(const std::filesystem::path& path, std::string_view content);

/// Reads a whole file; throws InputError naming the path if it cannot be read.
std::string read_file(const std::filesystem::path& path);

/// Whether `path` names something that exists. Never throws: a path the system cannot even look
/// up (a name too long, a component that is not a folder, no permission) counts as not there, so
/// a reader reports it as a missing file with the field that named it, not as a system error.
bool path_exists(const std::filesystem::path& path) noexcept;

/// Checks up front that `path` could be created (its folder exists and is writable), so commands
/// fail before doing expensive work. Throws InputError naming the path and `field`.
void check_writable(const std::filesystem::path& path, const std::string& field = "");

}  // namespace clumpkit
