#pragma once
/// Closed, outward-oriented tessellations of simple solids, in metres, centred at the origin.
/// Shared by tests and benchmarks, and usable to export analytic shapes as meshes. Each is a
/// polyhedron: compare it against polyhedron_moments(), not the smooth solid's closed form.
#include "clumpkit/mesh_io/triangle_mesh.hpp"

namespace clumpkit {

/// Axis-aligned box with the given edge lengths (12 triangles).
TriangleMesh box_mesh(const Eigen::Vector3d& sizes);

/// Icosphere: an icosahedron subdivided `subdivisions` times, vertices on the sphere
/// (20 * 4^subdivisions triangles).
TriangleMesh icosphere_mesh(double radius, int subdivisions);

/// Cylinder, axis z, with `segments` vertices around each rim and `rings` bands along the side;
/// caps are fans about a centre vertex (2 * segments * (rings + 1) triangles).
TriangleMesh cylinder_mesh(double diameter, double height, int segments, int rings = 1);

/// Torus about the z axis: major radius R (axis to tube centre), minor radius a, with `major`
/// segments around the axis and `minor` around the tube (2 * major * minor triangles).
TriangleMesh torus_mesh(double R, double a, int major, int minor);

}  // namespace clumpkit
