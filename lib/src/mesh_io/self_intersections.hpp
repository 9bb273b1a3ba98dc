#pragma once
// One of the two CGAL-using units of clumpkit (with hole_filling.hpp): triangle-triangle
// self-intersection counting (CGAL::Polygon_mesh_processing). Kept behind this plain interface so
// CGAL's headers never reach another translation unit.
#include "clumpkit/mesh_io/triangle_mesh.hpp"

namespace clumpkit::detail {

/// Number of pairs of triangles that intersect other than along shared edges or at shared
/// vertices; -1 if the triangles do not form a polygon mesh CGAL can check (non-manifold).
long long count_self_intersections(const TriangleMesh& mesh);

}  // namespace clumpkit::detail
