// Shape-error figures against closed forms; exact union-surface distances against brute force.
#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "analytic_solids.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/mesh_io/primitive_meshes.hpp"
#include "clumpkit/raycast/analytic_surfaces.hpp"
#include "clumpkit/raycast/mesh_solid.hpp"
#include "clumpkit/raycast/shape_error.hpp"

namespace clumpkit {
namespace {

using std::numbers::pi;

ShapeErrorOptions fast(std::int64_t rays = 400'000) {
  ShapeErrorOptions o;
  o.sampling.rays = rays;
  o.surface_samples = 4000;
  return o;
}

TEST(ShapeError, ConcentricSpheres) {
  const double R = 0.003, r = 0.0025;
  const test::Ball shape({0.001, 0, 0}, R);
  const ShapeError e = shape_error(shape, {{Eigen::Vector3d(0.001, 0, 0), r}}, fast());
  const double vs = 4.0 / 3 * pi * R * R * R, vc = 4.0 / 3 * pi * r * r * r;
  EXPECT_NEAR(e.shape.volume / vs, 1, 1e-3);
  EXPECT_NEAR(e.clump.volume / vc, 1, 1e-3);
  EXPECT_NEAR(e.volume_rel_error.value, vc / vs - 1, 2 * e.volume_rel_error.ci95 + 1e-6);
  EXPECT_NEAR(e.sym_diff_volume.value, vs - vc, 2 * e.sym_diff_volume.ci95 + 1e-6 * vs);
  EXPECT_NEAR(e.sym_diff_rel.value, 1 - vc / vs, 1e-3);
  EXPECT_NEAR(e.intersection_volume.value / vc, 1, 1e-3);
  EXPECT_LT(e.com_offset.value, 1e-3 * R);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(e.moments_rel_error[k].value, std::pow(r / R, 5) - 1, 2e-3);
  EXPECT_FALSE(e.axis_angle_deg.has_value());  // all moments equal: no axis to compare
  EXPECT_NEAR(e.hausdorff, R - r, 1e-9);
  EXPECT_NEAR(e.mean_surface_distance, R - r, 1e-9);
  EXPECT_EQ(e.spheres, 1u);
}

TEST(ShapeError, CylinderAgainstInscribedSphere) {
  // D = H = 2r: the sphere touches the side and both caps.
  const double r = 0.003;
  const CylinderSurface shape(2 * r, 2 * r);
  ShapeErrorOptions o = fast();
  o.surface_samples = 20000;
  o.density = 1380;
  const ShapeError e = shape_error(shape, {{Eigen::Vector3d::Zero(), r}}, o);
  const double vc = 2 * pi * r * r * r, vs = 4.0 / 3 * pi * r * r * r;
  EXPECT_NEAR(e.sym_diff_rel.value, 1 - vs / vc, 1e-3);  // = 1/3
  EXPECT_NEAR(e.volume_rel_error.value, vs / vc - 1, 1e-3);
  EXPECT_NEAR(e.shape.mass, 1380 * vc, 1e-3 * 1380 * vc);
  // Principal moments, ascending: cylinder m r^2/2 (axis) < 7/12 m r^2 (transverse).
  const double mc = 1380 * vc, ms = 1380 * vs;
  EXPECT_NEAR(e.shape.principal_moments[0] / (mc * r * r / 2), 1, 1e-3);
  EXPECT_NEAR(e.shape.principal_moments[2] / (mc * r * r * 7 / 12), 1, 1e-3);
  EXPECT_NEAR(e.moments_rel_error[0].value, 0.4 * ms / (0.5 * mc) - 1, 2e-3);
  // The rim is farthest from the sphere: (sqrt 2 - 1) r; sampling approaches it from below.
  EXPECT_LE(e.shape_to_clump_max, (std::sqrt(2.0) - 1) * r + 1e-12);
  EXPECT_GT(e.shape_to_clump_max, 0.98 * (std::sqrt(2.0) - 1) * r);
  // Sphere points at 45 deg latitude are (1 - 1/sqrt 2) r from the cylinder.
  EXPECT_NEAR(e.clump_to_shape_max, (1 - std::sqrt(0.5)) * r, 0.01 * r);
  EXPECT_NEAR(e.hausdorff, (std::sqrt(2.0) - 1) * r, 0.02 * r);
  // The sphere's moments are all equal: its axes are arbitrary, so none is compared.
  EXPECT_FALSE(e.axis_angle_deg.has_value());
}

TEST(ShapeError, IdenticalUnionHasNoError) {
  const Spheres s = {{Eigen::Vector3d(0, 0, 0), 0.002},
                     {Eigen::Vector3d(0.0025, 0, 0), 0.0015},
                     {Eigen::Vector3d(0.001, 0.002, 0.0005), 0.001}};
  const SphereUnionSurface shape(s);
  const ShapeError e = shape_error(shape, s, fast());
  EXPECT_EQ(e.sym_diff_volume.value, 0.0);
  EXPECT_EQ(e.volume_rel_error.value, 0.0);
  EXPECT_EQ(e.com_offset.value, 0.0);
  EXPECT_LT(e.hausdorff, 1e-15);
  ASSERT_TRUE(e.axis_angle_deg.has_value());
  EXPECT_NEAR(*e.axis_angle_deg, 0.0, 1e-6);
}

TEST(ShapeError, AxisAngleOfARotatedRod) {
  // Box 4 x 1 x 1 along x vs three spheres on a line rotated 10 deg about z: the long axes (the
  // smallest moments) are 10 deg apart; the other two moments are equal for both solids (square
  // section, line of spheres) so only one axis is compared.
  const MeshSolid shape(box_mesh({0.004, 0.001, 0.001}));
  const Eigen::Vector3d u(std::cos(10 * pi / 180), std::sin(10 * pi / 180), 0);
  const Spheres s = {{-0.001 * u, 0.0005}, {Eigen::Vector3d::Zero(), 0.0005}, {0.001 * u, 0.0005}};
  const ShapeError e = shape_error(shape, s, fast());
  ASSERT_TRUE(e.axis_angle_deg.has_value());
  EXPECT_EQ(e.axes_compared, 1);
  EXPECT_NEAR(*e.axis_angle_deg, 10.0, 0.05);
}

TEST(ShapeError, MeshAndExactCylinderAgree) {
  // The paper's 12-sphere pill A against the exact cylinder and a 10 000-triangle tessellation:
  // they differ by the tessellation's missing volume only.
  const double D = 0.006, H = 0.0054, r = H / 3;
  Spheres s;
  for (double z : {H / 6, -H / 6})
    for (int k = 0; k < 6; ++k)
      s.push_back({Eigen::Vector3d((D / 2 - r) * std::cos(k * pi / 3),
                                   (D / 2 - r) * std::sin(k * pi / 3), z),
                   r});
  const TriangleMesh mesh = cylinder_mesh(D, H, 2500);
  const MeshSolid tess(mesh);
  const CylinderSurface exact(D, H);
  const ShapeError a = shape_error(exact, s, fast(1'500'000));
  const ShapeError b = shape_error(tess, s, fast(1'500'000));
  const double deficit = pi * D * D / 4 * H - polyhedron_moments(mesh).m0;
  EXPECT_NEAR(a.sym_diff_volume.value - b.sym_diff_volume.value, deficit,
              2 * (a.sym_diff_volume.ci95 + b.sym_diff_volume.ci95));
  EXPECT_NEAR(a.volume_rel_error.value, b.volume_rel_error.value, 1e-4);
  EXPECT_NEAR(a.hausdorff, b.hausdorff, 0.01 * a.hausdorff);  // different surface samples
  EXPECT_EQ(b.unresolved_lines, 0);
  // Against closed forms: the union is inside the cylinder, so XOR = V_cyl - V_union.
  EXPECT_NEAR(a.sym_diff_volume.value, a.shape.volume - a.clump.volume, 1e-12);
}

TEST(ShapeError, SameSeedSameFiguresWhateverTheThreads) {
  const CylinderSurface shape(0.006, 0.0058);
  const Spheres s = {{Eigen::Vector3d(0, 0, 0.0005), 0.0028},
                     {Eigen::Vector3d(0, 0, -0.0005), 0.0028}};
  ShapeErrorOptions one = fast(100'000), two = fast(100'000);
  one.sampling.threads = 1;
  two.sampling.threads = 2;
  const nlohmann::json a = to_json(shape_error(shape, s, one));
  nlohmann::json b = to_json(shape_error(shape, s, two));
  b["seconds"] = a["seconds"];
  EXPECT_EQ(a, b);
}

TEST(ShapeError, JsonHasTheDocumentedKeys) {
  const ShapeError e = shape_error(CylinderSurface(0.006, 0.0054),
                                   {{Eigen::Vector3d::Zero(), 0.0027}}, fast(30'000));
  const nlohmann::json j = to_json(e);
  for (const char* k :
       {"volume", "symmetric_difference", "center_of_mass_offset", "principal_moments",
        "axis_angle_deg", "hausdorff", "mean_surface_distance", "spheres", "rays", "seconds"})
    EXPECT_TRUE(j.contains(k)) << k;
  for (const char* k : {"shape", "clump", "rel_error", "ci95"})
    EXPECT_TRUE(j["volume"].contains(k));
  for (const char* k : {"volume", "rel", "ci95"})
    EXPECT_TRUE(j["symmetric_difference"].contains(k));
  for (const char* k : {"abs", "rel_to_size"}) EXPECT_TRUE(j["center_of_mass_offset"].contains(k));
  for (const char* k : {"shape", "clump", "rel_error"})
    EXPECT_EQ(j["principal_moments"][k].size(), 3u);
}

TEST(ShapeError, BadInputIsRefused) {
  const CylinderSurface shape(0.006, 0.0054);
  EXPECT_THROW(shape_error(shape, {}, fast()), InputError);
  EXPECT_THROW(shape_error(shape, {{Eigen::Vector3d::Zero(), -0.001}}, fast()), InputError);
  EXPECT_THROW(shape_error(shape, {{Eigen::Vector3d(NAN, 0, 0), 0.001}}, fast()), InputError);
  ShapeErrorOptions o = fast();
  o.sampling.rays = 0;
  EXPECT_THROW(shape_error(shape, {{Eigen::Vector3d::Zero(), 0.001}}, o), InputError);
}

TEST(SphereUnionSurface, EnclosedVoidWallsAreNotOuterSurface) {
  // Six spheres on the axes enclose a void around the origin (the diagonal direction is blocked
  // at 0.816 < 0.9 from the centres); the origin is outside every sphere.
  Spheres s;
  for (int k = 0; k < 3; ++k)
    for (double sign : {-1.0, 1.0}) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      c[k] = sign;
      s.push_back({c, 0.9});
    }
  const SphereUnionSurface surf(s);
  std::size_t dropped = 0;
  const auto outer = surf.sample_outer_surface(20000, 5, &dropped);
  const auto all = surf.sample_surface(20000, 5);
  EXPECT_GT(dropped, 0u);
  double rmin_outer = 1e300, rmin_all = 1e300;
  for (const auto& p : outer) rmin_outer = std::min(rmin_outer, p.norm());
  for (const auto& p : all) rmin_all = std::min(rmin_all, p.norm());
  // Void walls lie within ~0.1 of the origin (the sphere surfaces nearest to it); the outer
  // surface nowhere comes that close.
  EXPECT_LT(rmin_all, 0.2);
  EXPECT_GT(rmin_outer, 0.9);
  // No void: nothing dropped.
  const SphereUnionSurface two(
      {{Eigen::Vector3d(0, 0, 0), 1.0}, {Eigen::Vector3d(1.5, 0, 0), 0.8}});
  two.sample_outer_surface(5000, 1, &dropped);
  EXPECT_EQ(dropped, 0u);
}

TEST(SphereUnionSurface, DistanceMatchesBruteForceProperty) {
  // Random unions; random points inside and outside. The exact distance can never exceed the
  // distance to any sampled boundary point, and dense sampling must come close to it.
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> u(-1, 1), rad(0.4, 0.9);
  for (int c = 0; c < 8; ++c) {
    Spheres s;
    for (int i = 0; i < 5; ++i) s.push_back({Eigen::Vector3d(u(rng), u(rng), u(rng)), rad(rng)});
    const SphereUnionSurface surf(s);
    const auto boundary = surf.sample_surface(200'000, 7 + c);
    ASSERT_EQ(boundary.size(), 200'000u);
    for (const Eigen::Vector3d& b : boundary) {
      // Every sampled point is on the boundary: on a sphere, inside none.
      double out = 1e300;
      for (const Sphere& x : s) out = std::min(out, (b - x.center).norm() - x.radius);
      ASSERT_NEAR(out, 0.0, 1e-12);
    }
    for (int k = 0; k < 60; ++k) {
      const Eigen::Vector3d p(1.5 * u(rng), 1.5 * u(rng), 1.5 * u(rng));
      double brute = 1e300;
      for (const Eigen::Vector3d& b : boundary) brute = std::min(brute, (b - p).norm());
      const double d = surf.surface_distance(p);
      SCOPED_TRACE(::testing::Message() << "case " << c << " point " << k);
      EXPECT_LE(d, brute + 1e-12);
      EXPECT_GE(d, brute - 0.02);  // sample spacing on ~10 unit^2 of boundary
    }
  }
}

}  // namespace
}  // namespace clumpkit
