#pragma once
/// A triangle mesh as one array per attribute: vertex positions in metres and triangles as
/// indices into them, counter-clockwise seen from outside (outward normals) once validated.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "clumpkit/geometry/ray_moments.hpp"

namespace clumpkit {

struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;   ///< m
  std::vector<Eigen::Vector3i> triangles;  ///< vertex indices, outward by the right-hand rule
};

/// Axis-aligned bounds of the vertices (empty box for an empty mesh).
Eigen::AlignedBox3d mesh_bounds(const TriangleMesh& mesh);

/// Total surface area, m^2.
double surface_area(const TriangleMesh& mesh);

/// Exact raw moments (m0 = volume, m1, m2 about the origin) of the polyhedron bounded by a
/// closed, consistently oriented mesh, by the divergence theorem. Negative m0 for an inward
/// orientation.
Moments polyhedron_moments(const TriangleMesh& mesh);

/// Reverses every triangle's orientation in place.
void flip_orientation(TriangleMesh& mesh);

}  // namespace clumpkit
