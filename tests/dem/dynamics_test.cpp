// Rigid-body dynamics against closed forms: sliding on an incline, rolling resistance,
// intermediate-axis tumbling, energy conservation.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "clumpkit/dem/time_step.hpp"
#include "dem/world_impl.hpp"
#include "scenes.hpp"

namespace clumpkit::dem {
namespace {

// A flat 3 × 3 slab of touching spheres (radius r): it slides long before it could tip
// (tipping needs tan θ > 2).
ClumpTypeSettings block_type(double r) {
  Spheres s;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j) s.push_back({Eigen::Vector3d(2 * r * i, 2 * r * j, 0), r});
  const double m = 9.0 * 4.0 / 3.0 * std::numbers::pi * r * r * r * 1380.0;
  const double ixy = m * (6.0 * r * r) / 3.0;
  return test::clump_type("block", s, m, Eigen::Vector3d(ixy, ixy, 2.0 * ixy));
}

// The floor is horizontal and gravity is tilted by theta about y: an incline of angle theta.
// Returns the block's mean acceleration along the slope between t = 0.05 s and 0.15 s.
double incline_acceleration(double theta, double mu) {
  WorldSettings s;
  const double g = 9.81;
  s.gravity = Eigen::Vector3d(g * std::sin(theta), 0.0, -g * std::cos(theta));
  s.materials = test::test_materials(0.3, mu, 0.0);
  PairContact law;  // damping and friction, no rolling resistance
  law.restitution = 0.3;
  law.static_friction = mu;
  s.pair_contacts.push_back({"pill", "galvanized_steel", law});
  const double r = 1e-3;
  s.clump_types.push_back(block_type(r));
  s.walls.push_back(test::floor_wall(0.2, 2));
  World w = World::create(s);
  w.add_clump(0, Eigen::Vector3d(0, 0, r));
  w.run_until(0.05);
  const double v1 = w.velocities()[0].x();
  w.run_until(0.15);
  const double v2 = w.velocities()[0].x();
  EXPECT_NEAR(w.positions()[0].z(), r, 0.05 * r) << "the block left the incline";
  return (v2 - v1) / 0.1;
}

TEST(Dynamics, BlockOnInclineSlidesAtTanThetaEqualsMuS) {
  const double mu = 0.5, g = 9.81;
  const double crit = std::atan(mu);
  const double below = incline_acceleration(crit - 1.0 * std::numbers::pi / 180.0, mu);
  EXPECT_NEAR(below, 0.0, 1e-3) << "sliding below tan θ = μs";
  const double theta = crit + 2.0 * std::numbers::pi / 180.0;
  const double above = incline_acceleration(theta, mu);
  const double expected = g * (std::sin(theta) - mu * std::cos(theta));
  EXPECT_NEAR(above, expected, 0.03 * expected);
}

// A sphere rolling on a steel floor decelerates at (5/7) μr g under paper eq. (2), and at the
// same rate under the CDT and (once mobilised) the EPSD models on a fixed floor.
double rolling_deceleration(RollingModel model, double mu_r) {
  WorldSettings s;
  s.materials = test::test_materials(0.3, 0.5, mu_r);
  s.rolling_model = model;
  const double r = 3e-3;
  s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
  s.walls.push_back(test::floor_wall(1.0, 4));
  World w = World::create(s);
  const ResolvedContact& law = w.resolved_contact("pill", "galvanized_steel");
  const double m = w.clump_type_mass(0);
  const double delta0 = std::pow(3.0 * m * 9.81 / (4.0 * law.e_star * std::sqrt(r)), 2.0 / 3.0);
  const double v0 = 0.2;
  w.add_clump(0, Eigen::Vector3d(-0.2, 0, r - delta0), Eigen::Quaterniond::Identity(),
              Eigen::Vector3d(v0, 0, 0), Eigen::Vector3d(0, v0 / r, 0));
  w.run_until(0.02);
  const double v1 = w.velocities()[0].x();
  w.run_until(0.12);
  const double v2 = w.velocities()[0].x();
  EXPECT_NEAR(w.omega_world(0).y() * r, v2, 1e-3 * v0) << "the sphere slips";
  return -(v2 - v1) / 0.1;
}

TEST(Dynamics, RollingSphereDeceleratesAsPaperEq2) {
  const double mu_r = 0.05, g = 9.81;
  const double expected = 5.0 / 7.0 * mu_r * g;
  EXPECT_NEAR(rolling_deceleration(RollingModel::kStandard, mu_r), expected, 0.02 * expected);
  EXPECT_NEAR(rolling_deceleration(RollingModel::kCdt, mu_r), expected, 0.02 * expected);
  // For a single sphere the contact lies one radius from the centre of mass.
  EXPECT_NEAR(rolling_deceleration(RollingModel::kStandardCom, mu_r), expected, 0.02 * expected);
  EXPECT_NEAR(rolling_deceleration(RollingModel::kEpsd, mu_r), expected, 0.05 * expected);
}

TEST(Dynamics, RollingResistanceStopsButNeverReverses) {
  WorldSettings s;
  s.materials = test::test_materials(0.3, 0.5, 0.3);
  const double r = 3e-3;
  s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
  s.walls.push_back(test::floor_wall(0.2, 2));
  World w = World::create(s);
  w.add_clump(0, Eigen::Vector3d(0, 0, r), Eigen::Quaterniond::Identity(),
              Eigen::Vector3d(0.05, 0, 0), Eigen::Vector3d(0, 0.05 / r, 0));
  w.run_until(0.1);
  EXPECT_NEAR(w.velocities()[0].norm(), 0.0, 1e-4);
  EXPECT_GE(w.omega_world(0).y(), -1e-3);
}

// Free rigid body: spin about the intermediate axis is unstable (Dzhanibekov effect), spin
// about the major axis is stable; |L| in the world frame and the energy are conserved.
struct SpinResult {
  double max_perp = 0.0;  // largest |ω1| seen, relative to the spin
  bool flipped = false;   // ω2 changed sign
  double l_drift = 0.0;   // relative change of the world angular momentum
  double e_drift = 0.0;   // relative change of the kinetic energy
};

SpinResult spin(int axis) {
  WorldSettings s;
  s.gravity.setZero();
  const double r = 10e-3;
  const Eigen::Vector3d I(1e-6, 2e-6, 3e-6);
  s.clump_types.push_back(test::clump_type(
      "tee", {{Eigen::Vector3d(0, 0, 0), r}, {Eigen::Vector3d(2 * r, 0, 0), r}}, 0.01, I));
  World w = World::create(s);
  Eigen::Vector3d wb(1e-2, 1e-2, 1e-2);
  wb[axis] = 10.0;
  w.add_clump(0, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero(),
              wb);
  auto momentum = [&] {
    return Eigen::Vector3d(w.orientations()[0] * I.cwiseProduct(w.omegas_body()[0]));
  };
  const Eigen::Vector3d l0 = momentum();
  const double e0 = w.kinetic_energy();
  SpinResult out;
  const int other = axis == 1 ? 0 : 1;
  while (w.time() < 2.0) {
    w.step();
    const Eigen::Vector3d& o = w.omegas_body()[0];
    out.max_perp = std::max(out.max_perp, std::abs(o[other]) / 10.0);
    if (o[axis] < 0.0) out.flipped = true;
  }
  out.l_drift = (momentum() - l0).norm() / l0.norm();
  out.e_drift = std::abs(w.kinetic_energy() - e0) / e0;
  return out;
}

TEST(Dynamics, IntermediateAxisTumblesMajorAxisDoesNot) {
  const SpinResult mid = spin(1);
  EXPECT_TRUE(mid.flipped);
  EXPECT_GT(mid.max_perp, 0.5);
  EXPECT_LT(mid.l_drift, 1e-9);
  EXPECT_LT(mid.e_drift, 1e-6);
  const SpinResult major = spin(2);
  EXPECT_FALSE(major.flipped);
  EXPECT_LT(major.max_perp, 0.01);
}

TEST(Dynamics, EnergyConservedWithoutDampingAndFriction) {
  WorldSettings s;
  s.materials = test::test_materials(0.5, 0.5, 0.1);
  PairContact elastic;  // every dissipative effect absent
  s.pair_contacts.push_back({"pill", "pill", elastic});
  s.pair_contacts.push_back({"pill", "galvanized_steel", elastic});
  const double r = 2e-3;
  s.clump_types.push_back(
      test::clump_type("dumbbell", {{Eigen::Vector3d(-r, 0, 0), r}, {Eigen::Vector3d(r, 0, 0), r}},
                       2.0 * 4.0 / 3.0 * std::numbers::pi * r * r * r * 1380.0,
                       Eigen::Vector3d(1.0e-10, 4.0e-10, 4.0e-10)));
  s.walls.push_back({"box",
                     make_box(Eigen::Vector3d(-0.01, -0.01, 0), Eigen::Vector3d(0.01, 0.01, 0.02)),
                     "galvanized_steel",
                     {},
                     {}});
  // Velocity Verlet's energy error is O(dt²) while springs are loaded (measured: largest
  // deviation 1.4e-4 at 0.1 T_R, 3.7e-5 at 0.05 T_R, 8e-6 at 0.025 T_R); 1e-6 needs 0.02 T_R.
  s.time_step = 0.02 * rayleigh_time(r, 1380.0, 1.1e8 / 2.7, 0.35);
  World w = World::create(s);
  // Eight dumbbells (bounding radius 4 mm) in two layers of four, clear of each other and the box.
  for (int k = 0; k < 8; ++k) {
    const double x = (k & 1) ? 4.5e-3 : -4.5e-3, y = (k & 2) ? 4.5e-3 : -4.5e-3;
    const double z = (k & 4) ? 14.5e-3 : 5e-3;
    w.add_clump(
        0, Eigen::Vector3d(x, y, z),
        Eigen::Quaterniond(Eigen::AngleAxisd(0.7 * k, Eigen::Vector3d(1, 2, 3).normalized())),
        Eigen::Vector3d(0.1 * (k % 3) - 0.1, 0.2 - 0.05 * k, 0.1),
        Eigen::Vector3d(5.0 * k, -3.0, 2.0));
  }
  w.step();
  const double e0 = w.kinetic_energy() + w.potential_energy() + w.elastic_energy();
  int contacts_seen = 0;
  double max_dev = 0.0;
  while (w.time() < 0.05) {
    w.step();
    contacts_seen += w.contact_count();
    const double e = w.kinetic_energy() + w.potential_energy() + w.elastic_energy();
    max_dev = std::max(max_dev, std::abs(e - e0) / e0);
  }
  const double e1 = w.kinetic_energy() + w.potential_energy() + w.elastic_energy();
  EXPECT_GT(contacts_seen, 1000) << "the test should exercise contacts";
  EXPECT_LT(std::abs(e1 - e0) / std::abs(e0), 1e-6) << e0 << " -> " << e1;
  EXPECT_LT(max_dev, 1e-5);
}

TEST(Dynamics, IntraClumpSpheresNeverInteract) {
  WorldSettings s;
  s.gravity.setZero();
  const double r = 2e-3;
  // Heavily overlapping spheres in one clump: no force may arise between them.
  s.clump_types.push_back(test::clump_type(
      "lens", {{Eigen::Vector3d(-0.5 * r, 0, 0), r}, {Eigen::Vector3d(0.5 * r, 0, 0), r}}, 1e-4,
      Eigen::Vector3d(1e-10, 2e-10, 2e-10)));
  World w = World::create(s);
  w.add_clump(0, Eigen::Vector3d::Zero());
  for (int k = 0; k < 100; ++k) w.step();
  EXPECT_EQ(w.contact_count(), 0);
  EXPECT_EQ(w.velocities()[0].norm(), 0.0);
  EXPECT_EQ(w.positions()[0].norm(), 0.0);
}

}  // namespace
}  // namespace clumpkit::dem

// The drift's written-out sphere position gives the bits of Eigen's x + R * o (the engine's
// results before it was written out), on seeded random rotations, centres and offsets.
TEST(DemKernels, SpherePositionIsEigensProduct) {
  std::mt19937_64 rng(20261202);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n = 0; n < 200000; ++n) {
    const Eigen::Quaterniond q = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized();
    const Eigen::Matrix3d R = q.toRotationMatrix();
    const Eigen::Vector3d x(0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng));
    const Eigen::Vector3d o(3e-3 * u(rng), 3e-3 * u(rng), 3e-3 * u(rng));
    const Eigen::Vector3d eigen = x + R * o;
    const Eigen::Vector3d ours = clumpkit::dem::sphere_position(x, R, o);
    ASSERT_EQ(eigen.x(), ours.x()) << "case " << n;
    ASSERT_EQ(eigen.y(), ours.y()) << "case " << n;
    ASSERT_EQ(eigen.z(), ours.z()) << "case " << n;
  }
}
