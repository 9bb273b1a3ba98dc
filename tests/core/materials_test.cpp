#include "clumpkit/core/materials.hpp"

#include <gtest/gtest.h>

#include "clumpkit/core/error.hpp"

using namespace clumpkit;

TEST(Materials, BundledFileEqualsPaperTable1) {
  const MaterialLibrary file = MaterialLibrary::load(CLUMPKIT_SOURCE_DIR "/shapes/materials.toml");
  const MaterialLibrary ref = MaterialLibrary::paper_table1();
  for (const std::string& name : ref.names()) {
    const Material& a = file.get(name);
    const Material& b = ref.get(name);
    EXPECT_DOUBLE_EQ(a.density, b.density) << name;
    EXPECT_DOUBLE_EQ(a.poisson_ratio, b.poisson_ratio) << name;
    EXPECT_DOUBLE_EQ(a.youngs_modulus, b.youngs_modulus) << name;
    const Interaction& ia = file.interaction("pill", name);
    const Interaction& ib = ref.interaction(name, "pill");
    EXPECT_DOUBLE_EQ(ia.restitution, ib.restitution) << name;
    EXPECT_DOUBLE_EQ(ia.static_friction, ib.static_friction) << name;
    EXPECT_DOUBLE_EQ(ia.rolling_friction, ib.rolling_friction) << name;
  }
  EXPECT_EQ(file.names().size(), ref.names().size());
}

TEST(Materials, UnknownMaterialListsKnownOnes) {
  const MaterialLibrary lib = MaterialLibrary::paper_table1();
  try {
    lib.get("steel", "scene.toml:4", "walls.0.material");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(
        std::string(e.what()).find("scene.toml:4: walls.0.material: unknown material 'steel'"),
        std::string::npos);
    EXPECT_NE(std::string(e.what()).find("galvanized_steel"), std::string::npos);
  }
  EXPECT_THROW(lib.interaction("abs_plastic", "organic_glass"), InputError);
}
