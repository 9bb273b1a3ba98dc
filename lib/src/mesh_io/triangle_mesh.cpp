#include "clumpkit/mesh_io/triangle_mesh.hpp"

#include <algorithm>

namespace clumpkit {

Eigen::AlignedBox3d mesh_bounds(const TriangleMesh& mesh) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : mesh.vertices) box.extend(v);
  return box;
}

double surface_area(const TriangleMesh& mesh) {
  double area = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    area += 0.5 * (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).norm();
  }
  return area;
}

Moments polyhedron_moments(const TriangleMesh& mesh) {
  // Sum of signed tetrahedra (o, a, b, c) about a reference point o inside the bounds, which
  // keeps the cancellation between positive and negative tetrahedra small; shifted back after.
  Moments m;
  if (mesh.vertices.empty()) return m;
  const Eigen::Vector3d o = mesh_bounds(mesh).center();
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]] - o;
    const Eigen::Vector3d b = mesh.vertices[t[1]] - o;
    const Eigen::Vector3d c = mesh.vertices[t[2]] - o;
    const double vol = a.dot(b.cross(c)) / 6.0;
    const Eigen::Vector3d s = a + b + c;
    m.m0 += vol;
    m.m1 += vol * 0.25 * s;
    // ∫ y yᵀ dV over a tetrahedron with one vertex at the origin: V/20 (Σ v vᵀ + s sᵀ).
    m.m2 += (vol / 20.0) *
            (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  Moments r;
  r.m0 = m.m0;
  r.m1 = m.m1 + m.m0 * o;
  r.m2 = m.m2 + m.m1 * o.transpose() + o * m.m1.transpose() + m.m0 * o * o.transpose();
  return r;
}

void flip_orientation(TriangleMesh& mesh) {
  for (Eigen::Vector3i& t : mesh.triangles) std::swap(t[1], t[2]);
}

}  // namespace clumpkit
