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

/// An output folder a command makes before its work, so that a folder it cannot write is refused
/// before any long run. The folders it had to create are removed again when it goes out of scope
/// still empty: a command that fails before writing its first file (a missing mesh found while
/// the clumps are built, say) leaves nothing behind. A folder that existed before is never
/// removed, nor one that holds anything.
class OutputFolder {
 public:
  /// Creates `dir` (and missing parents); throws InputError naming `field` if it cannot be
  /// created or written.
  OutputFolder(const std::filesystem::path& dir, const std::string& field);
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

 private:
  void remove_if_empty() noexcept;
  std::filesystem::path dir_;
  std::filesystem::path made_;  ///< the topmost folder this one created; empty: none
};

}  // namespace clumpkit
