// Contact multiplicity of clump impacts (time_step.hpp): closed-form cases.
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

TEST(ContactMultiplicity, OneSphereIsOnePair) {
  const SphereSet one{{Eigen::Vector3d::Zero()}, {1e-3}};
  EXPECT_EQ(wall_contact_multiplicity(one), 1);
  EXPECT_EQ(clump_contact_multiplicity(one, one), 1);
}

TEST(ContactMultiplicity, CoincidentSpheresAllTouchAtOnce) {
  // Four spheres at nearly one place (the paper's 4-sphere pill A is close to this).
  const SphereSet four = ring(4, 1e-5, 1e-3);
  EXPECT_EQ(wall_contact_multiplicity(four), 4);
  EXPECT_EQ(clump_contact_multiplicity(four, four), 16);
}

TEST(ContactMultiplicity, FlatRingLiesDownWholeOnAWall) {
  // A ring of 6 spheres in the body's xy plane: along +-z all six touch a wall together.
  const SphereSet six = ring(6, 2e-3, 1e-3);
  EXPECT_EQ(wall_contact_multiplicity(six), 6);
  // Another clump meets it along its rim: at most a few of the pairs, never all 36.
  const int n = clump_contact_multiplicity(six, six);
  EXPECT_GE(n, 2);
  EXPECT_LT(n, 12);
}

TEST(ContactMultiplicity, ShortensTheImpactAsParallelSprings) {
  // N equal Hertz springs in parallel are one spring with N E*: t_c scales as N^(-2/5).
  const double t1 = hertz_contact_time(1e8, 1e-3, 1e-4, 1.0);
  const double t16 = hertz_contact_time(16 * 1e8, 1e-3, 1e-4, 1.0);
  EXPECT_NEAR(t16 / t1, std::pow(16.0, -0.4), 1e-12);
}

}  // namespace
}  // namespace clumpkit::dem
