#include "clumpkit/mesh_io/mesh_report.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "clumpkit/core/error.hpp"
#include "clumpkit/mesh_io/orientation.hpp"
#include "self_intersections.hpp"

namespace clumpkit {

bool MeshReport::closed_solid() const {
  return triangles > 0 && nonfinite_vertices == 0 && bad_indices == 0 && boundary_edges == 0 &&
         nonmanifold_edges == 0 && inconsistent_edges == 0 && misoriented_bodies == 0 &&
         self_intersections <= 0 && signed_volume != 0.0;
}

bool MeshReport::holes_repairable() const {
  return triangles > 0 && nonfinite_vertices == 0 && bad_indices == 0 && boundary_edges > 0 &&
         nonmanifold_edges == 0;
}

bool MeshReport::orientation_repairable() const {
  return triangles > 0 && nonfinite_vertices == 0 && bad_indices == 0 && boundary_edges == 0 &&
         nonmanifold_edges == 0 && self_intersections <= 0 &&
         (inconsistent_edges > 0 || misoriented_bodies > 0);
}

std::string MeshReport::defects() const {
  std::string s;
  auto add = [&](std::size_t n, const char* what) {
    if (n == 0) return;
    if (!s.empty()) s += ", ";
    s += fmt::format("{} {}", n, what);
  };
  if (triangles == 0) return "no triangles (empty mesh)";
  add(nonfinite_vertices, "vertices with NaN/inf coordinates");
  add(bad_indices, "triangles with invalid vertex indices");
  add(boundary_edges, "boundary (open) edges");
  add(nonmanifold_edges, "non-manifold edges");
  add(inconsistent_edges, "edges with inconsistent orientation");
  // An inverted body beside others, or a cavity's wall facing outward.
  add(misoriented_bodies, misoriented_bodies == 1 ? "body inside out for its nesting"
                                                  : "bodies inside out for their nesting");
  if (self_intersections > 0)
    add(static_cast<std::size_t>(self_intersections), "self-intersecting triangle pairs");
  add(degenerate_faces, "degenerate faces");
  if (s.empty() && signed_volume == 0.0) s = "zero enclosed volume";
  return s.empty() ? "no defects" : s;
}

MeshReport validate_mesh(const TriangleMesh& mesh, const MeshValidateOptions& opt) {
  MeshReport r;
  r.vertices = mesh.vertices.size();
  r.triangles = mesh.triangles.size();
  for (const Eigen::Vector3d& v : mesh.vertices)
    if (!v.allFinite()) ++r.nonfinite_vertices;
  const long long nv = static_cast<long long>(mesh.vertices.size());
  // Undirected edge -> (use count, sum of directions); two consistently oriented neighbours
  // traverse a shared edge in opposite directions, so their directions cancel.
  struct EdgeUse {
    int count = 0;
    int direction = 0;
  };
  std::unordered_map<std::uint64_t, EdgeUse> edges;
  edges.reserve(mesh.triangles.size() * 2);
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : mesh.vertices)
    if (v.allFinite()) box.extend(v);
  const double diag2 = box.isEmpty() ? 0.0 : box.diagonal().squaredNorm();
  for (const Eigen::Vector3i& t : mesh.triangles) {
    bool ok = true;
    for (int k = 0; k < 3; ++k) ok = ok && t[k] >= 0 && t[k] < nv;
    ok = ok && t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
    if (!ok) {
      ++r.bad_indices;
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = static_cast<std::uint32_t>(t[k]);
      const std::uint32_t b = static_cast<std::uint32_t>(t[(k + 1) % 3]);
      const std::uint64_t key = a < b ? (std::uint64_t{a} << 32 | b) : (std::uint64_t{b} << 32 | a);
      EdgeUse& e = edges[key];
      ++e.count;
      e.direction += a < b ? 1 : -1;
    }
    const Eigen::Vector3d& p = mesh.vertices[t[0]];
    const double area2 = (mesh.vertices[t[1]] - p).cross(mesh.vertices[t[2]] - p).norm();
    if (!(area2 > 2.0 * opt.degenerate_area * diag2)) ++r.degenerate_faces;
  }
  for (const auto& [key, e] : edges) {
    if (e.count == 1)
      ++r.boundary_edges;
    else if (e.count > 2)
      ++r.nonmanifold_edges;
    else if (e.direction != 0)
      ++r.inconsistent_edges;
  }
  if (r.nonfinite_vertices == 0 && r.bad_indices == 0) {
    r.signed_volume = polyhedron_moments(mesh).m0;
    r.area = surface_area(mesh);
  }
  const bool topology_ok = r.triangles > 0 && r.nonfinite_vertices == 0 && r.bad_indices == 0 &&
                           r.boundary_edges == 0 && r.nonmanifold_edges == 0 &&
                           r.inconsistent_edges == 0;
  if (topology_ok) {
    const BodyOrientation b = body_orientation(mesh);
    r.bodies = b.bodies;
    r.misoriented_bodies = b.misoriented;
    r.solids = b.solids;
  }
  if (opt.check_self_intersections && topology_ok)
    r.self_intersections = detail::count_self_intersections(mesh);
  return r;
}

void require_closed_solid(const MeshReport& report, const std::string& where) {
  if (report.closed_solid()) return;
  std::string hint;
  if (report.orientation_repairable())
    hint =
        "; it is closed and manifold, so its triangles can be re-oriented: give "
        "--repair-orientation (a shape file: repair_orientation = true under [shape])";
  else if (report.holes_repairable())
    hint =
        "; it is manifold, so its holes can be closed: give --repair-holes (a shape file: "
        "repair_holes = true under [shape])";
  throw InputError(where, "",
                   fmt::format("{} ({} vertices, {} triangles): not a closed solid, its volume "
                               "would be meaningless{}",
                               report.defects(), report.vertices, report.triangles, hint));
}

}  // namespace clumpkit
