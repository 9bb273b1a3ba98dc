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

// The spellings of a lab spreadsheet: superscripts, the degree sign, micro, litres, per hour.
TEST(Units, SpreadsheetSpellingsAreTheSameUnits) {
  const double deg = M_PI / 180.0;
  EXPECT_DOUBLE_EQ(parse_quantity("31.5°", Dimension::Angle), 31.5 * deg);
  EXPECT_DOUBLE_EQ(parse_quantity("31.5 °", Dimension::Angle), 31.5 * deg);
  EXPECT_DOUBLE_EQ(parse_quantity("31.5 degrees", Dimension::Angle), 31.5 * deg);
  EXPECT_DOUBLE_EQ(parse_quantity("1 degree", Dimension::Angle), deg);
  EXPECT_DOUBLE_EQ(parse_quantity("735 kg/m³", Dimension::Density), 735.0);
  EXPECT_DOUBLE_EQ(parse_quantity("735 g/L", Dimension::Density), 735.0);
  EXPECT_DOUBLE_EQ(parse_quantity("0.735 g/mL", Dimension::Density), 735.0);
  EXPECT_DOUBLE_EQ(parse_quantity("0.735 kg/L", Dimension::Density), 735.0);
  EXPECT_DOUBLE_EQ(parse_quantity("0.735 g/cm³", Dimension::Density), 735.0);
  EXPECT_DOUBLE_EQ(parse_quantity("6000 J/m³", Dimension::Pressure), 6000.0);
  EXPECT_DOUBLE_EQ(parse_quantity("250 µm", Dimension::Length), 250e-6);  // micro sign
  EXPECT_DOUBLE_EQ(parse_quantity("250 μm", Dimension::Length), 250e-6);  // Greek mu
  EXPECT_DOUBLE_EQ(parse_quantity("5 µs", Dimension::Time), 5e-6);
  EXPECT_DOUBLE_EQ(parse_quantity("2 h", Dimension::Time), 7200.0);
  EXPECT_DOUBLE_EQ(parse_quantity("260 ml", Dimension::Volume), 2.6e-4);
  EXPECT_DOUBLE_EQ(parse_quantity("260000 mm³", Dimension::Volume), 2.6e-4);
  EXPECT_DOUBLE_EQ(parse_quantity("9.81 m/s²", Dimension::Acceleration), 9.81);
  EXPECT_DOUBLE_EQ(parse_quantity("0.05 J/m²", Dimension::SurfaceEnergy), 0.05);
  EXPECT_DOUBLE_EQ(parse_quantity("21 kg/min", Dimension::MassFlow), 0.35);
  EXPECT_DOUBLE_EQ(parse_quantity("1260 kg/h", Dimension::MassFlow), 0.35);
  EXPECT_DOUBLE_EQ(parse_quantity("1.26 t/h", Dimension::MassFlow), 0.35);
  EXPECT_DOUBLE_EQ(parse_quantity("21000 g/min", Dimension::MassFlow), 0.35);
  // Still one dimension each: a degree is no density, an hour no length.
  EXPECT_THROW(parse_quantity("30 °", Dimension::Density), InputError);
  EXPECT_THROW(parse_quantity("2 h", Dimension::Length), InputError);
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
