// Sphere–triangle contacts: one contact per flat region however it is triangulated, correct
// multi-contacts in concave corners, wall loads and prescribed motions.
#include <gtest/gtest.h>

#include <cmath>

#include "clumpkit/core/error.hpp"
#include "clumpkit/dem/time_step.hpp"
#include "scenes.hpp"

namespace clumpkit::dem {
namespace {

struct Resting {
  int contacts = 0;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
};

// A sphere pressed into a floor (overlap 1 µm) at (x, y); one step, no gravity.
Resting press(int divisions, double x, double y) {
  WorldSettings s;
  s.gravity.setZero();
  s.materials = test::test_materials(0.5, 0.5, 0.05);
  const double r = 2e-3;
  s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
  s.walls.push_back(test::floor_wall(0.04, divisions));
  World w = World::create(s);
  w.add_clump(0, Eigen::Vector3d(x, y, r - 1e-6));
  w.step();
  return {w.contact_count(), w.contact_forces()[0]};
}

TEST(Walls, OneContactOnAFlatFaceSplitIntoManyTriangles) {
  const Resting coarse = press(1, 1e-3, 2e-3);
  ASSERT_EQ(coarse.contacts, 1);
  ASSERT_GT(coarse.force.z(), 0.0);
  // 16 × 16 squares of 2.5 mm: on a vertex shared by six triangles, on an edge shared by two
  // coplanar triangles, on a diagonal, inside a triangle.
  const double d = 0.04 / 16;
  for (auto [x, y] : {std::pair{0.0, 0.0}, std::pair{d, 0.5 * d}, std::pair{0.5 * d, 0.0},
                      std::pair{0.5 * d, 0.5 * d}, std::pair{0.3 * d, 0.7 * d}}) {
    const Resting fine = press(16, x, y);
    EXPECT_EQ(fine.contacts, 1) << x << ", " << y;
    EXPECT_NEAR((fine.force - coarse.force).norm(), 0.0, 1e-9 * coarse.force.norm());
  }
}

TEST(Walls, RollingAcrossManyTrianglesFeelsOneSmoothContact) {
  auto roll = [](int divisions) {
    WorldSettings s;
    s.materials = test::test_materials(0.3, 0.5, 0.05);
    const double r = 2e-3;
    s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
    s.walls.push_back(test::floor_wall(0.2, divisions));
    World w = World::create(s);
    w.add_clump(0, Eigen::Vector3d(-0.01, 0.003, r), Eigen::Quaterniond::Identity(),
                Eigen::Vector3d(0.3, 0.1, 0), Eigen::Vector3d(-0.1 / r, 0.3 / r, 0));
    int max_contacts = 0;
    while (w.time() < 0.05) {
      w.step();
      max_contacts = std::max(max_contacts, w.contact_count());
    }
    EXPECT_EQ(max_contacts, 1);
    return w.positions()[0];
  };
  const Eigen::Vector3d a = roll(1), b = roll(40);
  EXPECT_NEAR((a - b).norm(), 0.0, 1e-9);
}

TEST(Walls, ConvexEdgeGivesOneContactConcaveCornerGivesThree) {
  WorldSettings s;
  s.gravity.setZero();
  s.materials = test::test_materials(0.5, 0.5, 0.05);
  const double r = 2e-3;
  s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
  WallSettings block{"block",
                     make_box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.01, 0.01, 0.01)),
                     "galvanized_steel",
                     {},
                     {}};
  s.walls.push_back(block);
  World w = World::create(s);
  // Outside, over the top corner vertex (0, 0, 0.01), touching it diagonally.
  const Eigen::Vector3d dir = Eigen::Vector3d(-1, -1, 1).normalized();
  w.add_clump(0, Eigen::Vector3d(0, 0, 0.01) + (r - 1e-6) * dir);
  // Outside, over the middle of the top edge y = 0, z = 0.01.
  const Eigen::Vector3d dir2 = Eigen::Vector3d(0, -1, 1).normalized();
  w.add_clump(0, Eigen::Vector3d(0.005, 0, 0.01) + (r - 1e-6) * dir2);
  w.step();
  EXPECT_EQ(w.contact_count(), 2);
  const auto c = w.contacts();
  ASSERT_EQ(c.size(), 2u);
  EXPECT_NEAR(c[0].normal.dot(dir), 1.0, 1e-9);
  EXPECT_NEAR(c[1].normal.dot(dir2), 1.0, 1e-9);

  // Inside a closed box, in a corner: floor and two side walls.
  WorldSettings s2 = s;
  s2.walls = {{"box",
               make_box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.02, 0.02, 0.02)),
               "galvanized_steel",
               {},
               {}}};
  World w2 = World::create(s2);
  w2.add_clump(0, Eigen::Vector3d(r - 1e-6, r - 1e-6, r - 1e-6));
  w2.step();
  EXPECT_EQ(w2.contact_count(), 3);
}

TEST(Walls, WallRecordsForceAndTorque) {
  WorldSettings s;
  s.materials = test::test_materials(0.2, 0.5, 0.05);
  const double r = 2e-3;
  s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
  s.walls.push_back(test::floor_wall(0.1, 4));
  World w = World::create(s);
  w.add_clump(0, Eigen::Vector3d(0.01, -0.02, r));
  w.run_until(0.1);
  const double mg = w.clump_mass(0) * 9.81;
  const WallState& ws = w.wall(0);
  EXPECT_NEAR(ws.force.z(), -mg, 1e-4 * mg);
  EXPECT_NEAR(ws.force.head<2>().norm(), 0.0, 1e-6 * mg);
  // Torque about the origin of the weight carried at (0.01, −0.02): r × F.
  const Eigen::Vector3d expected =
      Eigen::Vector3d(0.01, -0.02, 0).cross(Eigen::Vector3d(0, 0, -mg));
  EXPECT_NEAR((ws.torque - expected).norm(), 0.0, 1e-4 * expected.norm());
}

TEST(Walls, MotionKinematics) {
  VelocityProfile p{{0.0, 1.0, 2.0},
                    {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(0, 0, 2)}};
  EXPECT_NEAR(p.displacement(1.0).z(), 1.0, 1e-15);
  EXPECT_NEAR(p.displacement(0.5).z(), 0.25, 1e-15);
  EXPECT_NEAR(p.displacement(3.0).z(), 1.0 + 2.0 * 2.0, 1e-14);
  WallMotion m;
  m.translation = VelocityProfile::constant(Eigen::Vector3d(0.1, 0, 0));
  m.rotation = WallRotation{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 1), 30.0, 0.5};
  const WallPose a = wall_pose(m, 0.25), b = wall_pose(m, 1.5);
  EXPECT_TRUE(a.rotation.isIdentity(0.0));
  EXPECT_NEAR(b.omega.z(), std::numbers::pi, 1e-12);  // 30 rpm
  // Velocity of a material point = finite difference of its position.
  const Eigen::Vector3d x0(0.2, 0.1, 0.3);
  const double h = 1e-6;
  const Eigen::Vector3d fd =
      (wall_pose(m, 1.5 + h).apply(x0) - wall_pose(m, 1.5 - h).apply(x0)) / (2 * h);
  EXPECT_NEAR((fd - b.velocity_at(b.apply(x0))).norm(), 0.0, 1e-6);
  // unapply carries a world point back to the wall's point at t = 0 (the neighbour search bins
  // a moving wall's triangles once, in that frame).
  EXPECT_NEAR((b.unapply(b.apply(x0)) - x0).norm(), 0.0, 1e-15);
  EXPECT_TRUE(wall_pose(WallMotion{}, 2.0).at_rest());
  EXPECT_FALSE(b.at_rest());
  EXPECT_FALSE(a.at_rest());  // translated, not turned
}

TEST(Walls, LiftingPistonCarriesASphere) {
  WorldSettings s;
  s.materials = test::test_materials(0.2, 0.5, 0.05);
  const double r = 2e-3;
  s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
  WallSettings piston = test::floor_wall(0.05, 2);
  piston.motion.translation = {{0.1, 0.2}, {Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.05)}};
  s.walls.push_back(piston);
  World w = World::create(s);
  w.add_clump(0, Eigen::Vector3d(0, 0, r));
  w.run_until(0.4);
  EXPECT_NEAR(w.velocities()[0].z(), 0.05, 1e-3);
  // The wall moved 0.0025 + 0.01 m by t = 0.4 s; the sphere rides on it.
  EXPECT_NEAR(w.positions()[0].z(), r + 0.0125, 2e-5);
}

TEST(Walls, BadMeshIsAnInputError) {
  WorldSettings s;
  s.source = "scene.toml";
  s.clump_types.push_back(test::sphere_type("ball", 2e-3, 1380.0));
  WallSettings bad{"cup", {}, "organic_glass", {}, {}};
  bad.mesh.vertices = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                       Eigen::Vector3d(2, 0, 0)};
  bad.mesh.triangles = {{0, 1, 2}};
  s.walls.push_back(bad);
  try {
    (void)World::create(s);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "scene.toml");
    EXPECT_EQ(e.field(), "walls[0].mesh.triangles[0]");
  }
  s.walls[0] = test::floor_wall(0.1, 1, 0.0, "unobtainium");
  EXPECT_THROW((void)World::create(s), InputError);
}

}  // namespace
}  // namespace clumpkit::dem

namespace clumpkit::dem {
namespace {

// A flat 3 × 3 slab on a turntable (10 rpm about z) is carried round by friction: it ends up
// moving with the table, v = Ω × x and ω_z = Ω.
TEST(Walls, TurntableCarriesASlab) {
  WorldSettings s;
  s.materials = test::test_materials(0.3, 0.6, 0.0);
  const double r = 1e-3;
  Spheres sp;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j) sp.push_back({Eigen::Vector3d(2 * r * i, 2 * r * j, 0), r});
  const double m = 9.0 * 4.0 / 3.0 * std::numbers::pi * r * r * r * 1380.0;
  const double ixy = m * 2.0 * r * r;
  s.clump_types.push_back(test::clump_type("slab", sp, m, Eigen::Vector3d(ixy, ixy, 2 * ixy)));
  WallSettings table = test::floor_wall(0.1, 8);
  table.motion.rotation = WallRotation{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 10.0};
  s.walls.push_back(table);
  World w = World::create(s);
  w.add_clump(0, Eigen::Vector3d(0.02, 0, r));
  w.run_until(0.3);
  const double omega = 10.0 * 2.0 * std::numbers::pi / 60.0;
  const Eigen::Vector3d expected = Eigen::Vector3d(0, 0, omega).cross(w.positions()[0]);
  EXPECT_NEAR((w.velocities()[0] - expected).norm(), 0.0, 0.01 * expected.norm());
  EXPECT_NEAR(w.omega_world(0).z(), omega, 0.01 * omega);
  EXPECT_NEAR(w.positions()[0].head<2>().norm(), 0.02, 1e-4);
}

// A paddle (the plane x = 0, 4 × 4 squares) turns a quarter turn about z and stops: it is now
// the plane y = 0. A ball pressed into it from +y feels one contact pushing it along +y. The
// contact search rejects triangles by their plane distance, so this fails if the cached face
// normals did not turn with the wall (at x = 5 mm every stale plane test rejects: the rotated
// vertices sit at x = 0, ±10, ±20 mm).
TEST(Walls, TurnedWallContactsUseTurnedNormals) {
  WorldSettings s;
  s.gravity.setZero();
  s.materials = test::test_materials(0.5, 0.5, 0.05);
  const double r = 2e-3;
  s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
  WallSettings paddle{"paddle",
                      make_plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), 0.04, 0.04, 4),
                      "galvanized_steel",
                      {},
                      {}};
  paddle.motion.rotation = WallRotation{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 30.0,
                                        0.0, 0.5};  // π rad/s for 0.5 s
  s.walls.push_back(paddle);
  World w = World::create(s);
  w.run_until(0.6);
  w.add_clump(0, Eigen::Vector3d(0.005, r - 1e-6, 0.001));
  w.step();
  ASSERT_EQ(w.contact_count(), 1);
  const Eigen::Vector3d f = w.contact_forces()[0];
  EXPECT_GT(f.y(), 0.0);
  EXPECT_NEAR(f.x(), 0.0, 1e-9 * f.norm() + 1e-12);
  EXPECT_NEAR(f.z(), 0.0, 1e-9 * f.norm() + 1e-12);
}

// A ball between the floor and a ceiling that comes down at 5 cm/s: a prescribed wall has
// unlimited force, so the ball is squeezed without end. Without a pinch release the overlap
// check stops the run; with one the ball is taken out, counted and reported.
WorldSettings squeeze(double release) {
  WorldSettings s;
  s.gravity.setZero();
  s.materials = test::test_materials(0.5, 0.5, 0.05);
  const double r = 2e-3;
  s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
  s.walls.push_back(test::floor_wall(0.04, 2));
  WallSettings ceiling{
      "ceiling",
      make_plane(Eigen::Vector3d(0, 0, 2 * r + 1e-4), -Eigen::Vector3d::UnitZ(), 0.04, 0.04),
      "galvanized_steel",
      {},
      {}};
  ceiling.motion.translation = VelocityProfile::constant(Eigen::Vector3d(0, 0, -0.05));
  s.walls.push_back(ceiling);
  s.pinch_release = release;
  return s;
}

TEST(Walls, PinchedBallStopsTheRunWithoutARelease) {
  World w = World::create(squeeze(0.0));
  w.add_clump(0, Eigen::Vector3d(0, 0, 2e-3));
  try {
    w.run_until(0.05);
    FAIL() << "the squeezed ball ran on";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("overlap"), std::string::npos) << e.what();
  }
}

TEST(Walls, PinchReleaseTakesTheBallOutAndCountsIt) {
  World w = World::create(squeeze(0.25));
  w.add_clump(0, Eigen::Vector3d(0, 0, 2e-3));
  w.add_clump(0, Eigen::Vector3d(0.01, 0, 2e-3));
  const double m = w.clump_mass(0);
  // The ceiling closes 0.05 m/s × t; each side's overlap passes 25 % of r = 0.5 mm when it
  // has moved 1.1 mm, at t = 0.022 s.
  w.run_until(0.018);
  EXPECT_EQ(w.clump_count(), 2);
  EXPECT_EQ(w.pinched_count(), 0);
  w.run_until(0.03);
  EXPECT_EQ(w.clump_count(), 0);
  EXPECT_EQ(w.pinched_count(), 2);
  EXPECT_NEAR(w.pinched_mass(), 2 * m, 1e-15);
  bool warned = false;
  for (const auto& msg : w.warnings())
    warned = warned || msg.find("pinched against wall") != std::string::npos;
  EXPECT_TRUE(warned);
}

// Only a moving wall pinches. Two soft balls meet head-on at 3.9 m/s, deep enough for a Hertz
// overlap of ~40 % of their radius (closed form, undamped), while a ceiling moves far above
// them: the release leaves a hard landing to the overlap check, and the balls bounce apart.
TEST(Walls, PinchReleaseLeavesAHardImpactWithoutAMovingWall) {
  WorldSettings s = squeeze(0.25);
  Material pill = s.materials.get("pill");
  pill.youngs_modulus = 1.0e6;
  s.materials.add(pill);
  s.walls[1].mesh = make_plane(Eigen::Vector3d(0, 0, 0.03), -Eigen::Vector3d::UnitZ(), 0.04, 0.04);
  s.max_impact_speed = 4.0;
  const double r = 2e-3, v = 1.95;
  World w = World::create(s);
  w.add_clump(0, Eigen::Vector3d(-1.5 * r, 0, 0.01), Eigen::Quaterniond::Identity(),
              Eigen::Vector3d(v, 0, 0));
  w.add_clump(0, Eigen::Vector3d(1.5 * r, 0, 0.01), Eigen::Quaterniond::Identity(),
              Eigen::Vector3d(-v, 0, 0));
  const double m = w.clump_mass(0);
  const double e_star =
      pill.youngs_modulus / (2.0 * (1.0 - pill.poisson_ratio * pill.poisson_ratio));
  const double deepest = hertz_max_overlap(e_star, 0.5 * r, 0.5 * m, 2.0 * v) / r;
  ASSERT_GT(deepest, 0.35);
  ASSERT_LT(deepest, 0.5);
  w.run_until(0.004);
  EXPECT_EQ(w.pinched_count(), 0);
  ASSERT_EQ(w.clump_count(), 2);
  EXPECT_LT(w.velocities()[0].x(), 0.0) << "the balls bounce apart";
  EXPECT_GT(w.velocities()[1].x(), 0.0);
}

// A moving wall pinches through the clumps it presses on. A column between the floor and the
// descending ceiling: ball A (r = 2 mm) under the ceiling, ball B (2 mm) under it, a small
// ball C (1 mm) on the floor. The same force runs down the column, and a Hertz overlap goes as
// R*^(-1/3): in units of the smaller radius, B-C passes 25 % first (A-B is then at ~11 %), far
// from the ceiling; neither B nor C touches a moving wall. B and C are loaded by the ceiling
// through A, so they are released; A stays. (Releasing only clumps that touch the moving wall,
// session 50's rule, left B-C to reach the 50 % overlap check: the run stopped.)
TEST(Walls, PinchReleaseTakesADeepContactTheMovingWallLoadsThroughAnotherClump) {
  WorldSettings s = squeeze(0.25);
  s.clump_types.push_back(test::sphere_type("small", 1e-3, 1380.0));
  s.walls[1].mesh =
      make_plane(Eigen::Vector3d(0, 0, 10.1e-3), -Eigen::Vector3d::UnitZ(), 0.04, 0.04);
  World w = World::create(s);
  w.add_clump(0, Eigen::Vector3d(0, 0, 8e-3));  // A
  w.add_clump(0, Eigen::Vector3d(0, 0, 4e-3));  // B
  w.add_clump(1, Eigen::Vector3d(0, 0, 1e-3));  // C
  const double m = w.clump_mass(0) + w.clump_mass(2);
  // B-C passes 25 % of 1 mm when the ceiling has closed ~0.96 mm (t ~ 0.019 s) and would pass
  // 50 % at ~0.036 s.
  w.run_until(0.012);
  EXPECT_EQ(w.pinched_count(), 0);
  ASSERT_NO_THROW(w.run_until(0.03));
  EXPECT_EQ(w.pinched_count(), 2);
  EXPECT_NEAR(w.pinched_mass(), m, 1e-12 * m);
  EXPECT_EQ(w.clump_count(), 1);  // a ball and the small one went: B and C (A never touches C)
  bool warned = false;
  for (const auto& msg : w.warnings())
    warned = warned || msg.find("pinched against another clump") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(Walls, PinchReleaseOutOfRangeIsAnInputError) {
  WorldSettings s = squeeze(0.5);
  EXPECT_THROW((void)World::create(s), InputError);
  s.pinch_release = -0.1;
  EXPECT_THROW((void)World::create(s), InputError);
}

}  // namespace
}  // namespace clumpkit::dem
