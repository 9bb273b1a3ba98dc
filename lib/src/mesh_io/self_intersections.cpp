#include "self_intersections.hpp"

#include <CGAL/Polygon_mesh_processing/self_intersections.h>

#include <iterator>
#include <vector>

#include "cgal_surface_mesh.hpp"

namespace clumpkit::detail {

long long count_self_intersections(const TriangleMesh& mesh) {
  std::optional<CgalSurfaceMesh> sm = to_surface_mesh(mesh);
  if (!sm) return -1;
  std::vector<std::pair<CgalSurfaceMesh::Face_index, CgalSurfaceMesh::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(CGAL::faces(*sm), *sm,
                                                    std::back_inserter(pairs));
  return static_cast<long long>(pairs.size());
}

}  // namespace clumpkit::detail
