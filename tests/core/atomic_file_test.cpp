#include "clumpkit/core/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <filesystem>

#include "clumpkit/core/error.hpp"

using namespace clumpkit;
namespace fs = std::filesystem;

namespace {
fs::path fresh_dir(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("clumpkit_" + name + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}
size_t entries(const fs::path& d) {
  return static_cast<size_t>(std::distance(fs::directory_iterator(d), fs::directory_iterator()));
}
}  // namespace

TEST(AtomicFile, WritesAndReplaces) {
  const fs::path d = fresh_dir("atomic");
  write_file_atomic(d / "a.txt", "one");
  write_file_atomic(d / "a.txt", "two");
  EXPECT_EQ(read_file(d / "a.txt"), "two");
  EXPECT_EQ(entries(d), 1u);  // no temporaries left
  fs::remove_all(d);
}

TEST(AtomicFile, MissingFolderIsAnInputErrorAndLeavesNothing) {
  EXPECT_THROW(write_file_atomic("/nonexistent_clumpkit_dir/a.txt", "x"), InputError);
  EXPECT_THROW(check_writable("/nonexistent_clumpkit_dir/a.txt"), InputError);
  EXPECT_THROW(read_file("/nonexistent_clumpkit_dir/a.txt"), InputError);
}

TEST(AtomicFile, FullDiskLeavesOldContentAndNoTemporary) {
  const fs::path d = fresh_dir("full");
  write_file_atomic(d / "a.txt", "old");
  // Simulate a full disk with a file-size limit; SIGXFSZ ignored so write() fails with EFBIG.
  struct rlimit old_limit;
  getrlimit(RLIMIT_FSIZE, &old_limit);
  auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit lim = old_limit;
  lim.rlim_cur = 1024;
  setrlimit(RLIMIT_FSIZE, &lim);
  EXPECT_THROW(write_file_atomic(d / "a.txt", std::string(4096, 'x')), InputError);
  setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_EQ(read_file(d / "a.txt"), "old");
  EXPECT_EQ(entries(d), 1u);
  fs::remove_all(d);
}

TEST(OutputFolder, TheFoldersItMadeGoAgainWhenLeftEmpty) {
  const fs::path d = fresh_dir("outfolder");
  {
    OutputFolder out(d / "runs" / "first", "--out");  // two levels made
    EXPECT_TRUE(fs::is_directory(d / "runs" / "first"));
  }
  EXPECT_FALSE(fs::exists(d / "runs"));  // both taken away, the one that was there kept
  EXPECT_TRUE(fs::is_directory(d));
  {
    OutputFolder out(d / "kept", "--out");
    write_file_atomic(d / "kept" / "result.json", "{}");
  }
  EXPECT_TRUE(fs::exists(d / "kept" / "result.json"));  // written into: kept
  fs::create_directories(d / "before");
  { OutputFolder out(d / "before", "--out"); }
  EXPECT_TRUE(fs::is_directory(d / "before"));  // there before the command: kept, even empty
  write_file_atomic(d / "file", "x");
  try {
    OutputFolder out(d / "file", "--report");
    ADD_FAILURE() << "a file taken for a folder";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a folder"), std::string::npos) << e.what();
  }
  try {
    OutputFolder out(d / "file" / "sub", "--out");
    ADD_FAILURE() << "a folder under a file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
  fs::remove_all(d);
}
