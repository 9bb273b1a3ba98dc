#pragma once
/// Reading closed triangle meshes (STL ascii/binary and OBJ through assimp; PLY and OFF by
/// clumpkit's own readers), welded, validated and oriented outward.
#include <filesystem>

#include "clumpkit/geometry/shape_spec.hpp"
#include "clumpkit/mesh_io/mesh_report.hpp"
#include "clumpkit/mesh_io/triangle_mesh.hpp"

namespace clumpkit {

struct MeshLoadOptions {
  double scale = 1.0;  ///< factor from file units to metres (0.001 for a file in mm)
  /// Vertices closer than this fraction of the bounding-box diagonal are merged.
  double weld_tolerance = 1e-7;
  /// Refuse (InputError) meshes whose enclosed volume would be meaningless.
  bool require_closed = true;
  bool check_self_intersections = true;
  /// Re-orient a closed, manifold mesh whose triangles disagree on orientation, or whose bodies
  /// face against their nesting (orient_outward), instead of refusing it. The report counts the
  /// triangles reversed (reoriented_faces).
  bool repair_orientation = false;
  /// Close the holes of an open, manifold mesh (boundary loops, e.g. of a scan) with CGAL's hole
  /// triangulation, then re-orient it as repair_orientation does. Loops longer than
  /// `max_hole_edges` are refused. The report counts the holes and the triangles added.
  bool repair_holes = false;
  std::size_t max_hole_edges = 1000;
};

/// True for the file names load_mesh reads: .stl .obj .ply .off, in any case.
bool is_mesh_file(const std::filesystem::path& path);

/// Loads, welds and validates a mesh; flips it to outward orientation if its signed volume is
/// negative. Throws InputError naming the file (and the defect counts) for a missing, empty,
/// unreadable (or not .stl, .obj, .ply, .off: the format is chosen by the extension, in any case)
/// or, with `require_closed`, a non-manifold or self-intersecting mesh, an open one (unless
/// `repair_holes` closes it) or one whose orientation is inconsistent (unless `repair_orientation`
/// or `repair_holes` re-orients it).
/// `report`, if given, receives the validation report of the returned mesh.
TriangleMesh load_mesh(const std::filesystem::path& path, const MeshLoadOptions& options,
                       MeshReport* report = nullptr);

/// Shorthand: load_mesh with the given scale and default options.
TriangleMesh load_mesh(const std::filesystem::path& path, double scale = 1.0);

/// The mesh of a ShapeSpec of kind mesh (its file, in its units). Throws InputError naming the
/// shape file for a cylinder spec.
TriangleMesh load_shape_mesh(const ShapeSpec& shape, MeshReport* report = nullptr);

/// Merges vertices closer than `tolerance` (metres), drops triangles that collapse (repeated
/// vertex) and unused vertices. Returns the number of vertices merged away; `collapsed`, if
/// given, receives the number of triangles dropped.
std::size_t weld_vertices(TriangleMesh& mesh, double tolerance, std::size_t* collapsed = nullptr);

}  // namespace clumpkit
