// Fuzz target: lab measurement CSV (examples/lab_template.csv) through parse_measurements. An
// accepted file's promises are checked, and formatting it back and reading that again gives the
// same measurements (format_measurements writes what `clumpkit synth` produces).
#include <algorithm>
#include <cmath>
#include <set>

#include "clumpkit/calibrate/measurements.hpp"
#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace clumpkit;
  const std::string text = fuzz::as_text(data, size);
  fuzz::input_errors_only([&] {
    const std::vector<Measurement> ms = parse_measurements(text, "fuzz/lab.csv");
    CLUMPKIT_FUZZ_CHECK(!ms.empty(), "accepted a file without measurements");
    std::set<std::string> keys;
    for (const Measurement& m : ms) {
      CLUMPKIT_FUZZ_CHECK(std::isfinite(m.value), "value not finite: " + m.key());
      CLUMPKIT_FUZZ_CHECK(std::isfinite(m.std) && m.std > 0.0, "std not finite > 0: " + m.key());
      CLUMPKIT_FUZZ_CHECK(m.n >= 1, "n < 1");
      CLUMPKIT_FUZZ_CHECK(keys.insert(m.key()).second, "duplicate accepted: " + m.key());
    }
    const std::vector<Measurement> again = parse_measurements(format_measurements(ms), "again");
    CLUMPKIT_FUZZ_CHECK(again.size() == ms.size(), "round trip changed the count");
    for (size_t i = 0; i < ms.size(); ++i) {
      CLUMPKIT_FUZZ_CHECK(again[i].key() == ms[i].key(), "round trip changed " + ms[i].key());
      CLUMPKIT_FUZZ_CHECK(
          std::abs(again[i].value - ms[i].value) <= 1e-9 * std::max(1.0, std::abs(ms[i].value)),
          "round trip changed the value of " + ms[i].key());
      CLUMPKIT_FUZZ_CHECK(again[i].n == ms[i].n, "round trip changed n");
    }
  });
  return 0;
}
