// Fuzz target: material libraries (shapes/materials.toml).
#include <cmath>

#include "clumpkit/core/materials.hpp"
#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace clumpkit;
  const std::string text = fuzz::as_text(data, size);
  fuzz::input_errors_only([&] {
    const MaterialLibrary lib = MaterialLibrary::parse(text, "fuzz/materials.toml");
    const std::vector<std::string> names = lib.names();
    CLUMPKIT_FUZZ_CHECK(!names.empty(), "accepted a library without materials");
    for (const std::string& a : names) {
      const Material& m = lib.get(a);
      CLUMPKIT_FUZZ_CHECK(std::isfinite(m.density) && m.density > 0.0, a);
      CLUMPKIT_FUZZ_CHECK(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5, a);
      CLUMPKIT_FUZZ_CHECK(std::isfinite(m.youngs_modulus) && m.youngs_modulus > 0.0, a);
      CLUMPKIT_FUZZ_CHECK(std::isfinite(m.shear_modulus()) && m.shear_modulus() > 0.0, a);
      for (const std::string& b : names) {
        if (!lib.has_interaction(a, b)) continue;
        const Interaction& i = lib.interaction(b, a);  // symmetric
        CLUMPKIT_FUZZ_CHECK(i.restitution > 0.0 && i.restitution <= 1.0, a + "/" + b);
        CLUMPKIT_FUZZ_CHECK(i.static_friction >= 0.0 && i.rolling_friction >= 0.0, a + "/" + b);
      }
    }
    // Asking for an unknown material is an input error, never anything else.
    fuzz::input_errors_only([&] { lib.get("no such material \x01", "fuzz", "material"); });
  });
  return 0;
}
