#pragma once
// Shared by the fuzz targets. Bad input must end in clumpkit::InputError with a one-line message;
// anything else (another exception, a broken invariant of an accepted input, a sanitizer report,
// an assert) is a bug and must crash the fuzzer.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "clumpkit/core/error.hpp"

namespace clumpkit::fuzz {

[[noreturn]] inline void fail(const char* check, const std::string& detail) {
  std::fprintf(stderr, "fuzz: invariant violated: %s (%s)\n", check, detail.c_str());
  std::abort();
}

// NOLINTNEXTLINE(cppcoreguidelines-macro-usage): the failing expression is printed.
#define CLUMPKIT_FUZZ_CHECK(cond, detail)                            \
  do {                                                               \
    if (!(cond)) ::clumpkit::fuzz::fail(#cond, std::string(detail)); \
  } while (0)

/// The CLI prints what() as one line: it must be non-empty and free of control characters.
inline void check_message(const InputError& e) {
  const std::string msg = e.what();
  CLUMPKIT_FUZZ_CHECK(!msg.empty(), "empty InputError message");
  for (unsigned char c : msg)
    CLUMPKIT_FUZZ_CHECK(c >= 0x20 && c != 0x7f, "control character in message: " + msg);
}

/// Runs `f`; an InputError is the expected outcome of bad input, everything else propagates.
template <class F>
void input_errors_only(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    check_message(e);
  }
}

inline std::string as_text(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace clumpkit::fuzz
