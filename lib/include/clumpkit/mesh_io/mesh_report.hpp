#pragma once
/// Validation of a triangle mesh as the boundary of a solid: the defects that would make its
/// enclosed volume meaningless, counted.
#include <cstddef>
#include <string>

#include "clumpkit/mesh_io/triangle_mesh.hpp"

namespace clumpkit {

struct MeshReport {
  std::size_t vertices = 0;
  std::size_t triangles = 0;
  std::size_t welded_vertices = 0;     ///< merged by welding (loading only)
  std::size_t collapsed_faces = 0;     ///< dropped because welding collapsed them (loading only)
  std::size_t nonfinite_vertices = 0;  ///< NaN or infinite coordinates
  std::size_t bad_indices = 0;         ///< triangles referring to missing or repeated vertices
  std::size_t boundary_edges = 0;      ///< edges used by one triangle (open mesh)
  std::size_t nonmanifold_edges = 0;   ///< edges used by more than two triangles
  std::size_t inconsistent_edges = 0;  ///< edges whose two triangles disagree on orientation
  std::size_t bodies = 0;              ///< connected components (counted on a closed manifold)
  /// Bodies facing against their nesting: an inverted body beside others, or a cavity's wall
  /// facing outward (clumpkit/mesh_io/orientation.hpp). Counted on a closed, consistent manifold.
  std::size_t misoriented_bodies = 0;
  /// Bodies inside no other body: the separate pieces of the solid (1 for one piece, with or
  /// without cavities). Counted on a closed, consistent manifold.
  std::size_t solids = 0;
  std::size_t degenerate_faces = 0;  ///< (near-)zero area; harmless for volume, reported
  /// Pairs of triangles that intersect other than at shared edges/vertices; -1 when not checked
  /// (disabled, or the mesh is not a closed oriented manifold, which CGAL's check requires).
  long long self_intersections = -1;
  double signed_volume = 0.0;        ///< m^3, positive for outward orientation
  double area = 0.0;                 ///< m^2
  bool flipped = false;              ///< orientation was reversed to make it outward (loading only)
  std::size_t reoriented_faces = 0;  ///< triangles reversed by the orientation repair (loading)
  std::size_t holes_filled = 0;      ///< boundary loops closed by the hole repair (loading)
  std::size_t triangles_added = 0;   ///< triangles the hole repair added (loading)
  double hole_area = 0.0;            ///< m^2, area of those triangles (loading)

  /// True when the only defects found are orientations: a closed manifold whose triangles can be
  /// re-oriented (MeshLoadOptions::repair_orientation). Self-intersections are only counted on a
  /// consistent mesh, so one may still be found after the repair.
  bool orientation_repairable() const;
  /// True when the mesh is open but otherwise manifold: its holes can be closed
  /// (MeshLoadOptions::repair_holes).
  bool holes_repairable() const;

  /// True when the mesh bounds a solid whose volume and moments mean something.
  bool closed_solid() const;
  /// One line: the counts of every defect found, e.g. "12 boundary edges, 2 non-manifold edges".
  std::string defects() const;
};

struct MeshValidateOptions {
  bool check_self_intersections = true;
  /// A face is degenerate when its area is below this times the squared bbox diagonal.
  double degenerate_area = 1e-14;
};

/// Counts the defects of `mesh` without modifying it.
MeshReport validate_mesh(const TriangleMesh& mesh, const MeshValidateOptions& options = {});

/// Throws InputError(where, "", "<defects>: not a closed solid") unless report.closed_solid();
/// when a repair would help (the orientation, or the holes of a manifold mesh), the message says
/// how to ask for it.
void require_closed_solid(const MeshReport& report, const std::string& where);

}  // namespace clumpkit
