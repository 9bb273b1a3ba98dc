// Equivalent contact masses of clump impacts (time_step.hpp): closed-form cases.
#include "clumpkit/dem/time_step.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace clumpkit::dem {
namespace {

SphereSet ring(int n, double ring_radius, double r) {
  SphereSet s;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    s.centers.emplace_back(ring_radius * std::cos(a), ring_radius * std::sin(a), 0.0);
    s.radii.push_back(r);
  }
  return s;
}

const ClumpInertia kUnit{1.0, Eigen::Vector3d(0.5, 0.5, 0.5)};

TEST(ContactMass, OneSphereIsItsMass) {
  const SphereSet one{{Eigen::Vector3d::Zero()}, {1e-3}};
  const ClumpInertia ball{2e-4, Eigen::Vector3d::Constant(0.4 * 2e-4 * 1e-6)};
  // Normal springs only: the contact pushes through the centre.
  EXPECT_NEAR(wall_contact_mass(one, ball, 0.0), 2e-4, 1e-16);
  const ClumpInertia other{6e-4, Eigen::Vector3d::Constant(0.4 * 6e-4 * 1e-6)};
  EXPECT_NEAR(clump_contact_mass(one, ball, one, other, 0.0), 1.5e-4, 1e-16);
  // A tangential spring of weight w at the surface drives slip and spin together:
  // 1/m_eq = w (1/m + r²/I) = 3.5 w / m for a solid ball.
  EXPECT_NEAR(wall_contact_mass(one, ball, 0.8), 2e-4 / 2.8, 1e-12);
}

TEST(ContactMass, CoincidentSpheresAreParallelSprings) {
  // Four spheres at nearly one place (the paper's 4-sphere pill A is close to this): four
  // springs in parallel on the wall, sixteen pairs between two such clumps.
  const SphereSet four = ring(4, 1e-9, 1e-3);
  EXPECT_NEAR(wall_contact_mass(four, kUnit, 0.0), 0.25, 1e-6);
  EXPECT_NEAR(clump_contact_mass(four, kUnit, four, kUnit, 0.0), 1.0 / 32.0, 1e-6);
}

TEST(ContactMass, RockingIsStifferThanBouncing) {
  // A dumbbell (spheres at x = ±1, m = 1, I = 0.5) lying on a wall: bouncing 2/m, rocking
  // 2a²/I = 4 about y (lying along z on its side, the same about z). One sphere alone at the
  // far end gives at most 1/m + a²/I = 3.
  SphereSet bell{{Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(-1, 0, 0)}, {0.1, 0.1}};
  EXPECT_NEAR(wall_contact_mass(bell, kUnit, 0.0), 0.25, 1e-9);
}

TEST(ContactMass, FlatRingRocksFasterThanItBounces) {
  // A ring of 6 spheres (radius 1) flat on a wall, I = (0.25, 0.25, 0.5) as a thin ring of
  // mass 1... about x: Σ y_k² = 3, so rocking is 3/0.25 = 12 against bouncing 6.
  const SphereSet six = ring(6, 1.0, 0.05);
  const ClumpInertia disc{1.0, Eigen::Vector3d(0.25, 0.25, 0.5)};
  EXPECT_NEAR(wall_contact_mass(six, disc, 0.0), 1.0 / 12.0, 1e-9);
}

TEST(ContactMass, ParallelSpringsShortenTheImpact) {
  // N equal Hertz springs in parallel are one spring with N E*: t_c scales as N^(-2/5).
  const double t1 = hertz_contact_time(1e8, 1e-3, 1e-4, 1.0);
  const double t16 = hertz_contact_time(16 * 1e8, 1e-3, 1e-4, 1.0);
  EXPECT_NEAR(t16 / t1, std::pow(16.0, -0.4), 1e-12);
}

}  // namespace
}  // namespace clumpkit::dem
