#include "clumpkit/geometry/shape_spec.hpp"

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/core/toml_doc.hpp"

namespace clumpkit {

ShapeSpec load_shape(const std::filesystem::path& path) {
  return parse_shape(read_file(path), path);
}

ShapeSpec parse_shape(const std::string& text, const std::filesystem::path& path) {
  TomlDoc doc = TomlDoc::parse(text, path.string());
  ShapeSpec s;
  s.path = path;
  s.name = doc.string_opt("shape.name").value_or(path.stem().string());
  const std::string kind = doc.string("shape.kind");
  if (kind == "cylinder") {
    s.kind = ShapeSpec::Kind::Cylinder;
    s.diameter = doc.quantity("shape.diameter", Dimension::Length);
    doc.require_range("shape.diameter", s.diameter, 0.0, 10.0, true);
    s.height = doc.quantity("shape.height", Dimension::Length);
    doc.require_range("shape.height", s.height, 0.0, 10.0, true);
  } else if (kind == "mesh") {
    s.kind = ShapeSpec::Kind::Mesh;
    s.mesh = path.parent_path() / doc.string("shape.file");
    const std::string unit = doc.string_opt("shape.units").value_or("m");
    s.mesh_scale = unit_factor(unit, Dimension::Length, path.string(), "shape.units");
    s.repair_orientation = doc.boolean_opt("shape.repair_orientation").value_or(false);
    s.repair_holes = doc.boolean_opt("shape.repair_holes").value_or(false);
  } else {
    doc.fail("shape.kind", "unknown kind '" + kind + "' (expected cylinder or mesh)");
  }
  s.material = doc.string_opt("material.name").value_or("pill");
  s.density = doc.quantity("material.density", Dimension::Density);
  doc.require_range("material.density", s.density, 0.0, 1e5, true);
  s.mass_fraction = doc.number_opt("population.mass_fraction").value_or(1.0);
  doc.require_range("population.mass_fraction", s.mass_fraction, 0.0, 1.0, true);
  return s;
}

ShapeSpec cylinder_shape(const std::string& name, double diameter, double height, double density) {
  ShapeSpec s;
  s.name = name;
  s.diameter = diameter;
  s.height = height;
  s.density = density;
  return s;
}

}  // namespace clumpkit
