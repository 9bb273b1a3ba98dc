#include "clumpkit/core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

#include "clumpkit/core/error.hpp"

namespace clumpkit {

namespace fs = std::filesystem;

namespace {
std::string temp_name(const fs::path& path) {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  return path.string() + ".tmp" + std::to_string(::getpid()) + "_" +
         std::to_string(rng() % 1000000);
}
}  // namespace

void write_file_atomic(const fs::path& path, std::string_view content) {
  const std::string tmp = temp_name(path);
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw InputError(path.string(), "", std::string("cannot write: ") + std::strerror(errno));
  size_t done = 0;
  while (done < content.size()) {
    ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      throw InputError(path.string(), "", std::string("cannot write: ") + std::strerror(err));
    }
    done += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw InputError(path.string(), "", std::string("cannot write: ") + std::strerror(err));
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw InputError(path.string(), "", std::string("cannot write: ") + std::strerror(err));
  }
}

std::string read_file(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(path.string(), "", "is a directory, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "", std::string("cannot read: ") + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

bool path_exists(const fs::path& path) noexcept {
  std::error_code ec;
  return fs::exists(path, ec) && !ec;
}

void check_writable(const fs::path& path, const std::string& field) {
  fs::path dir = path.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError(path.string(), field, "folder '" + dir.string() + "' does not exist");
  if (::access(dir.c_str(), W_OK) != 0)
    throw InputError(path.string(), field, "folder '" + dir.string() + "' is not writable");
  if (fs::is_directory(path, ec)) throw InputError(path.string(), field, "is a directory");
}

OutputFolder::OutputFolder(const fs::path& dir, const std::string& field) : dir_(dir) {
  std::error_code ec;
  // The topmost missing folder on the way down to `dir` is the one to take away again.
  for (fs::path p = dir; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    made_ = p;
    if (p == p.parent_path()) break;
  }
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw InputError(dir.string(), field, "exists and is not a folder");
  fs::create_directories(dir, ec);  // a failure is named by the check below
  try {
    check_writable(dir / "x.json", field);  // "folder '...' does not exist" / "is not writable"
  } catch (...) {
    remove_if_empty();
    throw;
  }
}

OutputFolder::~OutputFolder() {
  remove_if_empty();
}

void OutputFolder::remove_if_empty() noexcept {
  if (made_.empty()) return;
  std::error_code ec;
  for (fs::path p = dir_;; p = p.parent_path()) {
    if (!fs::is_directory(p, ec) || !fs::is_empty(p, ec) || ec) return;
    fs::remove(p, ec);
    if (ec || p == made_ || p == p.parent_path()) return;
  }
}

}  // namespace clumpkit
