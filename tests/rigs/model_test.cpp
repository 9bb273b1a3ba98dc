// Particle model files: the bundled models load, effects map onto the DEM contact laws (absent =
// absent), the mass basis scales mass and inertia, and bad files name file:line and key.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "clumpkit/core/error.hpp"
#include "clumpkit/geometry/clump_template.hpp"
#include "clumpkit/rigs/model.hpp"

namespace clumpkit {
namespace {

namespace fs = std::filesystem;
const fs::path kModels = fs::path(CLUMPKIT_SOURCE_DIR) / "shapes" / "models";

// A model file in the models folder (so "../pill_A.toml" resolves), parsed from text.
ParticleModel parse(const std::string& text) {
  return parse_model(text, kModels / "test_model.toml", fs::path(CLUMPKIT_SOURCE_DIR));
}

// The InputError message of `f()`, "" if it throws none.
template <class F>
std::string error_from(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string error_of(const std::string& text) {
  return error_from([&] { parse(text); });
}

const char* kHead = R"(
[model]
name = "t"
materials = "../materials.toml"
[[types]]
name = "A"
shape = "../pill_A.toml"
paper_spheres = 12
)";

TEST(Model, BundledPaperVariantsAndProductionLoad) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(kModels)) {
    if (e.path().extension() != ".toml") continue;
    const ParticleModel m = load_model(e.path());
    EXPECT_FALSE(m.types.empty()) << e.path();
    EXPECT_TRUE(m.effects.on("rolling_friction"));
    EXPECT_FALSE(m.effects.on("cohesion"));
    ++n;
  }
  EXPECT_EQ(n, 10);  // nine single-type variants and the production model
  const ParticleModel p = load_model(kModels / "production.toml");
  ASSERT_EQ(p.types.size(), 3u);
  EXPECT_NEAR(p.types[0].mass_fraction, 0.35, 1e-12);
  EXPECT_NEAR(p.types[2].mass_fraction, 0.30, 1e-12);
  EXPECT_TRUE(p.effects.size_distribution);
  const auto mix = p.mixture();
  EXPECT_EQ(mix[1].clump_type, "B");
}

TEST(Model, EffectsMapToPairLawsAndAbsentMeansAbsent) {
  ParticleModel m = parse(std::string(kHead) + R"(
[effects]
restitution = true
wall_friction = true
[effects.rolling_friction]
pill = 0.1
)");
  const auto laws = m.pair_contacts({"abs_plastic"});
  ASSERT_EQ(laws.size(), 2u);
  const auto& pp = laws[0].law;                  // pill-pill
  EXPECT_FALSE(pp.static_friction.has_value());  // particle_friction absent
  ASSERT_TRUE(pp.rolling.has_value());
  EXPECT_DOUBLE_EQ(pp.rolling->coefficient, 0.1);
  EXPECT_DOUBLE_EQ(*pp.restitution, 0.201);  // Table 1
  const auto& pw = laws[1].law;              // pill-ABS
  EXPECT_DOUBLE_EQ(*pw.static_friction, 0.577);
  EXPECT_DOUBLE_EQ(pw.rolling->coefficient, 0.120);  // not given: the library's value
  EXPECT_FALSE(pw.cohesion.has_value());

  set_model_effect(m, "effects.rolling_friction", "off", "--set");
  set_model_effect(m, "effects.cohesion", "2e4 J/m^3", "--set");
  set_model_effect(m, "effects.particle_friction", "0.3", "--set");
  const auto laws2 = m.pair_contacts({"abs_plastic"});
  EXPECT_FALSE(laws2[0].law.rolling.has_value());
  EXPECT_DOUBLE_EQ(laws2[0].law.cohesion->energy_density, 2e4);
  EXPECT_DOUBLE_EQ(*laws2[0].law.static_friction, 0.3);
  EXPECT_FALSE(laws2[1].law.cohesion.has_value());  // cohesion is pill-pill
  EXPECT_THROW(set_model_effect(m, "effects.stickiness", "1", "--set"), InputError);
  EXPECT_THROW(set_model_effect(m, "effects.restitution", "1.5", "--set"), InputError);
}

TEST(Model, MassBasisScalesMassAndInertiaTogether) {
  const ParticleModel u = parse(std::string(kHead) + "[effects]\nrestitution = true\n");
  std::string text = std::string(kHead) + "[effects]\nrestitution = true\n";
  text.replace(text.find("name = \"t\""), 10, "name = \"t\"\nmass_basis = \"true_shape\"");
  const ParticleModel t = parse(text);
  const auto cu = u.clump_types(4000), ct = t.clump_types(4000);
  const double cyl = 1380.0 * M_PI * 0.25 * 0.006 * 0.006 * 0.0054;
  EXPECT_NEAR(ct[0].clump.mass.mass, cyl, 1e-12);
  EXPECT_LT(cu[0].clump.mass.mass, 0.9 * cyl);  // the union is lighter than the cylinder
  const double f = ct[0].clump.mass.mass / cu[0].clump.mass.mass;
  EXPECT_NEAR(ct[0].clump.mass.principal_moments[2] / cu[0].clump.mass.principal_moments[2], f,
              1e-9);
}

// A type given as a clump template (from `clumpkit fill` of any mesh) still names its shape
// file, for the material and density: the union's mass is the template's volume at that
// density, whatever density the template was filled at. Without a shape file the error says why.
TEST(Model, AClumpTemplateTakesItsShapeFilesDensity) {
  const fs::path dir = fs::temp_directory_path() / "clumpkit_model_template_test";
  fs::create_directories(dir);
  {
    std::ofstream f(dir / "grain.toml");
    f << "[shape]\nkind = \"mesh\"\nfile = \"grain.stl\"\nunits = \"mm\"\n"
         "[material]\nname = \"pill\"\ndensity = \"1200 kg/m^3\"\n";
  }
  const std::string clump = CLUMPKIT_SOURCE_DIR "/tests/fuzz/corpus/clump_json/A4.json";
  const std::string head = "[model]\nname = \"g\"\nmaterials = \"" CLUMPKIT_SOURCE_DIR
                           "/shapes/materials.toml\"\n[[types]]\nname = \"G\"\n";
  const std::string tail = "clump = \"" + clump + "\"\n[effects]\nrestitution = true\n";
  const ParticleModel m =
      parse_model(head + "shape = \"grain.toml\"\n" + tail, dir / "g.toml", dir);
  const ClumpTemplate filled = load_clump(clump);  // filled at 1380 kg/m^3
  ASSERT_EQ(filled.mass.density, 1380.0);
  const auto types = m.clump_types(4000);
  const double volume = filled.mass.mass / filled.mass.density;
  EXPECT_NEAR(types[0].clump.mass.mass, volume * 1200.0, 1e-12 * volume * 1200.0);
  EXPECT_NEAR(types[0].clump.mass.principal_moments[0] / filled.mass.principal_moments[0],
              1200.0 / 1380.0, 1e-12);
  const std::string e = error_from([&] { parse_model(head + tail, dir / "g.toml", dir); });
  EXPECT_NE(e.find("types.0.shape"), std::string::npos) << e;
  EXPECT_NE(e.find("shape file"), std::string::npos) << e;
  EXPECT_NE(e.find("clump template"), std::string::npos) << e;
  fs::remove_all(dir);
}

// shape_resolution on a type given as a clump template: its shape filled again by the optimiser
// at that count, at the shape file's density, the same bits every time (a rig run's model).
TEST(Model, AClumpTemplateAtAnotherResolutionIsFilledAgainByTheOptimiser) {
  const fs::path dir = fs::temp_directory_path() / "clumpkit_model_refill_test";
  fs::create_directories(dir);
  const ParticleModel m = parse_model(
      "[model]\nname = \"t\"\nmaterials = \"" CLUMPKIT_SOURCE_DIR
      "/shapes/materials.toml\"\n[[types]]\nname = \"T\"\nshape = \"" CLUMPKIT_SOURCE_DIR
      "/shapes/pill_A.toml\"\nclump = \"" CLUMPKIT_SOURCE_DIR
      "/tests/fuzz/corpus/clump_json/A4.json\"\n[effects]\nshape_resolution = { spheres = 8 "
      "}\n",
      dir / "t.toml", dir);
  const auto a = m.clump_types(20000), b = m.clump_types(20000);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].clump.spheres.size(), 8u);
  EXPECT_EQ(a[0].clump.method.value("name", ""), "optimal");
  EXPECT_EQ(a[0].clump.mass.density, 1380.0);  // pill_A.toml's
  for (size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(a[0].clump.spheres[i].center, b[0].clump.spheres[i].center) << i;
    EXPECT_EQ(a[0].clump.spheres[i].radius, b[0].clump.spheres[i].radius) << i;
  }
  // 8 optimised spheres hold more of the pill than the paper's 4 (0.673 of the cylinder) and
  // stay inside it but for the fill's tolerance.
  const double cylinder = M_PI * 0.25 * 0.006 * 0.006 * 0.0054;
  EXPECT_GT(a[0].clump.mass.volume, 0.70 * cylinder);
  EXPECT_LT(a[0].clump.mass.volume, 1.02 * cylinder);
  EXPECT_NE(m.summary().find("8-sphere (optimiser)"), std::string::npos) << m.summary();
  // A mesh shape's bytes are part of the model (cached runs of its refills go when it changes).
  {
    std::ofstream(dir / "g.stl") << "solid g\nendsolid g\n";
    std::ofstream(dir / "g.toml") << "[shape]\nkind = \"mesh\"\nfile = \"g.stl\"\n"
                                     "[material]\ndensity = \"1200 kg/m^3\"\n";
  }
  const std::string text = "[model]\nname = \"g\"\nmaterials = \"" CLUMPKIT_SOURCE_DIR
                           "/shapes/materials.toml\"\n[[types]]\nname = \"G\"\nshape = "
                           "\"g.toml\"\nclump = \"" CLUMPKIT_SOURCE_DIR
                           "/tests/fuzz/corpus/clump_json/A4.json\"\n[effects]\nrestitution = "
                           "true\n";
  const std::string before = model_fingerprint(parse_model(text, dir / "g_model.toml", dir));
  std::ofstream(dir / "g.stl") << "solid g2\nendsolid g2\n";
  EXPECT_NE(model_fingerprint(parse_model(text, dir / "g_model.toml", dir)), before);
  fs::remove_all(dir);
}

// A height spread (size_distribution): each type becomes three height classes whose
// mass-weighted heights have the type's height as mean and the spread as relative std, each filled
// by the type's paper rule so that its outer spheres touch its own end faces.
TEST(Model, AHeightSpreadIsThreeHeightClassesWithTheSpreadsMoments) {
  const ParticleModel m = parse(std::string(kHead) + R"(
[effects]
size_distribution = { height_spread = 0.1 }
)");
  EXPECT_TRUE(m.effects.size_distribution);
  EXPECT_DOUBLE_EQ(m.effects.height_spread, 0.1);
  const double h = m.types.front().shape.height;
  const auto pop = m.population();
  ASSERT_EQ(pop.size(), 3u);
  EXPECT_EQ(pop[0].name, "A_short");
  EXPECT_EQ(pop[1].name, "A");
  EXPECT_EQ(pop[2].name, "A_tall");
  double f = 0, mean = 0, second = 0;
  for (const auto& t : pop) {
    f += t.mass_fraction;
    mean += t.mass_fraction * t.shape.height;
    second += t.mass_fraction * t.shape.height * t.shape.height;
  }
  EXPECT_NEAR(f, 1.0, 1e-12);
  EXPECT_NEAR(mean, h, 1e-12 * h);
  EXPECT_NEAR(std::sqrt(second - mean * mean) / h, 0.1, 1e-9);

  const auto clumps = m.clump_types(2000);
  const auto mix = m.mixture();
  ASSERT_EQ(clumps.size(), 3u);
  ASSERT_EQ(mix.size(), 3u);
  double last_mass = 0;
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(clumps[i].name, pop[i].name);
    EXPECT_EQ(mix[i].clump_type, pop[i].name);
    const auto& spheres = clumps[i].clump.spheres;
    EXPECT_EQ(spheres.size(), 12u) << pop[i].name;  // the type's rule in every class
    // The flat regime's 12-sphere rule: two layers whose spheres, of radius H / 3, touch the end
    // faces of the class's own height H.
    for (const auto& s : spheres)
      EXPECT_NEAR(s.radius, pop[i].shape.height / 3, 1e-12) << pop[i].name;
    EXPECT_GT(clumps[i].clump.mass.mass, last_mass) << pop[i].name;
    last_mass = clumps[i].clump.mass.mass;
  }
  // The tall class of pill A (H 5.4 mm at D 6 mm: flat) is taller than wide, yet keeps the flat
  // regime's 12-sphere rule (2 layers of 6), not the tall one's.
  EXPECT_GT(pop[2].shape.height, pop[2].shape.diameter);

  // Without a spread the population is the types.
  EXPECT_EQ(parse(std::string(kHead) + "[effects]\nsize_distribution = true\n").population().size(),
            1u);
}

TEST(Model, AHeightSpreadIsSetFromTheCommandLineAndItsErrorsNameTheKey) {
  ParticleModel m = parse(kHead);
  EXPECT_FALSE(m.effects.size_distribution);
  set_model_effect(m, "effects.size_distribution", "0.05", "--set");
  EXPECT_TRUE(m.effects.size_distribution);
  EXPECT_DOUBLE_EQ(m.effects.height_spread, 0.05);
  set_model_effect(m, "effects.size_distribution.height_spread", "0.08", "--set");
  EXPECT_DOUBLE_EQ(m.effects.height_spread, 0.08);
  set_model_effect(m, "effects.size_distribution", "on", "--set");  // keeps the spread
  EXPECT_DOUBLE_EQ(m.effects.height_spread, 0.08);
  set_model_effect(m, "effects.size_distribution", "off", "--set");
  EXPECT_FALSE(m.effects.size_distribution);
  EXPECT_EQ(m.effects.height_spread, 0.0);
  auto set_error = [&](const std::string& key, const std::string& value) {
    return error_from([&] { set_model_effect(m, key, value, "--set"); });
  };
  EXPECT_NE(set_error("effects.size_distribution", "0.5").find("0.3"), std::string::npos);
  EXPECT_NE(set_error("effects.size_distribution", "-0.1").find("size_distribution"),
            std::string::npos);
  EXPECT_NE(set_error("effects.size_distribution.width", "0.1").find("height_spread"),
            std::string::npos);

  std::string e = error_of(std::string(kHead) + R"(
[effects.size_distribution]
height_spread = 0.45
)");
  EXPECT_NE(e.find("effects.size_distribution.height_spread"), std::string::npos) << e;
  e = error_of(std::string(kHead) + R"(
[effects.size_distribution]
spread = 0.1
)");
  EXPECT_NE(e.find("effects.size_distribution.spread"), std::string::npos) << e;
  EXPECT_NE(e.find("height_spread"), std::string::npos) << e;
  // A type given as a clump template has no rule to refill its height classes with.
  e = error_of(std::string(R"(
[model]
name = "t"
materials = "../materials.toml"
[[types]]
name = "A"
shape = "../pill_A.toml"
clump = ")") + CLUMPKIT_SOURCE_DIR +
               R"(/tests/fuzz/corpus/clump_json/A4.json"
[effects]
size_distribution = { height_spread = 0.1 }
)");
  EXPECT_NE(e.find("effects.size_distribution.height_spread"), std::string::npos) << e;
  EXPECT_NE(e.find("clump template"), std::string::npos) << e;
}

TEST(Model, ATypesMassFractionIsSetFromTheCommandLineTheOthersKeepTheirRatios) {
  ParticleModel m = load_model(kModels / "production.toml");  // A, B, C at 35/35/30 %
  set_model_effect(m, "effects.size_distribution.C", "0.6", "--set");
  EXPECT_EQ(m.types[2].mass_fraction, 0.6);
  EXPECT_NEAR(m.types[0].mass_fraction, 0.2, 1e-15);  // 0.35 * 0.4 / 0.7
  EXPECT_NEAR(m.types[1].mass_fraction, 0.2, 1e-15);
  EXPECT_TRUE(m.effects.size_distribution);
  // The population (the factory's mixture) follows.
  double c_share = 0.0;
  for (const auto& t : m.population())
    if (t.name == "C") c_share += t.mass_fraction;
  EXPECT_NEAR(c_share, 0.6, 1e-15);
  auto set_error = [&](const std::string& key, const std::string& value) {
    return error_from([&] { set_model_effect(m, key, value, "--set"); });
  };
  std::string e = set_error("effects.size_distribution.D", "0.5");
  EXPECT_NE(e.find("--set"), std::string::npos) << e;
  EXPECT_NE(e.find("A, B, C"), std::string::npos) << e;
  for (const char* bad : {"1", "0", "1.5", "-0.2", "half"}) {
    e = set_error("effects.size_distribution.A", bad);
    EXPECT_NE(e.find("effects.size_distribution.A"), std::string::npos) << bad << ": " << e;
  }
  EXPECT_NEAR(m.types[2].mass_fraction, 0.6, 1e-15);  // a refused value changes nothing
  // One type has no shares to set.
  ParticleModel one = parse(kHead);
  e = error_from([&] { set_model_effect(one, "effects.size_distribution.A", "0.5", "--set"); });
  EXPECT_NE(e.find("several types"), std::string::npos) << e;
}

TEST(Model, ErrorsNameFileLineAndKey) {
  std::string e = error_of(std::string(kHead) + "[effects]\nstickiness = true\n");
  EXPECT_NE(e.find("test_model.toml"), std::string::npos) << e;
  EXPECT_NE(e.find("effects.stickiness"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown effect"), std::string::npos) << e;

  e = error_of(std::string(kHead) + "[effects.rolling_friction]\npill = -0.1\n");
  EXPECT_NE(e.find("test_model.toml:10"), std::string::npos) << e;
  EXPECT_NE(e.find("effects.rolling_friction.pill"), std::string::npos) << e;

  e = error_of(std::string(kHead) + "[effects.wall_friction]\nunobtainium = 0.3\n");
  EXPECT_NE(e.find("unobtainium"), std::string::npos) << e;

  e = error_of(R"(
[model]
mass_basis = "weighed"
[[types]]
name = "A"
shape = "../pill_A.toml"
paper_spheres = 12
)");
  EXPECT_NE(e.find("test_model.toml:3"), std::string::npos) << e;
  EXPECT_NE(e.find("model.mass_basis"), std::string::npos) << e;

  e = error_of(R"(
[[types]]
name = "A"
shape = "../pill_A.toml"
)");
  EXPECT_NE(e.find("paper_spheres"), std::string::npos) << e;

  e = error_of(R"(
[[types]]
name = "A"
shape = "../no_such_pill.toml"
paper_spheres = 12
)");
  EXPECT_NE(e.find("types.0.shape"), std::string::npos) << e;
  EXPECT_NE(e.find("not found"), std::string::npos) << e;

  // Two types without size_distribution: the population would silently have one size.
  e = error_of(std::string(kHead) + R"(
[[types]]
name = "B"
shape = "../pill_B.toml"
paper_spheres = 12
)");
  EXPECT_NE(e.find("size_distribution"), std::string::npos) << e;

  e = error_of("[modle]\nname = \"x\"\n");
  EXPECT_NE(e.find("modle"), std::string::npos) << e;
}

}  // namespace
}  // namespace clumpkit
