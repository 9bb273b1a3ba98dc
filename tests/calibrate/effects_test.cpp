// The diagnosis's candidate effects on real model files: a candidate at its baseline value is the
// baseline model itself (the diagnosis uses the baseline's run as the candidate's point there),
// per-material values move together with the fitted one, and uniform baselines stay uniform.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <random>

#include "clumpkit/calibrate/effects.hpp"
#include "clumpkit/rigs/model.hpp"

namespace clumpkit::calibrate {
namespace {

namespace fs = std::filesystem;
const fs::path kModels = fs::path(CLUMPKIT_SOURCE_DIR) / "shapes" / "models";

EffectCandidate find(const std::vector<EffectCandidate>& cs, const std::string& effect) {
  for (const auto& c : cs)
    if (c.effect == effect) return c;
  throw std::runtime_error("no candidate " + effect);
}

// The per-partner values an effect holds in a model.
std::map<std::string, double> partners(const ParticleModel& m, const std::string& effect) {
  const auto& fx = m.effects;
  const auto& slot = effect == "rolling_friction" ? fx.rolling_friction
                     : effect == "wall_friction"  ? fx.wall_friction
                                                  : fx.restitution;
  if (!slot) throw std::runtime_error(effect + " is absent");
  return *slot;
}

const char* const kPerPartner[] = {"rolling_friction", "wall_friction", "restitution"};

TEST(EffectCandidates, AtItsBaselineValueEveryCandidateIsTheBaselineModel) {
  // The production model holds Table 1's values: pill-wall rolling friction, friction and
  // restitution differ by wall material. Before session 39 a candidate set every partner to the
  // one fitted value, so at the baseline value it was another model (ABS's rolling friction 0.08
  // instead of 0.12) and the diagnosis's line through the baseline's run was off.
  const ParticleModel base = load_model(kModels / "production.toml");
  const std::string want = model_fingerprint(base);
  const auto cs = effect_candidates(base, {}, nullptr);
  int continuous = 0;
  for (const auto& c : cs) {
    if (c.discrete || !base.effects.on(c.effect)) continue;  // cohesion: absent, not held at 0
    ++continuous;
    EXPECT_EQ(model_fingerprint(c.apply(base, c.baseline)), want) << c.effect;
  }
  EXPECT_GE(continuous, 5);  // rolling, particle and wall friction, restitution, size distribution
  for (const char* e : kPerPartner)
    EXPECT_NE(find(cs, e).parameter.find("move with it"), std::string::npos) << e;
}

TEST(EffectCandidates, WithoutGalvanizedSteelWallFrictionIsTheFirstWallsValue) {
  ParticleModel base = load_model(kModels / "production.toml");
  base.effects.wall_friction =
      std::map<std::string, double>{{"abs_plastic", 0.6}, {"organic_glass", 0.4}};
  const EffectCandidate c =
      find(effect_candidates(base, {"wall_friction"}, nullptr), "wall_friction");
  EXPECT_EQ(c.baseline, 0.6);
  EXPECT_NE(c.parameter.find("pill-abs_plastic"), std::string::npos) << c.parameter;
  EXPECT_EQ(model_fingerprint(c.apply(base, c.baseline)), model_fingerprint(base));
  EXPECT_EQ(partners(c.apply(base, 0.9), "wall_friction").at("abs_plastic"), 0.9);
}

TEST(EffectCandidates, PartnerValuesMoveWithTheFittedOneInsideTheRange) {
  const ParticleModel base = load_model(kModels / "production.toml");
  const auto cs = effect_candidates(base, {}, nullptr);
  std::mt19937_64 rng(39);
  for (const char* e : kPerPartner) {
    const EffectCandidate c = find(cs, e);
    const std::string ref = std::string(e) == "wall_friction" ? "galvanized_steel" : "pill";
    const auto held = partners(base, e);
    std::uniform_real_distribution<double> u(c.lo, c.hi);
    for (int i = 0; i < 50; ++i) {
      double x = u(rng), y = u(rng);
      if (x > y) std::swap(x, y);
      const auto px = partners(c.apply(base, x), e);
      const auto py = partners(c.apply(base, y), e);
      ASSERT_EQ(px.size(), held.size()) << e;
      EXPECT_EQ(px.at(ref), x) << e;  // the parameter is the reference partner's value
      ASSERT_TRUE(c.partners) << e;
      EXPECT_EQ(c.partners(x), px) << e;  // what the JSON reports is what the model gets
      for (const auto& [p, v] : px) {
        EXPECT_GE(v, c.lo) << e << " " << p;
        EXPECT_LE(v, c.hi) << e << " " << p;
        EXPECT_LE(v, py.at(p)) << e << " " << p << ": " << x << " -> " << y;
        // Above the baseline a partner held higher stays higher (and lower, lower).
        if (x > c.baseline && p != ref) {
          EXPECT_EQ(v > x, held.at(p) > c.baseline) << e << " " << p << " at " << x;
        }
      }
    }
    // The range's ends are the same for every partner, bit for bit (a refinement pinned at a
    // bound then runs the model a uniform baseline's candidate runs there).
    for (const auto& [p, v] : partners(c.apply(base, c.hi), e)) EXPECT_EQ(v, c.hi) << p;
    for (const auto& [p, v] : partners(c.apply(base, c.lo), e)) EXPECT_EQ(v, c.lo) << p;
  }
}

TEST(EffectCandidates, AUniformOrAbsentBaselineGivesUniformVariants) {
  // Every partner at the same value (the calibration loops' models): each variant sets every
  // partner to the fitted value exactly, as before per-partner values moved (so their cached runs
  // keep their keys). An absent effect is switched on at one value for every partner.
  const ParticleModel table1 = load_model(kModels / "production.toml");
  ParticleModel uniform = table1;
  set_model_effect(uniform, "effects.rolling_friction", "0.05", "test");
  ParticleModel absent = table1;
  set_model_effect(absent, "effects.restitution", "off", "test");
  for (const auto& [m, e] : {std::pair{uniform, "rolling_friction"}, {absent, "restitution"}}) {
    const EffectCandidate c = find(effect_candidates(m, {e}, nullptr), e);
    EXPECT_EQ(c.parameter.find("move with it"), std::string::npos) << e;
    EXPECT_FALSE(c.partners) << e;
    for (double x : {c.lo, 0.1234567890123, c.probe, c.hi}) {
      ParticleModel set = m;
      set_model_effect(set, std::string("effects.") + e, fmt::format("{:.17g}", x), "test");
      EXPECT_EQ(model_fingerprint(c.apply(m, x)), model_fingerprint(set)) << e << " " << x;
    }
  }
}

TEST(EffectCandidates, ShapeResolutionOfAClumpTemplateIsTheOptimisersLadder) {
  // A paper-rule model keeps its rule's presets (the flat pill A: 4, 12, 20).
  const ParticleModel a12 = load_model(kModels / "paper_A12.toml");
  const EffectCandidate paper =
      find(effect_candidates(a12, {"shape_resolution"}, nullptr), "shape_resolution");
  EXPECT_EQ(paper.baseline, 12);
  EXPECT_EQ(paper.levels, (std::vector<double>{4, 20}));
  // A type given as a clump template (a 4-sphere pill A from `clumpkit fill`) is filled again by
  // the optimiser at 2, 4, 8, 16, 32 spheres, less its own count. Before session 43 the
  // candidate was skipped ("a type uses a clump template").
  const fs::path dir = fs::temp_directory_path() / "clumpkit_effects_template_test";
  fs::create_directories(dir);
  const std::string head =
      "[model]\nname = \"t\"\nmaterials = \"" CLUMPKIT_SOURCE_DIR "/shapes/materials.toml\"\n";
  const std::string templ = "[[types]]\nname = \"T\"\nshape = \"" CLUMPKIT_SOURCE_DIR
                            "/shapes/pill_A.toml\"\nclump = \"" CLUMPKIT_SOURCE_DIR
                            "/tests/fuzz/corpus/clump_json/A4.json\"\nmass_fraction = 0.5\n";
  const ParticleModel t =
      parse_model(head + templ + "[effects]\nrestitution = true\n", dir / "t.toml", dir);
  const EffectCandidate opt =
      find(effect_candidates(t, {"shape_resolution"}, nullptr), "shape_resolution");
  EXPECT_EQ(opt.baseline, 4);
  EXPECT_EQ(opt.levels, (std::vector<double>{2, 8, 16, 32}));
  EXPECT_NE(opt.parameter.find("optimiser"), std::string::npos) << opt.parameter;
  // Both in one model: the counts both can take (4), less the current 12.
  const ParticleModel mixed =
      parse_model(head +
                      "[[types]]\nname = \"A\"\nshape = \"" CLUMPKIT_SOURCE_DIR
                      "/shapes/pill_A.toml\"\npaper_spheres = 12\nmass_fraction = 0.5\n" +
                      templ + "[effects]\nrestitution = true\nsize_distribution = true\n",
                  dir / "m.toml", dir);
  const EffectCandidate both =
      find(effect_candidates(mixed, {"shape_resolution"}, nullptr), "shape_resolution");
  EXPECT_EQ(both.baseline, 12);
  EXPECT_EQ(both.levels, (std::vector<double>{4}));
  fs::remove_all(dir);
}

TEST(EffectCandidates, AMixturesFractionIsItsFirstTypesShareWithTheOthersInTheirRatios) {
  // The production model: A, B, C at 35/35/30 % by mass. Before session 44 only the height
  // spread was a size_distribution candidate; the types' shares were fixed by the model file.
  const ParticleModel prod = load_model(kModels / "production.toml");
  std::vector<std::string> skipped;
  const auto cs = effect_candidates(prod, {"size_distribution"}, &skipped);
  ASSERT_EQ(cs.size(), 2u);  // the mass fraction, then the height spread
  const EffectCandidate& f = cs[0];
  EXPECT_NE(f.parameter.find("mass fraction of type A"), std::string::npos) << f.parameter;
  EXPECT_EQ(f.baseline, 0.35);
  EXPECT_FALSE(f.discrete);
  EXPECT_GT(f.lo, 0.0);
  EXPECT_LT(f.hi, 1.0);
  EXPECT_NE(cs[1].parameter.find("height spread"), std::string::npos);
  const ParticleModel half = f.apply(prod, 0.5);
  EXPECT_EQ(half.types[0].mass_fraction, 0.5);
  EXPECT_NEAR(half.types[1].mass_fraction, 0.5 * 35.0 / 65.0, 1e-15);
  EXPECT_NEAR(half.types[2].mass_fraction, 0.5 * 30.0 / 65.0, 1e-15);
  double sum = 0.0;
  for (const auto& t : half.types) sum += t.mass_fraction;
  EXPECT_NEAR(sum, 1.0, 1e-15);
  EXPECT_NE(model_fingerprint(half), model_fingerprint(prod));
  // The candidate's run at the baseline's share is the baseline model (the same cache key).
  EXPECT_EQ(model_fingerprint(f.apply(prod, f.baseline)), model_fingerprint(prod));
  // One type has no shares to fit: only the height spread is tried.
  const auto one =
      effect_candidates(load_model(kModels / "paper_A12.toml"), {"size_distribution"}, nullptr);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_NE(one[0].parameter.find("height spread"), std::string::npos);
}

}  // namespace
}  // namespace clumpkit::calibrate
