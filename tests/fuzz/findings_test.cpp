// What fuzzing and the bad-input catalogue found, one test per finding, asserting the fixed
// behaviour directly (docs/hardening.md lists them). The raw crashing inputs are also replayed
// from regressions/<target>/ by the fuzz_<target>_replay tests.
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "clumpkit/core/error.hpp"
#include "clumpkit/core/units.hpp"
#include "clumpkit/geometry/clump_template.hpp"

namespace clumpkit {
namespace {

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

const char* kValidBody = R"(
  "spheres": [[0, 0, 0, 1e-3]],
  "frame": {"rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "translation": [0, 0, 0]},
  "format": "clumpkit-clump/1")";

// Appended piece by piece: GCC 12 at -O1 reports a false -Warray-bounds inside std::string for
// the chain std::string("{") + literal + ... (GCC bug 105651).
std::string clump_with_mass_properties(const std::string& extra) {
  std::string s = "{";
  s += kValidBody;
  s += R"(,
  "mass_properties": {"density": 1000, "volume": 4.2e-9, "mass": 4.2e-6,
    "center_of_mass": [0, 0, 0], "inertia_tensor": [[1e-12, 0, 0], [0, 1e-12, 0], [0, 0, 1e-12]],
    "principal_moments": [1e-12, 1e-12, 1e-12])";
  s += extra;
  s += "}}";
  return s;
}

// fuzz_units (unit_factor): a tab (or newline) in a unit reached the one-line CLI message
// unescaped.
TEST(FuzzFindings, ControlCharactersInMessagesAreEscaped) {
  const std::string m = message_of([] { unit_factor("3\tg", Dimension::Mass, "f.toml:1", "m"); });
  EXPECT_EQ(m, "f.toml:1: m: unknown unit '3\\tg' (expected a mass in kg)");
  EXPECT_EQ(std::string(InputError("a\nb.toml", "k\x01", "x\ny\x7f").what()),
            "a\\nb.toml: k\\x01: x\\ny\\x7f");
}

// fuzz_clump_json: nlohmann::json throws out_of_range (not parse_error) for 1e999; it escaped as
// an internal error (exit 1).
TEST(FuzzFindings, JsonNumberOverflowIsAnInputError) {
  EXPECT_NE(message_of([] {
              parse_clump(R"({"spheres": [[1e999, 0, 0, 1]]})", "c.json");
            }).find("c.json: not valid JSON"),
            std::string::npos);
}

// Review while writing the units fuzzer: a finite number times its unit factor could overflow.
TEST(FuzzFindings, QuantityOverflowingInSiIsRejected) {
  EXPECT_THROW(parse_quantity("1e308 g/cm^3", Dimension::Density), InputError);
  EXPECT_DOUBLE_EQ(parse_quantity("1e300 g/cm^3", Dimension::Density), 1e303);
}

// fuzz_clump_json round trip: free-form members of the wrong JSON type made nlohmann::json throw
// type_error while loading or saving a template (exit 1 instead of 2).
TEST(FuzzFindings, MistypedTemplateMembersAreInputErrors) {
  EXPECT_NO_THROW(parse_clump(clump_with_mass_properties(""), "c.json"));
  EXPECT_EQ(
      message_of([] { parse_clump(clump_with_mass_properties(R"(, "method": 5)"), "c.json"); }),
      "c.json: mass_properties.method: expected an object");
  EXPECT_EQ(
      message_of([] { parse_clump(clump_with_mass_properties(R"(, "basis": [1])"), "c.json"); }),
      "c.json: mass_properties.basis: expected a string");
  EXPECT_EQ(message_of([] {
              parse_clump(clump_with_mass_properties(R"(, "method": {"basis": 2})"), "c.json");
            }),
            "c.json: mass_properties.basis: expected a string");
  EXPECT_EQ(message_of([] {
              parse_clump(clump_with_mass_properties(R"(, "ci95": {"volume": "x"})"), "c.json");
            }),
            "c.json: mass_properties.ci95.volume: expected a number");
}

// fuzz_clump_json round trip: a template without a mass basis was saved with the default basis
// but loaded without it, so save(load(save(x))) differed from save(x).
TEST(FuzzFindings, SaveLoadSaveIsAFixedPoint) {
  const ClumpTemplate c =
      parse_clump(clump_with_mass_properties(R"(, "method": {"rays": 1})"), "c");
  EXPECT_EQ(c.mass_method.value("basis", ""), "sphere_union");
  const std::string saved = to_json(c).dump(2);
  EXPECT_EQ(to_json(parse_clump(saved, "saved")).dump(2), saved);
}

// Deep nesting made copying and printing a template recurse without bound.
TEST(FuzzFindings, DeepJsonNestingIsRejected) {
  EXPECT_EQ(message_of([] { parse_clump(std::string(100000, '['), "c.json"); }),
            "c.json: JSON nested deeper than 64");
}

}  // namespace
}  // namespace clumpkit
