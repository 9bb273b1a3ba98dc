// Fuzz target: quantities with units ("6.0 mm") as written in every human-edited file.
// Input: first byte selects the Dimension, the rest is the text.
#include <cmath>

#include "clumpkit/core/units.hpp"
#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace clumpkit;
  if (size == 0) return 0;
  constexpr int kDimensions = static_cast<int>(Dimension::MassFlow) + 1;
  const auto dim = static_cast<Dimension>(data[0] % kDimensions);
  const std::string text = fuzz::as_text(data + 1, size - 1);
  fuzz::input_errors_only([&] {
    const double v = parse_quantity(text, dim, "fuzz.toml:1", "value");
    CLUMPKIT_FUZZ_CHECK(std::isfinite(v), "accepted a non-finite quantity: " + text);
  });
  fuzz::input_errors_only([&] {
    const double f = unit_factor(text, dim, "fuzz.toml:1", "units");
    CLUMPKIT_FUZZ_CHECK(std::isfinite(f) && f > 0.0, "bad unit factor for: " + text);
  });
  return 0;
}
