#pragma once
// Hole filling of an open triangle mesh by CGAL (Polygon_mesh_processing::triangulate_hole), kept
// behind this plain interface so CGAL's headers never reach another translation unit (as
// self_intersections.hpp; both convert through cgal_surface_mesh.hpp).
#include <cstddef>
#include <string>

#include "clumpkit/mesh_io/triangle_mesh.hpp"

namespace clumpkit::detail {

struct FilledHoles {
  std::size_t holes = 0;            ///< boundary loops closed
  std::size_t triangles_added = 0;  ///< new triangles, appended after the mesh's own
  std::size_t largest_hole = 0;     ///< edges of the longest loop
  double area_added = 0.0;          ///< m^2
};

/// Closes every boundary loop of a manifold mesh whose neighbouring triangles agree on
/// orientation (orient_consistently), with CGAL's minimal-area triangulation of each loop within
/// its 3D Delaunay triangulation (no new vertices). The mesh's vertices and triangles keep their
/// order; the new triangles follow. Throws InputError(where, "", ...) for a vertex where surfaces
/// meet without sharing an edge (CGAL needs a polygon mesh), a loop longer than `max_edges`, or a
/// loop CGAL cannot triangulate.
FilledHoles fill_holes(TriangleMesh& mesh, const std::string& where, std::size_t max_edges);

}  // namespace clumpkit::detail
