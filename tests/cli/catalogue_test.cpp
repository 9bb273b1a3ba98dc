// The bad-input catalogue (docs/hardening.md): each [[case]] of tests/cli/catalogue/*.toml runs
// the clumpkit binary on broken input it creates, and checks that the command
//   - exits with the expected status (2 for bad input),
//   - prints exactly one line on stderr, matching the case's regex (which names file/line/field),
//   - leaves none of the `absent` paths and no new file at all in its scratch folder (no partial
//     output, no temporary left behind), and leaves its input files (and any old output) as they
//     were.
// Numerical faults (a simulation that blows up) are the exception: a run legitimately writes its
// series and frames up to the fault, so a case may list `outputs` folders where new files are
// allowed; every text file in them must then be free of NaN and infinity, and `allow_warnings`
// lets the run's own warning lines ("...warning: ...") precede the one-line diagnosis. Input found
// bad only once a run has started (a mesh that fails to load while the clumps are built) may
// follow the run's progress lines: `allow_progress` lets lines without "error" precede it.
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <ostream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "clumpkit/core/error.hpp"
#include "clumpkit/core/toml_doc.hpp"

namespace {

namespace fs = std::filesystem;
using clumpkit::TomlDoc;

struct InputFile {
  std::string path;  // relative to the case folder
  std::string content;
};

struct Case {
  std::string name, origin;  // origin: catalogue file:case index, for failure messages
  std::vector<std::string> args;
  std::vector<InputFile> files;
  std::vector<std::string> dirs;
  std::map<std::string, std::string> env;
  std::optional<long long> fsize_limit;  // bytes (RLIMIT_FSIZE in the child, SIGXFSZ ignored)
  bool needs_non_root = false;           // permission cases: root ignores file modes
  std::vector<std::string> read_only_dirs;
  int status = 2;
  std::string stderr_regex;
  std::vector<std::string> absent;
  std::vector<std::string> outputs;  // folders where a failing run may leave (NaN-free) files
  bool allow_warnings = false;       // lines before the diagnosis must be warnings
  bool allow_progress = false;       // lines before the diagnosis may be progress (no "error")
  std::string load_error;            // a malformed catalogue entry becomes one failing case
};

// gtest prints the parameter of a failing case: its name, not its bytes.
void PrintTo(const Case& c, std::ostream* os) {
  *os << c.name;
}

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (size_t pos = 0; (pos = s.find(from, pos)) != std::string::npos; pos += to.size())
    s.replace(pos, from.size(), to);
  return s;
}

std::vector<Case> load_catalogue() {
  std::vector<Case> cases;
  const fs::path dir = fs::path(CLUMPKIT_SOURCE_DIR) / "tests" / "cli" / "catalogue";
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".toml") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::set<std::string> names;
  for (const fs::path& file : files) {
    try {
      const TomlDoc doc = TomlDoc::load(file);
      const size_t n = doc.array_size("case");
      if (n == 0) doc.fail("case", "no [[case]] entries");
      for (size_t i = 0; i < n; ++i) {
        const std::string p = "case." + std::to_string(i) + ".";
        Case c;
        c.name = doc.string(p + "name");
        c.origin = file.filename().string() + " case " + std::to_string(i);
        if (c.name.empty() || !std::all_of(c.name.begin(), c.name.end(), [](char ch) {
              return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_';
            }))
          doc.fail(p + "name", "use letters, digits and _ only");
        if (!names.insert(c.name).second) doc.fail(p + "name", "duplicate case name");
        c.args = doc.strings(p + "args");
        for (size_t k = 0, m = doc.array_size(p + "files"); k < m; ++k) {
          const std::string q = p + "files." + std::to_string(k) + ".";
          InputFile f{doc.string(q + "path"), doc.string_opt(q + "content").value_or("")};
          for (size_t b = 0, nb = doc.array_size(q + "bytes"); b < nb; ++b)
            f.content += static_cast<char>(doc.integer(q + "bytes." + std::to_string(b)));
          const long long repeat = doc.integer_opt(q + "repeat").value_or(1);
          std::string one = f.content;
          for (long long r = 1; r < repeat; ++r) f.content += one;
          c.files.push_back(f);
        }
        c.dirs = doc.strings(p + "dirs");
        c.read_only_dirs = doc.strings(p + "read_only_dirs");
        c.needs_non_root = !c.read_only_dirs.empty();
        for (const std::string& k : doc.keys(p + "env")) c.env[k] = doc.string(p + "env." + k);
        c.fsize_limit = doc.integer_opt(p + "fsize_limit");
        c.status = static_cast<int>(doc.integer_opt(p + "status").value_or(2));
        c.stderr_regex = doc.string(p + "stderr");
        try {
          std::regex check(c.stderr_regex);
        } catch (const std::regex_error& e) {
          doc.fail(p + "stderr", std::string("not a valid regex: ") + e.what());
        }
        c.absent = doc.strings(p + "absent");
        c.outputs = doc.strings(p + "outputs");
        c.allow_warnings = doc.boolean_opt(p + "allow_warnings").value_or(false);
        c.allow_progress = doc.boolean_opt(p + "allow_progress").value_or(false);
        cases.push_back(std::move(c));
      }
    } catch (const clumpkit::InputError& e) {
      Case bad;
      bad.name = "catalogue_error_" + std::to_string(cases.size());
      bad.load_error = e.what();
      cases.push_back(bad);
    }
  }
  return cases;
}

std::set<fs::path> regular_files(const fs::path& dir) {
  std::set<fs::path> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (!e.is_directory()) out.insert(fs::relative(e.path(), dir));
  return out;
}

/// Position of the first NaN or infinity written as a number ("nan", "-nan", "inf", "Infinity",
/// any case, not part of a longer word such as "info"), or npos.
size_t find_nonfinite(const std::string& text) {
  std::string low(text);
  std::transform(low.begin(), low.end(), low.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  const auto letter = [&](size_t i) {
    return i < low.size() && (std::isalnum(static_cast<unsigned char>(low[i])) || low[i] == '_');
  };
  for (const std::string word : {"nan", "infinity", "inf"})
    for (size_t at = low.find(word); at != std::string::npos; at = low.find(word, at + 1))
      if ((at == 0 || !letter(at - 1)) && !letter(at + word.size())) return at;
  return std::string::npos;
}

struct Outcome {
  int status = -1;  // exit status, or -1 when killed by a signal
  int signal = 0;
  std::string err;  // everything written on stderr
};

/// Runs the CLI in `cwd` with stdout discarded and stderr captured through a pipe (pipes are not
/// subject to RLIMIT_FSIZE, so the message survives the full-disk cases).
Outcome run_cli(const Case& c, const fs::path& cwd, const std::vector<std::string>& args) {
  int pipefd[2];
  if (::pipe(pipefd) != 0) return {};
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(pipefd[0]);
    if (::chdir(cwd.c_str()) != 0) ::_exit(127);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::dup2(pipefd[1], STDERR_FILENO);
    for (const auto& [k, v] : c.env) ::setenv(k.c_str(), v.c_str(), 1);
    if (c.fsize_limit) {
      ::signal(SIGXFSZ, SIG_IGN);  // a write past the limit then fails with EFBIG, like ENOSPC
      const rlimit lim{static_cast<rlim_t>(*c.fsize_limit), static_cast<rlim_t>(*c.fsize_limit)};
      ::setrlimit(RLIMIT_FSIZE, &lim);
    }
    ::alarm(300);  // a hang is a failure too (SIGALRM kills the child)
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(pipefd[1]);
  Outcome out;
  char buf[4096];
  ssize_t n;
  while ((n = ::read(pipefd[0], buf, sizeof buf)) > 0) out.err.append(buf, static_cast<size_t>(n));
  ::close(pipefd[0]);
  int wstatus = 0;
  ::waitpid(pid, &wstatus, 0);
  if (WIFEXITED(wstatus)) out.status = WEXITSTATUS(wstatus);
  if (WIFSIGNALED(wstatus)) out.signal = WTERMSIG(wstatus);
  return out;
}

class BadInput : public ::testing::TestWithParam<Case> {};

TEST_P(BadInput, FailsCleanly) {
  const Case& c = GetParam();
  ASSERT_TRUE(c.load_error.empty()) << "malformed catalogue: " << c.load_error;
  if (c.needs_non_root && ::geteuid() == 0) GTEST_SKIP() << "root ignores file permissions";
#ifdef __clang__
  // LLVM's libomp (clang builds: the sanitizer stage) registers itself in a /dev/shm file at its
  // first parallel region; under RLIMIT_FSIZE that mapping cannot grow and the write SIGBUSes
  // inside libomp. The disk-full cases run in the gcc (libgomp) build.
  if (c.fsize_limit) GTEST_SKIP() << "RLIMIT_FSIZE breaks libomp's start-up (clang build)";
#endif
  SCOPED_TRACE(c.origin + " (" + c.name + ")");

  const fs::path dir = fs::path(CLUMPKIT_BINARY_DIR) / "tests" / "cli" / "scratch" / c.name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto expand = [&](const std::string& s) {
    return replace_all(replace_all(s, "{dir}", dir.string()), "{data}", CLUMPKIT_SOURCE_DIR);
  };
  for (const std::string& d : c.dirs) fs::create_directories(dir / expand(d));
  for (const InputFile& f : c.files) {
    const fs::path path = dir / expand(f.path);
    fs::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << f.content;
  }
  for (const std::string& d : c.read_only_dirs) {
    fs::create_directories(dir / d);
    fs::permissions(dir / d, fs::perms::owner_read | fs::perms::owner_exec);
  }
  const std::set<fs::path> before = regular_files(dir);

  std::vector<std::string> args{CLUMPKIT_CLI_BINARY};
  for (const std::string& a : c.args) args.push_back(expand(a));
  Case run = c;
  for (auto& [k, v] : run.env) v = expand(v);
  const Outcome out = run_cli(run, dir, args);

  EXPECT_EQ(out.signal, 0) << "killed by signal " << out.signal << "; stderr:\n" << out.err;
  EXPECT_EQ(out.status, c.status) << "stderr:\n" << out.err;
  ASSERT_FALSE(out.err.empty()) << "no message on stderr";
  EXPECT_EQ(out.err.back(), '\n') << "message not terminated: " << out.err;
  std::string line = out.err.substr(0, out.err.size() - 1);
  if (c.allow_warnings || c.allow_progress) {  // warning or progress lines, then the diagnosis
    const size_t last = line.rfind('\n');
    if (last != std::string::npos) {
      std::istringstream before_it(line.substr(0, last));
      for (std::string w; std::getline(before_it, w);) {
        if (c.allow_warnings && !c.allow_progress) {
          EXPECT_NE(w.find("warning: "), std::string::npos) << "not a warning line: " << w;
        } else if (!c.allow_warnings) {
          EXPECT_EQ(w.find("error"), std::string::npos) << "an error before the diagnosis: " << w;
        }
      }
      line = line.substr(last + 1);
    }
  }
  EXPECT_EQ(line.find('\n'), std::string::npos) << "more than one line on stderr:\n" << out.err;
  EXPECT_TRUE(std::regex_search(line, std::regex(c.stderr_regex)))
      << "message:  " << line << "\nexpected: /" << c.stderr_regex << "/";
  for (const std::string& a : c.absent)
    EXPECT_FALSE(fs::exists(expand(a).front() == '/' ? fs::path(expand(a)) : dir / expand(a)))
        << "output left behind: " << a;
  for (const std::string& d : c.read_only_dirs) fs::permissions(dir / d, fs::perms::owner_all);
  for (const InputFile& f : c.files) {  // a failing command touches neither inputs nor old outputs
    std::ifstream in(dir / expand(f.path), std::ios::binary);
    const std::string now((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_TRUE(now == f.content) << "file changed by a failing command: " << f.path;
  }
  const std::set<fs::path> after = regular_files(dir);
  const auto in_outputs = [&](const fs::path& f) {
    for (const std::string& o : c.outputs) {
      const std::string rel = fs::path(expand(o)).lexically_normal().string() + "/";
      if (f.string().rfind(rel, 0) == 0) return true;
    }
    return false;
  };
  for (const fs::path& f : after) {
    if (before.count(f)) continue;
    if (!in_outputs(f)) {
      ADD_FAILURE() << "file created by a failing command: " << f;
      continue;
    }
    std::ifstream in(dir / f, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (text.find('\0') != std::string::npos) continue;  // binary (a checkpoint)
    if (const size_t at = find_nonfinite(text); at != std::string::npos)
      ADD_FAILURE() << "non-finite number in output " << f << ": ..."
                    << text.substr(at > 40 ? at - 40 : 0, 80) << "...";
  }
  if (!HasFailure()) fs::remove_all(dir);
}

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  return info.param.name;
}

INSTANTIATE_TEST_SUITE_P(Catalogue, BadInput, ::testing::ValuesIn(load_catalogue()), case_name);

}  // namespace
