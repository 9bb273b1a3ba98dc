#pragma once
/// A particle shape as described in a human-edited shape file (shapes/pill_A.toml): an analytic
/// cylinder or a triangle mesh, with its material, density and population mass fraction.
#include <filesystem>
#include <string>

namespace clumpkit {

struct ShapeSpec {
  std::string name;
  std::filesystem::path path;  ///< the shape file it came from (empty if built in code)
  enum class Kind { Cylinder, Mesh } kind = Kind::Cylinder;
  double diameter = 0.0;       ///< m (cylinder)
  double height = 0.0;         ///< m (cylinder)
  std::filesystem::path mesh;  ///< mesh file, resolved against the shape file's folder
  double mesh_scale = 1.0;     ///< factor from mesh file units to metres
  /// Re-orient the mesh's triangles if they disagree (`repair_orientation = true` under [shape]).
  bool repair_orientation = false;
  /// Close the mesh's holes (`repair_holes = true` under [shape]); implies the orientation repair.
  bool repair_holes = false;
  std::string material = "pill";
  double density = 0.0;        ///< kg/m^3
  double mass_fraction = 1.0;  ///< share of the population by mass, (0, 1]
};

/// Loads a shape file; throws InputError naming file, line and key on anything missing, negative
/// or zero.
ShapeSpec load_shape(const std::filesystem::path& path);
/// The same from the file's text (`path` names it in errors and resolves relative mesh files).
ShapeSpec parse_shape(const std::string& text, const std::filesystem::path& path);

/// A cylinder shape built in code.
ShapeSpec cylinder_shape(const std::string& name, double diameter, double height, double density);

}  // namespace clumpkit
