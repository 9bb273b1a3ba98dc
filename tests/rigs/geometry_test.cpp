// Rig geometry: the cup holds 0.26 L, the wheel's pockets are equal and match their closed form,
// the hopper feeds the wheel.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "clumpkit/rigs/geometry.hpp"

namespace clumpkit::rigs {
namespace {

TEST(RigGeometry, EqualAreaPolygon) {
  for (int n : {6, 16, 64}) {
    const double R = equal_area_polygon_radius(1.0, n);
    EXPECT_NEAR(0.5 * n * R * R * std::sin(2.0 * std::numbers::pi / n), std::numbers::pi, 1e-12);
  }
}

TEST(RigGeometry, CupHoldsTheNominalVolume) {
  const CupGeometry cup;
  EXPECT_NEAR(cup.volume(), 0.26e-3, 0.0005e-3);  // 0.26 L (SPEC §7's assumed D and H)
  // Close the open cup with a lid (normal inward = down) and integrate the enclosed volume.
  dem::TriangleMesh m = cup_mesh(cup);
  const double rp = equal_area_polygon_radius(0.5 * cup.inner_diameter, cup.segments);
  const int c = int(m.vertices.size());
  m.vertices.push_back(Eigen::Vector3d(0, 0, cup.height));
  for (int k = 0; k < cup.segments; ++k) {
    const double a0 = 2 * std::numbers::pi * k / cup.segments,
                 a1 = 2 * std::numbers::pi * (k + 1) / cup.segments;
    const int i = int(m.vertices.size());
    m.vertices.push_back(Eigen::Vector3d(rp * std::cos(a0), rp * std::sin(a0), cup.height));
    m.vertices.push_back(Eigen::Vector3d(rp * std::cos(a1), rp * std::sin(a1), cup.height));
    m.triangles.push_back({c, i + 1, i});
  }
  // Inward normals: the divergence theorem gives minus the volume.
  EXPECT_NEAR(-signed_volume(m), cup.volume(), 1e-9 * cup.volume() + 1e-15);
  m.validate("cup", "mesh");
}

TEST(RigGeometry, WheelPocketsAreEqualAndMatchTheClosedForm) {
  for (double phase_scale : {1.0, 0.5}) {
    WheelGeometry g;
    g.outer_radius *= phase_scale;
    g.hub_radius *= phase_scale;
    const auto areas = measured_pocket_areas(g, 800);
    ASSERT_EQ(int(areas.size()), g.pockets);
    double mean = 0;
    for (double a : areas) mean += a / areas.size();
    for (double a : areas) EXPECT_NEAR(a, mean, 0.01 * mean);
    // The raster misses the outer rim's curvature only at the grid scale.
    EXPECT_NEAR(mean, g.pocket_area(), 0.01 * g.pocket_area());
  }
  const WheelGeometry g;
  EXPECT_NEAR(g.pocket_volume(), g.pocket_area() * 0.1, 1e-15);
  EXPECT_GT(g.pocket_volume(), 2.5e-4);  // about 0.28 L per full-size pocket
}

TEST(RigGeometry, MeshesAreValidAndPlaced) {
  const WheelGeometry g;
  for (const auto& m : {wheel_mesh(g), housing_mesh(g), hopper_mesh(g), end_plates_mesh(g)}) {
    EXPECT_NO_THROW(m.validate("wheel rig", "mesh"));
  }
  // The wheel (vane tips included) turns inside the housing; the hopper throat lies on the
  // housing circle, outside the wheel.
  const double tip = std::hypot(g.outer_radius, 0.5 * g.vane_thickness);
  for (const auto& v : wheel_mesh(g).vertices) EXPECT_LE(std::hypot(v.x(), v.z()), tip + 1e-12);
  EXPECT_LT(tip, g.outer_radius + g.housing_gap);
  EXPECT_NEAR(std::hypot(0.5 * g.hopper_opening, g.throat_z()), g.outer_radius + g.housing_gap,
              1e-12);
  const LiftingGeometry l;
  EXPECT_NO_THROW(lifting_cylinder_mesh(l).validate("tube", "mesh"));
  EXPECT_NO_THROW(plate_mesh(l).validate("plate", "mesh"));
}

// The lift's stop rules read every pill: a pill in the tube's footprint listed before one at
// the shell must not hide it (session 21's paper-scale run stopped the tube after 14 mm with the
// column standing when the scan ended at the first pill in the footprint).
TEST(RigGeometry, TubeClearanceLooksAtEveryPill) {
  const double R = 0.03, br = 0.004, bottom = 0.02, height = 0.15;
  const Eigen::Vector3d axis_top(0, 0, 0.05);          // under the tube, far from the shell
  const Eigen::Vector3d at_shell(R - 0.003, 0, 0.03);  // against the shell, above the edge
  const Eigen::Vector3d below(R, 0, bottom - 0.01);   // at the shell's radius, 10 mm below the edge
  const Eigen::Vector3d outside(R + 0.02, 0, 0.005);  // on the flank, outside
  TubeClearance c = tube_clearance({axis_top, at_shell}, R, br, bottom, height);
  EXPECT_TRUE(c.in_footprint);
  EXPECT_TRUE(c.near_shell);
  c = tube_clearance({axis_top, below, outside}, R, br, bottom, height);
  EXPECT_TRUE(c.in_footprint);  // the apex is under the tube
  EXPECT_FALSE(c.near_shell);   // 10 mm below the edge is beyond 1.5 br = 6 mm
  c = tube_clearance({below, outside}, R, br, bottom, height);
  EXPECT_FALSE(c.near_shell);
  EXPECT_TRUE(c.in_footprint);  // 3 br = 12 mm: the clearing rule still waits for it
  c = tube_clearance({outside, Eigen::Vector3d(0, 0, bottom - 0.02)}, R, br, bottom, height);
  EXPECT_FALSE(c.in_footprint);
  EXPECT_FALSE(c.near_shell);
  // Above the tube's top, beyond the reach: not near the shell.
  c = tube_clearance({Eigen::Vector3d(R, 0, bottom + height + 0.007)}, R, br, bottom, height);
  EXPECT_FALSE(c.near_shell);
  c = tube_clearance({Eigen::Vector3d(R, 0, bottom + height + 0.005)}, R, br, bottom, height);
  EXPECT_TRUE(c.near_shell);
}

}  // namespace
}  // namespace clumpkit::rigs
