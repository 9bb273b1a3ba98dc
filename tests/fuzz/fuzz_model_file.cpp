// Fuzz target: particle model files (shapes/models/*.toml) through parse_model, read as if the
// file lay in shapes/models/ of the source tree (so "../pill_A.toml" and "../materials.toml"
// resolve to the bundled files). An accepted model's promises are checked, and the cheap
// derived views (summary, mixture, the pair contact laws) must work or report an InputError.
#include <cmath>

#include "clumpkit/rigs/model.hpp"
#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace clumpkit;
  const std::string text = fuzz::as_text(data, size);
  const std::filesystem::path src(CLUMPKIT_SOURCE_DIR);
  fuzz::input_errors_only([&] {
    const ParticleModel m = parse_model(text, src / "shapes" / "models" / "fuzz.toml", src);
    CLUMPKIT_FUZZ_CHECK(!m.types.empty(), "accepted a model without types");
    CLUMPKIT_FUZZ_CHECK(m.materials.has("pill"), "accepted a model without material 'pill'");
    double sum = 0.0;
    for (const ModelType& t : m.types) {
      CLUMPKIT_FUZZ_CHECK(!t.name.empty(), "type without a name");
      CLUMPKIT_FUZZ_CHECK(
          std::isfinite(t.mass_fraction) && t.mass_fraction > 0.0 && t.mass_fraction <= 1.0 + 1e-12,
          "mass fraction of " + t.name);
      CLUMPKIT_FUZZ_CHECK(t.paper_spheres || !t.clump_path.empty() || m.effects.shape_resolution,
                          "type " + t.name + " has neither a sphere count nor a clump file");
      if (m.mass_basis == MassBasis::kGiven)
        CLUMPKIT_FUZZ_CHECK(t.given_mass && std::isfinite(*t.given_mass) && *t.given_mass > 0.0,
                            "given mass of " + t.name);
      sum += t.mass_fraction;
    }
    CLUMPKIT_FUZZ_CHECK(std::abs(sum - 1.0) < 1e-9, "mass fractions do not sum to 1");
    for (const dem::MixtureEntry& e : m.mixture())
      CLUMPKIT_FUZZ_CHECK(e.mass_fraction >= 0.0 && e.mass_fraction <= 1.0 + 1e-12, "mixture");
    CLUMPKIT_FUZZ_CHECK(!m.summary().empty(), "empty summary");
    fuzz::input_errors_only([&] {
      for (const dem::PairContactOverride& o : m.pair_contacts({"galvanized_steel"}))
        o.law.validate("fuzz", "pair");
    });
  });
  return 0;
}
