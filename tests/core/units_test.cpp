#include "clumpkit/core/units.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "clumpkit/core/error.hpp"

using namespace clumpkit;

TEST(Units, ConvertsToSI) {
  EXPECT_DOUBLE_EQ(parse_quantity("6.0 mm", Dimension::Length), 6.0e-3);
  EXPECT_DOUBLE_EQ(parse_quantity("  5.4mm ", Dimension::Length), 5.4e-3);
  EXPECT_DOUBLE_EQ(parse_quantity("1380 kg/m^3", Dimension::Density), 1380.0);
  EXPECT_DOUBLE_EQ(parse_quantity("1.38 g/cm^3", Dimension::Density), 1380.0);
  EXPECT_DOUBLE_EQ(parse_quantity("1.1e8 Pa", Dimension::Pressure), 1.1e8);
  EXPECT_DOUBLE_EQ(parse_quantity("79 GPa", Dimension::Pressure), 79e9);
  EXPECT_NEAR(parse_quantity("200 mm/min", Dimension::Velocity), 0.2 / 60.0, 1e-15);
  EXPECT_NEAR(parse_quantity("30 rpm", Dimension::AngularVelocity), M_PI, 1e-12);
  EXPECT_NEAR(parse_quantity("0.26 L", Dimension::Volume), 2.6e-4, 1e-18);
  EXPECT_DOUBLE_EQ(parse_quantity("0.35", Dimension::Dimensionless), 0.35);
}

TEST(Units, RejectsWithFieldNamed) {
  struct Case {
    const char* text;
    Dimension dim;
    const char* needle;
  };
  const Case cases[] = {
      {"6.0", Dimension::Length, "has no unit"},
      {"6.0 kg", Dimension::Length, "is not a unit of length"},
      {"6.0 furlong", Dimension::Length, "unknown unit"},
      {"abc mm", Dimension::Length, "not a number"},
      {"", Dimension::Length, "empty"},
      {"nan mm", Dimension::Length, "not finite"},
      {"inf Pa", Dimension::Pressure, "not finite"},
  };
  for (const Case& c : cases) {
    try {
      parse_quantity(c.text, c.dim, "f.toml:3", "shape.height");
      ADD_FAILURE() << "accepted '" << c.text << "'";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("f.toml:3: shape.height:"), std::string::npos) << msg;
      EXPECT_NE(msg.find(c.needle), std::string::npos) << msg;
    }
  }
}
