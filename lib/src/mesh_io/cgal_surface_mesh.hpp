#pragma once
// A TriangleMesh as CGAL's Surface_mesh, for the two CGAL units of clumpkit
// (self_intersections.cpp, hole_filling.cpp). Included by those two only, so CGAL's headers reach
// no other translation unit.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <optional>
#include <vector>

#include "clumpkit/mesh_io/triangle_mesh.hpp"

namespace clumpkit::detail {

using CgalKernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalSurfaceMesh = CGAL::Surface_mesh<CgalKernel::Point_3>;

/// `mesh` as a Surface_mesh whose vertex i is mesh.vertices[i] and whose faces are
/// mesh.triangles in order; nothing when the triangles do not form a polygon mesh (an edge of
/// more than two triangles, neighbours that disagree on orientation, surfaces meeting at a vertex).
inline std::optional<CgalSurfaceMesh> to_surface_mesh(const TriangleMesh& mesh) {
  namespace PMP = CGAL::Polygon_mesh_processing;
  std::vector<CgalKernel::Point_3> points;
  points.reserve(mesh.vertices.size());
  for (const Eigen::Vector3d& v : mesh.vertices) points.emplace_back(v[0], v[1], v[2]);
  std::vector<std::array<std::size_t, 3>> faces;
  faces.reserve(mesh.triangles.size());
  for (const Eigen::Vector3i& t : mesh.triangles)
    faces.push_back({static_cast<std::size_t>(t[0]), static_cast<std::size_t>(t[1]),
                     static_cast<std::size_t>(t[2])});
  if (!PMP::is_polygon_soup_a_polygon_mesh(faces)) return std::nullopt;
  CgalSurfaceMesh sm;
  PMP::polygon_soup_to_polygon_mesh(points, faces, sm);
  return sm;
}

}  // namespace clumpkit::detail
