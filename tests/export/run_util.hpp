#pragma once
// Running external programs from tests: the clumpkit CLI and the DEM peers.
#include <sys/wait.h>
#include <unistd.h>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace clumpkit::test {

/// Runs `command` through the shell; returns its exit status (-1 if it did not exit normally).
inline int run(const std::string& command) {
  const int status = std::system(command.c_str());
  if (status == -1 || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

/// Full path of a program on PATH, or empty.
inline std::string which(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (!path) return {};
  std::string p = path;
  for (size_t a = 0; a <= p.size();) {
    size_t b = p.find(':', a);
    if (b == std::string::npos) b = p.size();
    const std::filesystem::path cand = std::filesystem::path(p.substr(a, b - a)) / program;
    std::error_code ec;
    if (!p.substr(a, b - a).empty() && std::filesystem::is_regular_file(cand, ec) &&
        ::access(cand.c_str(), X_OK) == 0)
      return cand.string();
    a = b + 1;
  }
  return {};
}

inline std::string quoted(const std::filesystem::path& p) {
  return "'" + p.string() + "'";
}

}  // namespace clumpkit::test
