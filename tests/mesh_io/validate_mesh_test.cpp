// Mesh validation counts and polyhedral mass properties against closed forms.
#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "clumpkit/core/error.hpp"
#include "clumpkit/geometry/mass_properties.hpp"
#include "clumpkit/mesh_io/mesh_report.hpp"
#include "clumpkit/mesh_io/primitive_meshes.hpp"

namespace clumpkit {
namespace {

TEST(PolyhedronMoments, BoxMatchesClosedFormAnywhere) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.1, 3.0), off(-5, 5);
  for (int c = 0; c < 50; ++c) {
    const Eigen::Vector3d s(u(rng), u(rng), u(rng)), t(off(rng), off(rng), off(rng));
    TriangleMesh b = box_mesh(s);
    for (auto& v : b.vertices) v += t;
    const MassProperties got = mass_properties(polyhedron_moments(b), 1000.0);
    const MassProperties want = box_mass_properties(s, 1000.0);
    EXPECT_NEAR(got.volume / want.volume, 1.0, 1e-12);
    EXPECT_LT((got.center_of_mass - t).norm(), 1e-12 * (1 + t.norm()));
    EXPECT_LT((got.inertia_tensor - want.inertia_tensor).norm(), 1e-9 * want.inertia_tensor.norm());
  }
}

TEST(PolyhedronMoments, FineTessellationsApproachSmoothSolids) {
  const double r = 0.003;
  const double vs = polyhedron_moments(icosphere_mesh(r, 6)).m0;
  EXPECT_NEAR(vs / (4.0 / 3.0 * std::numbers::pi * r * r * r), 1.0, 1e-3);
  const double vc = polyhedron_moments(cylinder_mesh(0.006, 0.0054, 512)).m0;
  // An inscribed n-gon prism: area (n/2) r^2 sin(2 pi / n).
  EXPECT_NEAR(vc, 0.5 * 512 * 9e-6 * std::sin(2 * std::numbers::pi / 512) * 0.0054, 1e-18);
  const double vt = polyhedron_moments(torus_mesh(0.03, 0.01, 256, 128)).m0;
  EXPECT_NEAR(vt / (2 * std::numbers::pi * std::numbers::pi * 0.03 * 1e-4), 1.0, 1e-3);
}

TEST(ValidateMesh, PrimitivesAreClosedSolids) {
  for (const TriangleMesh& m : {box_mesh({1, 2, 3}), icosphere_mesh(1, 3),
                                cylinder_mesh(1, 2, 64, 4), torus_mesh(3, 1, 32, 16)}) {
    const MeshReport r = validate_mesh(m);
    EXPECT_TRUE(r.closed_solid()) << r.defects();
    EXPECT_EQ(r.self_intersections, 0);
    EXPECT_GT(r.signed_volume, 0);
    EXPECT_EQ(r.degenerate_faces, 0u);
  }
}

TEST(ValidateMesh, CountsEveryDefect) {
  const TriangleMesh box = box_mesh({1, 1, 1});
  {
    TriangleMesh m = box;
    m.triangles[3] = {m.triangles[3][0], m.triangles[3][2], m.triangles[3][1]};
    const MeshReport r = validate_mesh(m);
    EXPECT_EQ(r.inconsistent_edges, 3u);
    EXPECT_FALSE(r.closed_solid());
  }
  {
    TriangleMesh m = box;
    m.vertices.emplace_back(0, 0, 5);
    m.triangles.emplace_back(0, 1, 8);  // a fin on edge (0, 1)
    const MeshReport r = validate_mesh(m);
    EXPECT_GE(r.nonmanifold_edges, 1u);
    EXPECT_EQ(r.boundary_edges, 2u);
    EXPECT_NE(r.defects().find("non-manifold"), std::string::npos);
  }
  {
    TriangleMesh m = box;
    m.vertices[0] = {std::numeric_limits<double>::quiet_NaN(), 0, 0};
    const MeshReport r = validate_mesh(m);
    EXPECT_EQ(r.nonfinite_vertices, 1u);
    EXPECT_THROW(require_closed_solid(r, "m"), InputError);
  }
  {
    TriangleMesh m = box;
    m.triangles.emplace_back(0, 0, 1);
    m.triangles.emplace_back(0, 1, 99);
    EXPECT_EQ(validate_mesh(m).bad_indices, 2u);
  }
  {
    // Two interpenetrating closed boxes: closed, manifold, oriented, but self-intersecting.
    TriangleMesh m = box;
    const TriangleMesh b2 = box_mesh({1, 1, 1});
    for (const auto& v : b2.vertices) m.vertices.push_back(v + Eigen::Vector3d(0.3, 0.2, 0.1));
    for (const auto& t : b2.triangles) m.triangles.push_back(t + Eigen::Vector3i::Constant(8));
    const MeshReport r = validate_mesh(m);
    EXPECT_EQ(r.boundary_edges + r.nonmanifold_edges + r.inconsistent_edges, 0u);
    EXPECT_GT(r.self_intersections, 0);
    EXPECT_FALSE(r.closed_solid());
    try {
      require_closed_solid(r, "two_boxes.stl");
      FAIL();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("self-intersecting"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("two_boxes.stl"), std::string::npos);
    }
  }
  {
    TriangleMesh m;  // a collinear (zero-area) triangle
    m.vertices = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
    m.triangles = {{0, 1, 2}};
    const MeshReport r = validate_mesh(m);
    EXPECT_EQ(r.degenerate_faces, 1u);
    EXPECT_EQ(r.boundary_edges, 3u);
  }
  EXPECT_EQ(validate_mesh(TriangleMesh{}).defects(), "no triangles (empty mesh)");
}

}  // namespace
}  // namespace clumpkit
