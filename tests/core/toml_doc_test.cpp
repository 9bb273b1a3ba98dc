#include "clumpkit/core/toml_doc.hpp"

#include <gtest/gtest.h>

#include "clumpkit/core/error.hpp"

using namespace clumpkit;

namespace {
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(TomlDoc, TypedAccessWithUnits) {
  TomlDoc d = TomlDoc::parse(
      "[shape]\nkind = \"cylinder\"\ndiameter = \"6 mm\"\nlayers = 3\n[[f]]\nx = 1.5\n", "t.toml");
  EXPECT_EQ(d.string("shape.kind"), "cylinder");
  EXPECT_DOUBLE_EQ(d.quantity("shape.diameter", Dimension::Length), 0.006);
  EXPECT_EQ(d.integer("shape.layers"), 3);
  EXPECT_EQ(d.array_size("f"), 1u);
  EXPECT_DOUBLE_EQ(d.number("f.0.x"), 1.5);
  EXPECT_FALSE(d.quantity_opt("shape.height", Dimension::Length).has_value());
}

TEST(TomlDoc, ErrorsNameFileLineAndKey) {
  TomlDoc d = TomlDoc::parse("[shape]\nkind = 3\nheight = 5.4\nd = \"-1 mm\"\n", "t.toml");
  EXPECT_NE(
      error_of([&] { d.string("shape.kind"); }).find("t.toml:2: shape.kind: expected a string"),
      std::string::npos);
  EXPECT_NE(error_of([&] { d.quantity("shape.height", Dimension::Length); }).find("needs a unit"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              d.quantity("shape.missing", Dimension::Length);
            }).find("t.toml: shape.missing: missing"),
            std::string::npos);
  const double v = d.quantity("shape.d", Dimension::Length);
  EXPECT_NE(error_of([&] {
              d.require_range("shape.d", v, 0.0, 1.0, true);
            }).find("t.toml:4: shape.d: value -0.001 is outside (0, 1]"),
            std::string::npos);
}

TEST(TomlDoc, SyntaxErrorHasLineAndColumn) {
  const std::string e = error_of([] { TomlDoc::parse("a = 1\nb = = 2\n", "bad.toml"); });
  EXPECT_NE(e.find("bad.toml:2:"), std::string::npos) << e;
}
