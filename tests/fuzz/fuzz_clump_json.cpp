// Fuzz target: clump templates (clumpkit-clump/1 JSON), as read by `clumpkit info` and every
// command that takes a template. An accepted template must survive a save/load round trip.
#include <cmath>

#include "clumpkit/geometry/clump_template.hpp"
#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace clumpkit;
  const std::string text = fuzz::as_text(data, size);
  fuzz::input_errors_only([&] {
    const ClumpTemplate c = parse_clump(text, "fuzz/clump.json");
    CLUMPKIT_FUZZ_CHECK(!c.spheres.empty(), "accepted a clump without spheres");
    for (const Sphere& s : c.spheres)
      CLUMPKIT_FUZZ_CHECK(s.center.allFinite() && std::isfinite(s.radius) && s.radius > 0.0,
                          "accepted an invalid sphere");
    CLUMPKIT_FUZZ_CHECK(c.mass.mass > 0.0 && c.mass.volume > 0.0, "mass, volume");
    CLUMPKIT_FUZZ_CHECK(std::abs(c.rotation.determinant() - 1.0) < 1e-3, "rotation");
    // What we accepted, we must be able to write and read back unchanged.
    const std::string saved = to_json(c).dump(2);
    ClumpTemplate back;
    try {
      back = parse_clump(saved, "fuzz/saved.json");
    } catch (const InputError& e) {
      fuzz::fail("round trip", e.what());
    }
    CLUMPKIT_FUZZ_CHECK(back.spheres.size() == c.spheres.size(), "round trip: spheres");
    for (size_t i = 0; i < c.spheres.size(); ++i)
      CLUMPKIT_FUZZ_CHECK(back.spheres[i].radius == c.spheres[i].radius &&
                              back.spheres[i].center == c.spheres[i].center,
                          "round trip: sphere " + std::to_string(i));
    CLUMPKIT_FUZZ_CHECK(to_json(back).dump(2) == saved, "round trip: not a fixed point");
  });
  return 0;
}
