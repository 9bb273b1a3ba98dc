#pragma once
/// The shape a clump is compared with: built from a shape file, a mesh file, or the provenance a
/// clump template records about its source.
#include <filesystem>
#include <memory>
#include <string>

#include "clumpkit/geometry/clump_template.hpp"
#include "clumpkit/geometry/shape_spec.hpp"
#include "clumpkit/mesh_io/load_mesh.hpp"  // is_mesh_file: which paths are meshes
#include "clumpkit/raycast/surface_solid.hpp"

namespace clumpkit {

struct TargetShape {
  std::unique_ptr<SurfaceSolid> solid;  ///< exact cylinder, or a MeshSolid
  std::string description;              ///< e.g. "cylinder D 6 mm H 5.4 mm" or the mesh path
  double density = 0.0;                 ///< kg/m^3 if the source says, else 0
  std::size_t reoriented_faces = 0;     ///< triangles the orientation repair reversed
  std::size_t holes_filled = 0;         ///< holes the hole repair closed
  double hole_area_fraction = 0.0;      ///< their area over the repaired surface's
  std::size_t solids = 1;               ///< separate pieces of a mesh (MeshReport::solids)
};

/// A ShapeSpec as a solid: a cylinder exactly, a mesh through load_shape_mesh.
TargetShape target_from_shape(const ShapeSpec& shape);

/// A mesh file (scale: file units to metres), loaded, validated and oriented.
TargetShape target_from_mesh(const std::filesystem::path& path, double scale = 1.0);
/// The same with the loader's options: with `repair_orientation` or `repair_holes` the mesh is
/// repaired instead of refused, and the description says what was done.
TargetShape target_from_mesh(const std::filesystem::path& path, const MeshLoadOptions& options);

/// The clump's recorded source, read from its `source` object: `file` naming a shape file
/// (.toml) or a mesh (with `mesh_scale` or `units`), or `mesh` naming a mesh; else `kind`
/// "cylinder" with `diameter` and `height` in metres. Throws InputError(where, "source", ...)
/// when the source is missing or unusable.
TargetShape target_from_source(const ClumpTemplate& clump, const std::string& where);

}  // namespace clumpkit
