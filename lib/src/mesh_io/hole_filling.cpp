#include "hole_filling.hpp"

#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/exceptions.h>
#include <fmt/format.h>

#include <array>
#include <iterator>
#include <vector>

#include "cgal_surface_mesh.hpp"
#include "clumpkit/core/error.hpp"

namespace clumpkit::detail {

namespace {

FilledHoles fill_holes_with_cgal(TriangleMesh& mesh, const std::string& where,
                                 std::size_t max_edges) {
  using K = CgalKernel;
  using SurfaceMesh = CgalSurfaceMesh;
  namespace PMP = CGAL::Polygon_mesh_processing;
  // The caller made the triangles agree and has no edge of more than two: what is left to
  // refuse is a vertex where surfaces meet without sharing an edge.
  std::optional<SurfaceMesh> converted = to_surface_mesh(mesh);
  if (!converted)
    throw InputError(where, "",
                     "cannot fill its holes: surfaces meet at a vertex without sharing an edge "
                     "(a non-manifold vertex)");
  SurfaceMesh& sm = *converted;
  // The loops: one border halfedge of each, found by walking every border once.
  std::vector<SurfaceMesh::Halfedge_index> loops;
  std::vector<std::size_t> lengths;
  std::vector<char> seen(sm.number_of_halfedges(), 0);
  for (SurfaceMesh::Halfedge_index h : sm.halfedges()) {
    if (!sm.is_border(h) || seen[h.idx()]) continue;
    std::size_t n = 0;
    SurfaceMesh::Halfedge_index g = h;
    do {
      seen[g.idx()] = 1;
      ++n;
      g = sm.next(g);
    } while (g != h);
    loops.push_back(h);
    lengths.push_back(n);
  }
  FilledHoles out;
  for (std::size_t n : lengths) out.largest_hole = std::max(out.largest_hole, n);
  if (out.largest_hole > max_edges)
    throw InputError(where, "",
                     fmt::format("a hole of {} edges is too large to fill (at most {}): the mesh "
                                 "is more open than holed",
                                 out.largest_hole, max_edges));
  for (std::size_t k = 0; k < loops.size(); ++k) {
    std::vector<SurfaceMesh::Face_index> added;
    // The search within the loop's 3D Delaunay triangulation first; when that finds nothing, the
    // exhaustive search, cubic in the loop's length, only for loops of at most kCubicEdges (a
    // millisecond there; minutes for a loop of a few hundred edges).
    constexpr std::size_t kCubicEdges = 100;
    PMP::triangulate_hole(sm, loops[k], std::back_inserter(added),
                          CGAL::parameters::do_not_use_cubic_algorithm(lengths[k] > kCubicEdges));
    if (added.empty())
      throw InputError(
          where, "",
          fmt::format("cannot fill a hole of {} edges (no triangulation found)", lengths[k]));
    for (SurfaceMesh::Face_index f : added) {
      std::array<Eigen::Vector3d, 3> p;
      int i = 0;
      for (SurfaceMesh::Vertex_index v : CGAL::vertices_around_face(sm.halfedge(f), sm)) {
        const K::Point_3& q = sm.point(v);
        p[static_cast<std::size_t>(i++)] = Eigen::Vector3d(q.x(), q.y(), q.z());
      }
      out.area_added += 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
      std::array<int, 3> idx{};
      i = 0;
      for (SurfaceMesh::Vertex_index v : CGAL::vertices_around_face(sm.halfedge(f), sm))
        idx[static_cast<std::size_t>(i++)] = static_cast<int>(v.idx());
      mesh.triangles.emplace_back(idx[0], idx[1], idx[2]);
    }
    out.triangles_added += added.size();
    ++out.holes;
  }
  return out;
}

}  // namespace

FilledHoles fill_holes(TriangleMesh& mesh, const std::string& where, std::size_t max_edges) {
  // CGAL reports a broken precondition by an exception of its own (with its checks on, as in the
  // sanitizer builds): a mesh it cannot take, said as such.
  try {
    return fill_holes_with_cgal(mesh, where, max_edges);
  } catch (const CGAL::Failure_exception& e) {
    throw InputError(where, "",
                     "cannot fill its holes: CGAL refused the mesh (" + e.message() + ")");
  }
}

}  // namespace clumpkit::detail
